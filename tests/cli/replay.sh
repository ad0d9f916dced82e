#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid sim --record-vehicle` and `coavoid replay` (src/replay): a UAV's record of the
# paper's encounter, in each mode, replays on the protocol library with every datagram sent
# and every state as recorded, and the flight with a record is the flight without; a record
# with one sent byte or one state byte changed replays as different (exit 1, the record
# named), a cut or foreign file is refused (exit 2), and so are a UAV the scenario lacks and
# a malformed --record-vehicle.
#
# usage: bash replay.sh <path-to-coavoid> <source-dir>
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
paper=$src/scenarios/paper.json

for mode in decoupled centralised; do
    "$bin" sim "$paper" --mode "$mode" --json >"$tmp/plain.json"
    if "$bin" sim "$paper" --mode "$mode" --json --record-vehicle "2:$tmp/$mode.rec" \
        >"$tmp/recorded.json" && cmp -s "$tmp/plain.json" "$tmp/recorded.json"; then
        pass
    else
        fail "$mode: the flight with a record is not the flight without"
    fi
    expect_ok "$mode: replay" replay "$tmp/$mode.rec"
    grep -q "^replay: UAV 2 ($mode), 49 cycles, .* sent: all as recorded$" "$tmp/out" ||
        fail "$mode: replay said: $(cat "$tmp/out")"
done

# One byte changed in the 100th SENT record, and in the 100th STATE record.
python3 - "$tmp/decoupled.rec" "$tmp" <<'PY'
import struct, sys
d = bytearray(open(sys.argv[1], "rb").read())
at, seen, where = 8, {5: 0, 6: 0}, {}
while at < len(d):
    kind, _, cl, pl = struct.unpack_from("<BBHI", d, at)
    if kind in seen:
        seen[kind] += 1
        if seen[kind] == 100:
            where[kind] = at + 16 + cl + pl // 2
    at += 16 + cl + pl
for kind, name in ((5, "sent"), (6, "state")):
    m = bytearray(d)
    m[where[kind]] ^= 0x10
    open(f"{sys.argv[2]}/{name}.rec", "wb").write(m)
open(f"{sys.argv[2]}/cut.rec", "wb").write(d[: len(d) // 3])
PY
for what in sent state; do
    "$bin" replay "$tmp/$what.rec" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ "$rc" -eq 1 ] && grep -q "^coavoid replay: .*$what.rec: record [0-9]*: " "$tmp/err"; then
        pass
    else
        fail "a changed $what byte: exit $rc, stderr $(cat "$tmp/err")"
    fi
done
expect_bad "a cut record" "is truncated or bad" replay "$tmp/cut.rec"
expect_bad "not a record" "not a vehicle's record" replay "$paper"
expect_bad "no such file" "cannot be read" replay "$tmp/none.rec"
expect_bad "no such UAV" "has no UAV 9" sim "$paper" --mode decoupled --record-vehicle "9:$tmp/x.rec"
expect_bad "no file" "--record-vehicle: must be ID:FILE" sim "$paper" --mode decoupled \
    --record-vehicle 2
finish
