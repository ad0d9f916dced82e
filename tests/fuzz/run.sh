#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the scenario fuzzer with clang (libFuzzer + ASan + UBSan) and runs it for a fixed
# number of inputs from the shipped scenarios. Usage: run.sh SRC [RUNS]
# A fixed run count, not a time limit, keeps the test's verdict independent of machine load.
set -euo pipefail
src=$1 runs=${2:-20000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
command -v clang >/dev/null || { echo "fuzz: clang is not installed" >&2; exit 1; }
# shellcheck disable=SC2046
clang -std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
  -I"$src/include" -I"$src/src/scenario" $(pkg-config --cflags libcjson) \
  "$src/tests/fuzz/fuzz_scenario.c" "$src/src/scenario/scenario.c" "$src"/src/core/*.c \
  $(pkg-config --libs libcjson) -lccd -lm -o "$work/fuzz_scenario"
mkdir -p "$work/corpus"
cp "$src"/scenarios/*.json "$work/corpus/"
"$work/fuzz_scenario" -runs="$runs" -max_len=8192 -seed=1 \
  -dict="$src/tests/fuzz/scenario.dict" "$work/corpus" 2>"$work/log" || { tail -n 60 "$work/log"; exit 1; }
grep -E "DONE" "$work/log" || tail -n 3 "$work/log"
echo "fuzz_scenario: $runs inputs, no crash, no sanitizer report"
