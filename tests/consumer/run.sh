#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the build tree into a scratch prefix, then uses it as a downstream project does
# (docs/library.md, "Installed files"), each C consumer built twice, with
# find_package(coavoid) (CMake) and with pkg-config:
#   - the core: main.c plans an encounter (coavoid::core; coavoid.pc);
#   - with LCM, the message library: messages.c makes, encodes, signs and takes in intents
#     (coavoid::lcm, coavoid::auth, coavoid::lcmtypes; coavoid-messages.pc) and writes
#     them as an LCM log, the same bytes from both builds; find_package(coavoid COMPONENTS
#     messages) without libsodium fails saying so;
#   - the installed Python example (share/doc/coavoid/examples/print_intents.py, with the
#     installed Python types on PYTHONPATH) prints that log's intents exactly as
#     intents.expected says, every message with --all, and a bad file in one line with
#     exit 2; where UDP multicast works, it prints the same live while lcm-logplayer
#     replays the log, and lcm-logger's log of that replay gives the same lines.
# Usage: run.sh SRC BUILD. Exit 77 (skipped) when python3 is missing, after the C parts.
set -euo pipefail
src=$1 build=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
fail() { echo "install_consumer: FAIL: $*" >&2; exit 1; }

# A sanitized core needs the sanitizer runtime in whatever links it.
flags=""
if grep -q '^COAVOID_SANITIZE:BOOL=ON' "$build/CMakeCache.txt"; then
  flags="-fsanitize=address,undefined"
fi
messages=OFF
pc=$(find "$prefix" -name coavoid.pc | head -n 1)
[ -f "$(dirname "$pc")/coavoid-messages.pc" ] && messages=ON

cmake -S "$src/tests/consumer" -B "$work/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCONSUMER_MESSAGES=$messages -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" \
  >/dev/null
cmake --build "$work/cmake-build" >/dev/null
"$work/cmake-build/consumer"

export PKG_CONFIG_PATH
PKG_CONFIG_PATH=$(dirname "$pc")
# shellcheck disable=SC2046,SC2086
cc -std=c11 $flags "$src/tests/consumer/main.c" $(pkg-config --cflags coavoid) \
  $(pkg-config --libs --static coavoid) -o "$work/consumer-pc"
"$work/consumer-pc"
if [ $messages = OFF ]; then
  echo "install_consumer: core only (this build has no LCM): CMake and pkg-config consumers ran"
  exit 0
fi

# shellcheck disable=SC2046,SC2086
cc -std=c11 $flags "$src/tests/consumer/messages.c" $(pkg-config --cflags coavoid-messages) \
  $(pkg-config --libs --static coavoid-messages) -o "$work/messages-pc"
"$work/cmake-build/messages" "$work/intents.lcm"
"$work/messages-pc" "$work/intents-pc.lcm"
cmp -s "$work/intents.lcm" "$work/intents-pc.lcm" ||
  fail "the CMake and pkg-config builds of messages.c wrote different logs"

# The component's dependencies are looked for: no libsodium, no messages, and why.
mkdir -p "$work/nosodium" "$work/empty"
printf 'cmake_minimum_required(VERSION 3.16)\nproject(p LANGUAGES C)\n%s\n' \
  'find_package(coavoid REQUIRED COMPONENTS messages)' >"$work/nosodium/CMakeLists.txt"
if PKG_CONFIG_LIBDIR=$work/empty PKG_CONFIG_PATH='' cmake -S "$work/nosodium" \
  -B "$work/nosodium/b" -DCMAKE_PREFIX_PATH="$prefix" >"$work/nosodium.out" 2>&1 ||
  ! grep -q 'libsodium not found' "$work/nosodium.out"; then
  fail "find_package(coavoid COMPONENTS messages) without libsodium: $(tail -n 5 "$work/nosodium.out")"
fi
echo "install_consumer: the core and the message library, CMake and pkg-config consumers ran"

if ! command -v python3 >/dev/null; then
  echo "install_consumer: skipped the Python example: no python3 (Debian: apt-get install python3)"
  exit 77
fi
example=$prefix/share/doc/coavoid/examples/print_intents.py
export PYTHONPATH=$prefix/lib/python3/dist-packages
expected=$src/tests/consumer/intents.expected
if ! python3 "$example" "$work/intents.lcm" >"$work/out" 2>"$work/err" ||
  ! diff -u "$expected" "$work/out" >"$work/diff"; then
  fail "print_intents.py: $(cat "$work/diff" "$work/err")"
fi
grep -qx 'print_intents: 1 message(s) on COAVOID_INTENT did not decode as intent_t' "$work/err" ||
  fail "print_intents.py did not report the truncated intent: $(cat "$work/err")"
# --all: every intent in the log's order, the copies too (UAV:sequence).
all=$(python3 "$example" --all "$work/intents.lcm" 2>/dev/null |
  awk '{ printf "%s%s:%s", sep, $3, $5; sep = " " }')
[ "$all" = "1:0 2:0 1:1 2:1 1:2 2:2 2:3 2:4" ] || fail "print_intents.py --all: $all"

# bad NAME FILE: the example refuses FILE with one line on stderr and exit 2.
bad() {
  local rc=0
  python3 "$example" "$2" >/dev/null 2>"$work/err" || rc=$?
  if [ $rc -ne 2 ] || [ "$(wc -l <"$work/err")" -ne 1 ] || ! grep -q '^print_intents: ' "$work/err"; then
    fail "print_intents.py on $1: exit $rc, $(cat "$work/err")"
  fi
}
bad "a missing file" "$work/none.lcm"
bad "a scenario" "$src/scenarios/paper.json"
head -c 2000 "$work/intents.lcm" >"$work/cut.lcm"
bad "a truncated log" "$work/cut.lcm"
echo "install_consumer: the installed Python example printed the log's intents"

# Live: the example on the group while lcm-logplayer replays the log, and lcm-logger
# recording the same replay. No multicast route (a sandbox): skipped, said so.
command -v lcm-logplayer >/dev/null || { echo "install_consumer: live part skipped: no lcm-logplayer"; exit 0; }
url="udpm://239.255.76.67:$((7900 + $$ % 100))?ttl=0"
python3 "$example" --live "$url" --count 5 --seconds 10 >"$work/live" 2>"$work/live.err" &
listener=$!
lcm-logger --lcm-url="$url" "$work/logged.lcm" >"$work/logger.out" 2>&1 &
logger=$!
for _ in $(seq 50); do
  if grep -q listening "$work/live.err" && [ -s "$work/logger.out" ]; then break; fi
  sleep 0.1
done
sleep 0.5 # the logger has opened its file: room for it to join the group
lcm-logplayer -s 4 --lcm-url="$url" "$work/intents.lcm" >/dev/null 2>&1 || true
sleep 0.5
kill -INT "$logger" 2>/dev/null || true
wait "$logger" || true
if [ ! -s "$work/logged.lcm" ]; then
  kill "$listener" 2>/dev/null || true
  wait "$listener" || true
  echo "install_consumer: live part skipped: lcm-logger heard nothing on $url (no multicast route?)"
  exit 0
fi
wait "$listener" || fail "print_intents.py --live: $(cat "$work/live.err")"
diff -u "$expected" "$work/live" >"$work/diff" || fail "print_intents.py --live: $(cat "$work/diff")"
python3 "$example" "$work/logged.lcm" >"$work/out" 2>/dev/null || fail "print_intents.py on lcm-logger's log"
diff -u "$expected" "$work/out" >"$work/diff" || fail "lcm-logger's log: $(cat "$work/diff")"
echo "install_consumer: and the same intents live from the group and from lcm-logger's log"
