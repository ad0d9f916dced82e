#!/bin/bash
# SPDX-License-Identifier: MIT
# A flood without keys does not cost the fleet its separation (docs/security.md,
# "Floods"): the paper's encounter flown by the real processes, each in a network
# namespace of its own (scripts/lossy.sh), while a flooder sends copies of every channel's
# latest datagrams with their stamps moved ahead and their signatures broken, as fast as
# it can up to 100,000 a second, for the whole flight, once per mode. Each flight must
# keep separation, every node must refuse the flood from its tail or its fleet tag (never
# by a signature check) and drop nothing unchecked but at its socket (the tail and the
# tag, not the signature budget, stop it), and every UAV's first intent of each cycle must
# be heard within 50 ms (wall) of the cycle's start, except in decoupled cycles where it
# waits for the UAVs before it (bounded by the priority wait).
# Everything it sends stays inside the namespaces of the run.
#
# usage: bash flood.sh <path-to-coavoid> <source-dir> <path-to-coavoid_test_flood>
# (needs root for the namespaces; without them it says so and exits 77, which ctest
# reports as skipped)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
build=$(cd "$(dirname "$bin")/.." && pwd)
[ -x "${3:-}" ] || { fail "no flooder (argument 3: coavoid_test_flood)"; finish; exit; }
if [ "$(id -u)" -ne 0 ] || ! unshare --net --mount true 2>/dev/null || ! command -v nft >/dev/null; then
    echo "skipped: needs root, network namespaces and nftables: not flown"
    exit 77 # ctest's SKIP_RETURN_CODE (tests/CMakeLists.txt): skipped, not passed
fi
for mode in centralised decoupled; do
    out=$tmp/$mode
    if ! "$src/scripts/lossy.sh" --runs 1 --loss 0 --speed 4 --mode "$mode" --flood fresh \
        --build "$build" --out "$out" >"$tmp/$mode.out" 2>&1; then
        fail "$mode: lossy.sh failed: $(tail -n 3 "$tmp/$mode.out")"
        continue
    fi
    late=50
    [ "$mode" = decoupled ] && late=1e9 # a decoupled intent may wait for its predecessors
    if python3 - "$out/run-1/flood.json" "$late" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "$mode: $(tail -n 5 "$tmp/py")"; fi
import json, sys
f = json.load(open(sys.argv[1]))
assert f["loss_of_separation"] is False, f
assert f["sent"] >= 10000, ("the flooder sent too little to judge", f["sent"])
assert f["worst_late_ms"] <= float(sys.argv[2]), ("an intent heard late", f["worst_late_ms"])
for node, n in f["nodes"].items():
    # Refused from the tail (a copy -124, a stamp too far ahead -125) or the tag (-126):
    # the heartbeats sample the last refusal's code, never a signature's (-122).
    assert n["refused"] >= 1000, (node, n)
    assert set(n["codes"]) <= {0, -124, -125, -126} and set(n["codes"]) & {-124, -125, -126}, (node, n)
    # Dropped unchecked: only at the socket (its summary line's count), never over the
    # signature budget, which the flood cannot reach.
    socket = f["sockets"]["coordinator" if node == "65001" else "vehicle-" + node]
    assert n["dropped"] <= socket["dropped"], (node, "dropped over its budget", n, socket)
    assert n["reasons"] & 4, (node, "refusals not in its health", n)
PY
done
finish
