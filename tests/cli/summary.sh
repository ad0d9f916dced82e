#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid summary` rebuilds a run from an lcm-logger log and judges it: on logs written by
# test_flight --write-log (the paper scenario planned, a head-on encounter flown without
# manoeuvre, logs with intents missing, an abandoned plan logged late, refused and foreign
# messages), the result follows the simulation result's contract and its numbers check out
# against an independent recomputation here; valid messages that cannot be the run's (an
# intent that disagrees with the scenario, a bit-flipped plans_run, a heartbeat of another
# node) are ignored and counted, and the verdict, costs and replans are the clean log's; truncated, corrupt and foreign files and every
# bad argument exit 2 with one line; the figure is well-formed XML. When lcm-logger and
# UDP multicast are available, a log written by the real logger gives the same answer.
#
# usage: bash summary.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 shows each message)
# The log writer is test_flight: $COAVOID_TEST_FLIGHT (set by ctest), else found beside
# the build's tests.
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
scenarios=$src/scenarios

writer=${COAVOID_TEST_FLIGHT:-}
if [ -z "$writer" ]; then
    if ! "$bin" summary --help >/dev/null 2>&1; then
        echo "FAIL: coavoid has no summary command (CMake adds this test only with LCM)" >&2
        exit 1
    fi
    writer=$(dirname "$bin")/../tests/test_flight
fi
if [ ! -x "$writer" ]; then
    echo "FAIL: no log writer at '$writer' (set COAVOID_TEST_FLIGHT to test_flight)"
    exit 1
fi

# write NAME SCENARIO KIND [OPTION...]: $tmp/NAME.log
write() {
    local name=$1
    shift
    if ! "$writer" --write-log "$tmp/$name.log" "$@" 2>"$tmp/writer.err"; then
        fail "writing $name.log: $(cat "$tmp/writer.err")"
        return 1
    fi
}

# The contract's fields in order, then ours; numbers recomputed from the scenario: the
# flown x, y on the reference (straight routes at cruise speed), offsets (z - z_ref) / dh
# whole numbers moving by actions, and deviation and effort from those offsets by the
# contract's formula.
cat >"$tmp/check.py" <<'PY'
import json, math, sys

def check(result_path, scenario_path, expect):
    r = json.load(open(result_path))
    s = json.load(open(scenario_path))
    keys = list(r)
    contract = ["scenario", "mode", "steps", "replans", "loss_of_separation", "deviation",
                "effort"]
    assert keys[:7] == contract, keys
    assert "vehicles" in keys and "log" in keys, keys
    assert r["scenario"] == s["name"]
    assert isinstance(r["loss_of_separation"], bool)
    assert isinstance(r["effort"], int) and isinstance(r["steps"], int)
    K, dt = r["steps"], s["dt"]
    ids = [v["id"] for v in s["vehicles"]]
    assert [v["id"] for v in r["vehicles"]] == ids
    total_dev, total_eff = 0.0, 0
    for sv, rv in zip(s["vehicles"], r["vehicles"]):
        flown = rv["flown"]
        assert len(flown) == K + 1, len(flown)
        (x0, y0, z0), (x1, y1, z1) = sv["route"][0], sv["route"][-1]
        length = math.hypot(x1 - x0, y1 - y0)
        ux, uy = (x1 - x0) / length, (y1 - y0) / length
        dh = sv["climb_rate"] * dt
        s_f = sv.get("steep_factor", 2)
        offsets = []
        for k, (t, x, y, z) in enumerate(flown):
            assert t == k * dt, (k, t)
            d = sv["cruise_speed"] * t
            # Within float's precision too (COAVOID_SINGLE_PRECISION builds).
            scale = max(1.0, abs(x0), abs(y0), abs(z0), abs(x1), abs(y1), abs(z1), d)
            near = lambda a, b: abs(a - b) <= 1e-6 * scale
            assert near(x, x0 + ux * d) and near(y, y0 + uy * d), (k, x, y)
            zr = z0 + (z1 - z0) * d / length
            o = (z - zr) / dh
            assert abs(o - round(o)) < 1e-4, (k, z, zr)
            offsets.append(round(o))
        L = sv["cruise_speed"] * dt
        dev, eff = 0.0, 0
        for a, b in zip(offsets, offsets[1:]):
            assert b - a in (0, 1, -1, s_f, -s_f), (a, b)
            eff += {0: 0, 1: 1, s_f: 3}[abs(b - a)]
            area = (abs(a) + abs(b)) / 2 if a * b >= 0 else (a * a + b * b) / (2 * abs(a - b))
            dev += L * dh * area
        assert abs(dev - rv["deviation"]) < 1e-6 * max(1, dev), (dev, rv["deviation"])
        assert eff == rv["effort"], (eff, rv["effort"])
        total_dev += dev
        total_eff += eff
    assert abs(total_dev - r["deviation"]) < 1e-6 * max(1, total_dev)
    assert total_eff == r["effort"]
    for key, value in expect.items():
        if key.startswith("log."):
            got = r["log"][key[4:]]
        elif key.startswith("first_loss."):
            got = r["first_loss"][key[11:]]
        else:
            got = r[key]
        assert got == value, f"{key}: {got!r}, expected {value!r}"
    assert r["loss_of_separation"] == ("first_loss" in r)

