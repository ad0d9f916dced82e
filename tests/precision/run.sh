#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Single and double precision plan identically: the shipped scenarios and seeded random
# encounters aimed at exact touches, planned by both builds (compare.py), and the exact
# conflict steps of the random ones checked in rational arithmetic (exact_oracle.py).
# COUNT: how many random encounters (default 120).
# Usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]
set -uo pipefail
double=${1:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
single=${2:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
src=${3:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
count=${4:-120}
here=$src/tests/precision
# This test is about numbers; the other command-line tests run the same commands with leak
# checking on. LeakSanitizer's scan at exit would double the cost of ~1,000 short runs.
export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0

python3 "$here/random_scenarios.py" --exact 1 "$count" "$tmp" || exit 1
echo "== shipped scenarios: plans and predictions, double against single"
python3 "$here/compare.py" "$double" "$single" "$src"/scenarios/*.json || failed=1
echo "== $count random encounters (seed 1, exactly representable samples), and their"
echo "   conflict steps against exact arithmetic"
python3 "$here/compare.py" --exact "$double" "$single" "$tmp"/*.json || failed=1
exit "$failed"
