#!/usr/bin/env bash
# Single and double precision plan identically: the shipped scenarios and seeded random
# encounters aimed at exact touches, planned by both builds (compare.py), and the exact
# conflict steps of the random ones checked in rational arithmetic (exact_oracle.py).
# Usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]
set -uo pipefail
double=${1:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
single=${2:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
src=${3:?usage: run.sh DOUBLE_COAVOID SINGLE_COAVOID SOURCE_DIR [COUNT]}
count=${4:-200}
here=$src/tests/precision
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0

python3 "$here/random_scenarios.py" --exact 1 "$count" "$tmp" || exit 1
echo "== shipped scenarios: plans and predictions, double against single"
python3 "$here/compare.py" "$double" "$single" "$src"/scenarios/*.json || failed=1
echo "== $count random encounters (seed 1, exactly representable samples)"
python3 "$here/compare.py" "$double" "$single" "$tmp"/*.json || failed=1
echo "== their conflicts against exact arithmetic"
# The double build's answers only: the comparison above has shown the single build's equal.
python3 "$here/exact_oracle.py" "$double" "$tmp"/*.json || failed=1
exit "$failed"