expect = json.loads(sys.argv[3]) if len(sys.argv) > 3 else {}
check(sys.argv[1], sys.argv[2], expect)
PY

# check_json DESCRIPTION SCENARIO EXPECT_JSON: $tmp/out against the scenario.
check_json() {
    if python3 "$tmp/check.py" "$tmp/out" "$2" "$3" 2>"$tmp/py.err"; then
        pass
    else
        fail "$1: $(tail -n 3 "$tmp/py.err")"
    fi
}

# ---- the paper scenario, planned centrally once at cycle 0 (one plan: a message per UAV) ----
paper=$scenarios/paper.json
if write paper "$paper" planned junk; then
    if expect_status "paper: text" 0 summary "$tmp/paper.log" "$paper" --mode centralised; then
        for line in "loss of separation: no" "replans: 1" "steps: 48 " \
            "147 from their cycle's own intent, 0 from an earlier plan, 0 not covered" \
            "1 refused, 1 from UAVs not in the scenario" \
            "first refused intent: intent: position non-finite"; do
            if grep -qF -- "$line" "$tmp/out"; then pass; else fail "paper text lacks '$line'"; fi
        done
    fi
    if expect_status "paper: json" 0 summary "$tmp/paper.log" "$paper" --mode centralised \
        --json --svg "$tmp/paper.svg"; then
        check_json "paper json" "$paper" '{"mode": "centralised", "steps": 48, "replans": 1,
            "loss_of_separation": false, "log.intents": 149, "log.intents_refused": 1,
            "log.intents_other_uavs": 1, "log.plans": 3, "log.samples_own_intent": 147,
            "log.samples_missing": 0, "log.epoch_utime": 1700000000000000}'
        cp "$tmp/out" "$tmp/paper.json"
        if python3 -c 'import xml.dom.minidom,sys
d = xml.dom.minidom.parse(sys.argv[1]).documentElement
assert d.tagName == "svg", d.tagName
assert not d.getElementsByTagName("script")' "$tmp/paper.svg" 2>"$tmp/py.err"; then
            pass
        else
            fail "paper.svg is not a well-formed SVG: $(tail -n 2 "$tmp/py.err")"
        fi
    fi
    # The same run with intents missing (UAV 2's of cycles 5 and 6: earlier plans reach
    # them; UAV 1's of cycle 0: nothing does) and UAV 3's plan of cycle 2 logged again at
    # the end, abandoned (level): flown exactly as before but for UAV 1's first sample,
    # which comes from the scenario at the initial offset, the same here.
    if write gap "$paper" planned drop=2:5 drop=2:6 drop=1:0 stale=3:2 &&
        expect_status "gaps: json" 0 summary "$tmp/gap.log" "$paper" --mode centralised --json; then
        check_json "gaps json" "$paper" '{"log.samples_earlier_plan": 2,
            "log.samples_missing": 1, "log.samples_own_intent": 144}'
        if python3 -c 'import json,sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert [v["flown"] for v in a["vehicles"]] == [v["flown"] for v in b["vehicles"]]
