#!/bin/bash
# SPDX-License-Identifier: MIT
# scripts/lossy.sh, the real processes each in a network namespace of its own with a share
# of every receiver's datagrams dropped, works: with no loss the paper's flight is the
# one-shot plan's (3240 m^2, effort 40, no fallback); with every datagram dropped nobody
# hears anybody, the UAVs fly their references into each other, and the log (the logger
# loses nothing) says so; at 30 % loss two flights of each mode keep separation (the
# figure from 20 of each is a measurement, docs/evaluation.md).
#
# usage: bash lossy.sh <path-to-coavoid> <source-dir>   (needs root for the namespaces;
# without them it says so and exits 77, which ctest reports as skipped)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
build=$(cd "$(dirname "$bin")/.." && pwd)
if [ "$(id -u)" -ne 0 ] || ! unshare --net --mount true 2>/dev/null || ! command -v nft >/dev/null; then
    echo "skipped: needs root, network namespaces and nftables: not flown"
    exit 77 # ctest's SKIP_RETURN_CODE (tests/CMakeLists.txt): skipped, not passed
fi
# Scenario seconds per wall second; SPEED overrides. The run with no loss, which must be the
# one-shot plan's, holds only while every plan meets its deadline: it flies at half that,
# as multiprocess.sh's exact flights do (tests/README.md, "Running them side by side");
# SPEED_EXACT overrides.
speed=${SPEED:-4}
speed_exact=${SPEED_EXACT:-2}
# The four runs fly side by side: each lossy.sh makes its namespaces inside a private
# network and mount namespace of its own, and a flight waits on its scenario clock far
# more than it computes. run NAME ARGS...: lossy.sh in the background, its output in
# $tmp/NAME.out and its exit status in $tmp/NAME.rc.
run() {
    local name=$1
    shift
    { "$src/scripts/lossy.sh" --build "$build" --out "$tmp/$name" "$@" >"$tmp/$name.out" 2>&1
      echo $? >"$tmp/$name.rc"; } &
}
# ok NAME PATTERN...: run NAME exited 0 and its output holds every PATTERN (grep -E).
ok() {
    local name=$1 pattern
    shift
    [ "$(cat "$tmp/$name.rc")" = 0 ] || return 1
    for pattern in "$@"; do
        grep -Eq -- "$pattern" "$tmp/$name.out" || return 1
    done
}
run none --runs 1 --speed "$speed_exact" --loss 0
run all --runs 1 --speed "$speed" --loss 100
for mode in centralised decoupled; do
    run "l30-$mode" --runs 2 --speed 2 --loss 30 --mode "$mode"
done
wait
# The flight must be the one-shot plan's; the coordinator's planning calls may be more than
# the 3 of a quiet machine: on loaded cores a plan agreed a cycle later is planned again
# (the same plan), which changes nothing flown.
if ok none "loss of separation: no, deviation 3240 m\^2, effort 40, replans ([3-9]|[1-9][0-9]), fallbacks 0, samples from an earlier plan 0" \
    ": 0 lost separation"; then
    pass
else
    fail "no loss: $(tail -n 3 "$tmp/none.out")"
fi
if ok all "loss of separation: yes" ": 1 lost separation"; then
    pass
else
    fail "all lost: $(tail -n 3 "$tmp/all.out")"
fi
for mode in centralised decoupled; do
    if ok "l30-$mode" ": 0 lost separation"; then
        pass
    else
        fail "30 % loss, $mode: $(tail -n 3 "$tmp/l30-$mode.out")"
    fi
done
finish
