#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid summary` rebuilds a run from an lcm-logger log and judges it: on logs written by
# test_flight --write-log (the paper scenario planned, a head-on encounter flown without
# manoeuvre, logs with intents missing, an abandoned plan logged late, refused and foreign
# messages), the result follows the simulation result's contract and its numbers check out
# against an independent recomputation here; truncated, corrupt and foreign files and every
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

# ---- the paper scenario, planned centrally once at cycle 0 ----
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
            "log.intents_other_uavs": 1, "log.plans": 1, "log.samples_own_intent": 147,
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