assert [v.get("unknown_samples") for v in b["vehicles"]] == [1, 0, 0]
assert (a["deviation"], a["effort"]) == (b["deviation"], b["effort"])' \
            "$tmp/paper.json" "$tmp/out" 2>"$tmp/py.err"; then
            pass
        else
            fail "gaps changed the flight: $(tail -n 2 "$tmp/py.err")"
        fi
    fi
    # A later epoch: cycle 0 is the log's cycle 5, so cycles 0..43 are judged.
    if expect_status "--epoch" 0 summary "$tmp/paper.log" "$paper" --mode centralised --json \
        --epoch 1700000005000000; then
        # (Not check_json: t counts from the new epoch, so positions are shifted by 5 s.)
        if python3 -c 'import json,sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert b["steps"] == 43 and b["log"]["epoch_utime"] == 1700000005000000, b["steps"]
for va, vb in zip(a["vehicles"], b["vehicles"]):
    assert [p[1:] for p in va["flown"][5:]] == [p[1:] for p in vb["flown"]]' \
            "$tmp/paper.json" "$tmp/out" 2>"$tmp/py.err"; then
            pass
        else
            fail "--epoch: $(tail -n 2 "$tmp/py.err")"
        fi
    fi
fi

# ---- valid messages that cannot be the run's: ignored and counted, the verdict kept ----
# Copies of the paper log's messages, changed and inserted after the original (a forgery,
# or a bit flip that still validates), encoded with the types lcm-gen generates for
# Python. Each log is judged as the clean one ($tmp/paper.json): same verdict, steps,
# replans, costs and flight; the log object counts what was ignored, and why.
if [ -f "$tmp/paper.json" ] && ! lcm-gen -p --ppath "$tmp/py" "$src"/lcmtypes/*.lcm >/dev/null 2>&1; then
    fail "lcm-gen -p failed: cannot write changed messages"
elif [ -f "$tmp/paper.json" ]; then
    # mutate.py IN OUT EDIT...: OUT is IN with, per EDIT, a changed copy of a message
    # inserted right after it, or every intent of a UAV changed in place:
    #   intent:UAV:CYCLE:CHANGES   a copy of UAV's intent of cycle CYCLE (its sequence)
    #   status:NODE:SEQ:CHANGES    a copy of node NODE's heartbeat with sequence SEQ
    #   every-intent:UAV:CHANGES   every intent of UAV changed
    #   reference:UAV:CYCLE:DX     a copy of UAV's intent of cycle CYCLE with every
    #                              reference point moved DX m east
    # CHANGES: field=value or field+=delta, comma-separated.
    cat >"$tmp/mutate.py" <<'PY'
import struct, sys
sys.path.insert(0, sys.argv[1])
from coavoid import intent_t, status_t
src, out, edits = sys.argv[2], sys.argv[3], [e.split(":") for e in sys.argv[4:]]
data = open(src, "rb").read()
events, i = [], 0
while i < len(data):
    magic, number, utime, clen, dlen = struct.unpack_from(">Iqqii", data, i)
    channel = data[i + 28:i + 28 + clen]
    payload = data[i + 28 + clen:i + 28 + clen + dlen]
    events.append([utime, channel, payload])
    i += 28 + clen + dlen

def change(m, changes):
    for c in changes.split(","):
        if "+=" in c:
            field, value = c.split("+=")
            setattr(m, field, getattr(m, field) + type(getattr(m, field))(value))
        else:
            field, value = c.split("=")
            setattr(m, field, type(getattr(m, field))(value))
    return m.encode()

done, result = set(), []
for utime, channel, payload in events:
    result.append([utime, channel, payload])
    for n, e in enumerate(edits):
        if channel == b"COAVOID_INTENT" and e[0] in ("intent", "every-intent", "reference"):
            m = intent_t.decode(payload)
            if m.uav_id != int(e[1]) or (e[0] != "every-intent" and m.sequence != int(e[2])):
                continue
            if e[0] == "reference":
                m.reference = [[r[0] + float(e[3]), r[1], r[2]] for r in m.reference]
                result.append([utime + 1, channel, m.encode()])
            elif e[0] == "intent":
                result.append([utime + 1, channel, change(m, e[3])])
            else:
                result[-1][2] = change(m, e[2])
            done.add(n)
        elif channel == b"COAVOID_STATUS" and e[0] == "status":
            m = status_t.decode(payload)
            if m.node_id == int(e[1]) and m.sequence == int(e[2]):
                result.append([utime + 1, channel, change(m, e[3])])
                done.add(n)
assert done == set(range(len(edits))), f"no message for {[edits[n] for n in range(len(edits)) if n not in done]}"
with open(out, "wb") as f:
    for number, (utime, channel, payload) in enumerate(result):
        f.write(struct.pack(">Iqqii", 0xEDA1DA01, number, utime, len(channel), len(payload)))
        f.write(channel + payload)
PY
    # same_run DESCRIPTION LOG EXPECT_JSON: LOG's JSON result is the clean log's but for
    # the log object, which has EXPECT_JSON's values.
    same_run() {
        local what=$1 log=$2 expect=$3
        if expect_status "$what: json" 0 summary "$log" "$paper" --mode centralised --json; then
            if python3 - "$tmp/paper.json" "$tmp/out" "$expect" 2>"$tmp/py.err" <<'PY'; then
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for k in ("steps", "replans", "loss_of_separation", "deviation", "effort"):
    assert a[k] == b[k], (k, a[k], b[k])
assert [v["flown"] for v in a["vehicles"]] == [v["flown"] for v in b["vehicles"]]
assert list(b["log"])[:len(a["log"])] == list(a["log"]), "the log object's keys moved"
for k, v in json.loads(sys.argv[3]).items():
    got = b["log"].get(k)
    ok = v in got if isinstance(v, str) and k.startswith("first_") else got == v
    assert ok, f"log.{k}: {got!r}, expected {v!r}"
PY
                pass
            else
                fail "$what: $(tail -n 2 "$tmp/py.err")"
            fi
        fi
    }
    # write_mutated NAME EDIT...: $tmp/NAME.log from the paper log.
    write_mutated() {
        local name=$1
        shift
        if python3 "$tmp/mutate.py" "$tmp/py" "$tmp/paper.log" "$tmp/$name.log" "$@" 2>"$tmp/py.err"; then
            return 0
        fi
        fail "writing $name.log: $(tail -n 2 "$tmp/py.err")"
        return 1
    }
    # 1. An intent of UAV 2 at cycle 24 with another cruise speed: one ignored intent.
    if write_mutated odd_intent intent:2:24:cruise_speed+=1; then
        same_run "an odd intent" "$tmp/odd_intent.log" '{"intents": 150, "intents_refused": 1,
            "intents_other_uavs": 1, "intents_ignored": 1, "heartbeats_ignored": 0,
            "samples_own_intent": 147, "first_ignored_intent": "UAV 2'"'"'s cruise_speed"}'
        if expect_status "an odd intent: text" 0 summary "$tmp/odd_intent.log" "$paper" --mode centralised; then
            for line in "ignored: 1 intents (of scenario UAVs, disagreeing with the scenario); 0 heartbeats" \
                "first ignored intent: intent: UAV 2's cruise_speed" "loss of separation: no"; do
                if grep -qF -- "$line" "$tmp/out"; then pass; else fail "odd intent text lacks '$line'"; fi
            done
        fi
    fi
    # ... one of UAV 2 at cycle 24, well-formed and of its own performance, whose
    # reference says it is 50 m east of its route: ignored, the flight the clean one's.
    if write_mutated moved_reference reference:2:24:50; then
        same_run "a moved reference" "$tmp/moved_reference.log" '{"intents_ignored": 1,
            "first_ignored_intent": "UAV 2'"'"'s reference at cycle 24"}'
    fi
    # ... and one of UAV 1 at cycle 0 with another radius.
    if write_mutated odd_radius intent:1:0:radius+=5; then
        same_run "an odd radius" "$tmp/odd_radius.log" '{"intents_ignored": 1,
            "first_ignored_intent": "UAV 1'"'"'s radius"}'
    fi
    # 2. The coordinator's heartbeat of cycle 20 again with bit 30 of plans_run (1) set:
    # 1073741824 more planning calls than in its heartbeat just before, when it makes at
    # most 2 x 4 + 4 a cycle (2 per cluster, a cluster per UAV: the scenario's 3 and the
    # junk's UAV 4242; 4 more when it escalates).
    if write_mutated flipped_heartbeat status:65001:20:plans_run=1073741825; then
        same_run "a bit-flipped plans_run" "$tmp/flipped_heartbeat.log" '{"heartbeats": 197,
            "heartbeats_refused": 0, "heartbeats_ignored": 1, "heartbeats_ignored_too_fast": 1,
            "intents_ignored": 0,
            "first_ignored_heartbeat": "coordinator 65001'"'"'s plans_run goes from 1 to 1073741825 in 1 cycles; it plans at most 12 times a cycle"}'
        if expect_status "a bit-flipped plans_run: text" 0 summary "$tmp/flipped_heartbeat.log" "$paper" --mode centralised; then
            if grep -qxF "replans: 1" "$tmp/out"; then pass; else fail "bit-flipped plans_run: $(grep replans "$tmp/out")"; fi
            for line in "197 heartbeats (0 refused)" \
                "ignored: 0 intents (of scenario UAVs, disagreeing with the scenario); 1 heartbeats (0 of nodes not in the run, 0 with plans_run going back, 1 with plans_run growing faster than the node can plan)" \
                "first ignored heartbeat: heartbeat: coordinator 65001's plans_run goes from 1 to 1073741825"; do
                if grep -qF -- "$line" "$tmp/out"; then pass; else fail "bit-flipped plans_run text lacks '$line'"; fi
            done
        fi
    fi
    # Other heartbeats that would have added to the replans: 3257807038 (plans_run is an
    # int32: negative, refused by validation), another coordinator id (a flipped node_id)
    # and a UAV that is not in the scenario, each with a plans_run of their own; one that
    # goes back; a UAV's first heartbeat with more than its 2 planning calls.
    if write_mutated odd_heartbeats status:65001:21:plans_run=-1037160258 \
        status:65001:22:node_id=65003 status:1:5:node_id=77,plans_run=2 \
        status:65001:30:plans_run=0 status:2:0:plans_run=3; then
        same_run "odd heartbeats" "$tmp/odd_heartbeats.log" '{"heartbeats": 201,
            "heartbeats_refused": 1, "heartbeats_ignored": 4, "heartbeats_ignored_other_nodes": 2,
            "heartbeats_ignored_backwards": 1, "heartbeats_ignored_too_fast": 1,
            "first_ignored_heartbeat": "heartbeat: UAV 2'"'"'s plans_run goes from 0 to 3 in 1 cycles"}'
    fi
    # 3. An intent of a UAV that is not in the scenario: counted as such, not ignored.
    if write_mutated other_uav intent:2:10:uav_id=77; then
        same_run "an intent of UAV 77" "$tmp/other_uav.log" '{"intents": 150,
            "intents_other_uavs": 2, "intents_ignored": 0, "intents_refused": 1}'
    fi
    # An intent with bit 20 of plan_utime flipped (2^20 us earlier): off the run's cycle
    # grid, it neither becomes the epoch nor spoils the cycles.
    if write_mutated off_grid intent:1:0:plan_utime+=-1048576; then
        same_run "an intent off the grid" "$tmp/off_grid.log" '{"intents_off_grid": 1,
            "epoch_utime": 1700000000000000, "intents_ignored": 0}'
    fi
    # Every intent of UAV 2 with another radius: not a run of the scenario.
    if write_mutated all_odd every-intent:2:radius+=1; then
        also="not a run of this scenario" expect_bad "every intent of a UAV odd" \
            "UAV 2 of $paper never published an accepted intent: its intents have radius" \
            summary "$tmp/all_odd.log" "$paper" --mode centralised
    fi
fi

# ---- head-on, no manoeuvre: a loss of separation over step 13 (300 - 20 t < 30) ----
headon=$scenarios/headon.json
if write headon "$headon" reference; then
    if expect_status "head-on: json" 1 summary "$tmp/headon.log" "$headon" --mode decoupled \
        --json; then
        check_json "head-on json" "$headon" '{"mode": "decoupled", "loss_of_separation": true,
            "first_loss.vehicle": 1, "first_loss.step": 13, "replans": 0, "effort": 0}'
    fi
    if expect_status "head-on: text" 1 summary "$tmp/headon.log" "$headon" --mode decoupled &&
        ! grep -qF "loss of separation: yes, first over step 13 (t = 13 s): UAV 1 and UAV 2" "$tmp/out"; then
        fail "head-on text: $(grep 'loss of' "$tmp/out")"
    fi
fi

# ---- bad logs: one line, exit 2, never a crash ----
if [ -f "$tmp/headon.log" ]; then
    # Cut and corrupt at event boundaries found here.
    python3 - "$tmp/headon.log" "$tmp" <<'PY'
import struct, sys
path, out = sys.argv[1], sys.argv[2]
d = open(path, "rb").read()
starts, o = [], 0
while o < len(d):
    _, _, _, cl, dl = struct.unpack(">Iqqii", d[o:o + 28])
    starts.append(o)
    o += 28 + cl + dl
last = starts[-1]
open(out + "/cut_data.log", "wb").write(d[:len(d) - 10])
open(out + "/cut_header.log", "wb").write(d[:last + 10])
open(out + "/cut_magic.log", "wb").write(d[:last + 2])
second = starts[1]
bad = bytearray(d); bad[second] ^= 0xff
open(out + "/bad_magic.log", "wb").write(bytes(bad))
def with_lengths(cl, dl):
    b = bytearray(d); b[second + 20:second + 28] = struct.pack(">ii", cl, dl)
    return bytes(b)
open(out + "/huge_data.log", "wb").write(with_lengths(14, 2**31 - 1))
open(out + "/negative_data.log", "wb").write(with_lengths(14, -1))
open(out + "/negative_channel.log", "wb").write(with_lengths(-1, 100))
open(out + "/long_channel.log", "wb").write(with_lengths(5000, 100))
# Garbage between events: LCM's reader would skip it silently.
open(out + "/garbage.log", "wb").write(d[:second] + b"garbage" + d[second:])
PY
    also= expect_bad "truncated in data" "truncated" summary "$tmp/cut_data.log" "$headon" --mode decoupled
    also= expect_bad "truncated in header" "truncated" summary "$tmp/cut_header.log" "$headon" --mode decoupled
    also= expect_bad "truncated in magic" "truncated" summary "$tmp/cut_magic.log" "$headon" --mode decoupled
    also= expect_bad "bad magic" "corrupt: no event header at byte" summary "$tmp/bad_magic.log" "$headon" --mode decoupled
    also= expect_bad "garbage between events" "corrupt" summary "$tmp/garbage.log" "$headon" --mode decoupled
    also= expect_bad "data length 2^31-1" "corrupt" summary "$tmp/huge_data.log" "$headon" --mode decoupled
    also= expect_bad "negative data length" "corrupt" summary "$tmp/negative_data.log" "$headon" --mode decoupled
    also= expect_bad "negative channel length" "corrupt" summary "$tmp/negative_channel.log" "$headon" --mode decoupled
    also= expect_bad "long channel" "corrupt" summary "$tmp/long_channel.log" "$headon" --mode decoupled
fi
also= expect_bad "a scenario is not a log" "not an LCM log" summary "$headon" "$headon" --mode decoupled
# A centralised run's log (its UAVs followed the coordinator's plan) said to be decoupled.
if [ -f "$tmp/paper.log" ]; then
    also= expect_bad "a centralised log as decoupled" "followed a coordinator at" \
        summary "$tmp/paper.log" "$paper" --mode decoupled
fi
: >"$tmp/empty.log"
also= expect_bad "empty log" "empty file" summary "$tmp/empty.log" "$headon" --mode decoupled
also= expect_bad "no such log" "cannot open" summary "$tmp/nothing.log" "$headon" --mode decoupled
also= expect_bad "a directory" "not a regular file" summary "$tmp" "$headon" --mode decoupled

# ---- logs that are not a run of the scenario ----
if write skip "$headon" reference skip=2; then
    also="never published" expect_bad "a UAV never seen" "UAV 2" summary "$tmp/skip.log" "$headon" --mode decoupled
fi
if [ -f "$tmp/headon.log" ]; then
    also="never published" expect_bad "another scenario" "UAV 3" summary "$tmp/headon.log" "$paper" --mode decoupled
    also= expect_bad "epoch off the cycle grid" "no cycle after cycle 0" summary "$tmp/headon.log" "$headon" --mode decoupled --epoch 1700000000000001
fi
if write step "$headon" reference step=0.5; then
    also="not a run of this scenario" expect_bad "another dt" "step" summary "$tmp/step.log" "$headon" --mode decoupled
fi
if write one "$headon" reference cycles=1; then
    also= expect_bad "one cycle only" "no cycle after cycle 0" summary "$tmp/one.log" "$headon" --mode decoupled
fi
printf '{"name": "x"}' >"$tmp/bad_scenario.json"
also= expect_bad "invalid scenario" "bad_scenario.json" summary "$tmp/headon.log" "$tmp/bad_scenario.json" --mode decoupled

# ---- usage ----
log=$tmp/headon.log
also= expect_bad "no arguments" "missing LOGFILE" summary
also= expect_bad "no scenario" "missing SCENARIO.json" summary "$log"
also= expect_bad "no mode" "--mode" summary "$log" "$headon"
also= expect_bad "bad mode" "--mode" summary "$log" "$headon" --mode sideways
also= expect_bad "mode twice" "--mode" summary "$log" "$headon" --mode decoupled --mode decoupled
also= expect_bad "third argument" "unexpected argument" summary "$log" "$headon" "$headon" --mode decoupled
also= expect_bad "log and scenario swapped" "the log comes first" summary "$headon" "$log" --mode decoupled
also= expect_bad "unknown option" "unknown option" summary "$log" "$headon" --mode decoupled --fast
also= expect_bad "epoch 0" "--epoch" summary "$log" "$headon" --mode decoupled --epoch 0
also= expect_bad "epoch text" "--epoch" summary "$log" "$headon" --mode decoupled --epoch soon
also= expect_bad "json with a value" "--json" summary "$log" "$headon" --mode decoupled --json=yes
also= expect_bad "svg nowhere" "--svg" summary "$log" "$headon" --mode decoupled --svg "$tmp/no/such/dir/x.svg"
if "$bin" summary --help >"$tmp/out" 2>&1 && grep -q "usage: coavoid summary" "$tmp/out"; then
    pass
else
    fail "summary --help"
fi

# ---- a log written by lcm-logger itself (when it and multicast are available) ----
if command -v lcm-logger >/dev/null && [ -f "$tmp/paper.json" ]; then
    url="udpm://239.255.76.67:$((7700 + $$ % 200))?ttl=0"
    lcm-logger --lcm-url="$url" "$tmp/real.log" >"$tmp/logger.out" 2>&1 &
    logger=$!
    sleep 1
    if "$writer" --publish "$url" "$paper" planned junk 2>"$tmp/writer.err"; then
        sleep 0.5
        kill -INT "$logger"
        wait "$logger"
        if [ ! -s "$tmp/real.log" ]; then
            echo "lcm-logger part skipped: the logger heard nothing on $url (no multicast loopback?)"
        elif expect_status "lcm-logger log" 0 summary "$tmp/real.log" "$paper" --mode centralised --json; then
            if python3 -c 'import json,sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for k in ("steps", "replans", "deviation", "effort", "loss_of_separation"):
    assert a[k] == b[k], (k, a[k], b[k])
assert [v["flown"] for v in a["vehicles"]] == [v["flown"] for v in b["vehicles"]]' \
                "$tmp/paper.json" "$tmp/out" 2>"$tmp/py.err"; then
                pass
            else
                fail "lcm-logger's log differs from the written one: $(tail -n 2 "$tmp/py.err")"
            fi
        fi
    else
        kill -INT "$logger" 2>/dev/null
        wait "$logger" 2>/dev/null
        echo "lcm-logger part skipped: cannot publish on $url ($(cat "$tmp/writer.err"))"
    fi
fi

finish
