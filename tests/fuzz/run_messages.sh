#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the message fuzzer (fuzz_messages.c) with clang (libFuzzer + ASan + UBSan) over the
# types this build generated from lcmtypes/, the drivers' receiver's framing (rx.c) and the
# vehicle protocol (src/protocol), the vehicle records coavoid replay reads, their framing
# on a serial link and the frames a vehicle on the part takes (src/replay), and runs it for a fixed number of inputs from one
# seed per type and mode. Usage: run_messages.sh SRC LCMTYPES_BUILD_DIR [RUNS]
# A fixed run count, not a time limit, keeps the test's verdict independent of machine load.
set -euo pipefail
src=$1 types=$2 runs=${3:-20000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
command -v clang >/dev/null || { echo "fuzz: clang is not installed" >&2; exit 1; }
clang -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
  -I"$src/include" -I"$src/src/lcm" -I"$src/src/auth" -I"$src/src/protocol" -I"$src/src/replay" -I"$src/src/node" \
  -I"$src/src/realtime" -I"$src/tests" \
  -I"$types/include" "$src/tests/fuzz/fuzz_messages.c" "$src/src/lcm/convert.c" \
  "$src/src/auth/auth.c" "$src/src/auth/auth_files.c" "$src/src/realtime/rx.c" \
  "$src"/src/protocol/*.c "$src"/src/replay/*.c \
  "$src"/src/core/*.c "$types"/c/*.c -llcm -lsodium -lccd -lm -o "$work/fuzz_messages"
mkdir -p "$work/corpus"
# The six valid examples unchanged (mode byte 0-5), and raw bytes of each type (0x80-0x85);
# and a trust file and a secret key file for the key file parsers (kind 7).
for kind in 0 1 2 3 4 5; do
  printf "\\x0$kind" >"$work/corpus/example-$kind"
  printf "\\x8$kind" >"$work/corpus/raw-$kind"
done
printf '\x07# fleet\n1 coordinator 65001 %064d\n101 vehicle 1 %064d\n' 0 0 >"$work/corpus/trust"
printf '\x07coavoid-secret-key 101 %0128d\n' 0 >"$work/corpus/secret"
# A vehicle's record (its magic and an empty configuration), and one frame of a link.
printf '\x07COAVREC1\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00' >"$work/corpus/record"
printf '\x07\xc0abc\xc2\x41\x24\x35\xc0' >"$work/corpus/link"
# Frames a vehicle on the part takes (session.h): the configuration of UAV 1 of the paper's
# encounter (the first record of `coavoid sim scenarios/paper.json --mode decoupled
# --record-vehicle 1:FILE`, the simulation's public keys) and two TIME frames.
cp "$src/tests/fuzz/session.seed" "$work/corpus/session"
# A datagram in LCM's framing, as the drivers' receiver reads it off the socket.
printf '\x80LC02\x00\x00\x00\x01COAVOID_INTENT\x00abc' >"$work/corpus/frame"
"$work/fuzz_messages" -runs="$runs" -max_len=20000 -seed=1 "$work/corpus" 2>"$work/log" ||
  { tail -n 60 "$work/log"; exit 1; }
grep -E "DONE" "$work/log" || tail -n 3 "$work/log"
echo "fuzz_messages: $runs inputs, no crash, no sanitizer report"
