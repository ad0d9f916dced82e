#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A repeatable cost of planning the paper scenario: the instructions executed (callgrind's
# Ir) by `coavoid plan scenarios/paper.json`, centralised and decoupled. Unlike times, the
# count does not depend on the machine's load or clock, so it compares commits exactly
# (same compiler, same flags). The whole process is counted (start-up, JSON parsing,
# sampling and output too); planning dominates the centralised count, not the decoupled one.
#
# usage: scripts/bench_callgrind.sh [--build DIR] [--scenario FILE]
#
#   --build     a Release build directory with apps/coavoid (nothing is built here);
#               default build-release
#   --scenario  default scenarios/paper.json
#
# Needs valgrind (Debian package valgrind). Prints one line per mode, "MODE: Ir N
# (plan exit E)"; exits 2 on bad usage, 1 when valgrind or coavoid is missing or
# callgrind fails.
set -u

here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="build-release"
scenario=$here/scenarios/paper.json
while [ $# -gt 0 ]; do
    case $1 in
    --build) build=${2:?--build: missing value}; shift 2 ;;
    --scenario) scenario=${2:?--scenario: missing value}; shift 2 ;;
    -h | --help) sed -n '3,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_callgrind.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done

bin=$build/apps/coavoid
if ! command -v valgrind >/dev/null; then
    echo "bench_callgrind.sh: valgrind not found (apt-get install valgrind)" >&2
    exit 1
fi
if [ ! -x "$bin" ]; then
    echo "bench_callgrind.sh: no $bin (build Release first: cmake -S . -B $build -DCMAKE_BUILD_TYPE=Release && cmake --build $build)" >&2
    exit 1
fi
if ! grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$build/CMakeCache.txt" 2>/dev/null; then
    echo "bench_callgrind.sh: warning: $build is not a Release build; counts will not compare" >&2
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
for mode in centralised decoupled; do
    valgrind --tool=callgrind --callgrind-out-file="$tmp/$mode.out" \
        "$bin" plan "$scenario" --mode "$mode" >"$tmp/$mode.json" 2>"$tmp/$mode.err"
    rc=$?
    # callgrind's file ends with "totals: N" (or "summary: N"): the Ir of the whole run.
    ir=$(sed -n 's/^\(totals\|summary\): \([0-9]*\).*/\2/p' "$tmp/$mode.out" 2>/dev/null | tail -n 1)
    if [ -z "$ir" ]; then
        echo "bench_callgrind.sh: $mode: callgrind gave no total: $(tail -n 3 "$tmp/$mode.err")" >&2
        status=1
        continue
    fi
    # plan exits 1 when the plan is not solved: still a count, but say so.
    echo "$mode: Ir $ir (plan exit $rc)"
done
exit $status
