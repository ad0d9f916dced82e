#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid bench auth` runs (a few repeats) and prints every key: every message type with
# its size, sign and verify times, every fleet's nodes with their cycle, and no check that
# failed; the JSON form has the same; the per-cycle counts follow the protocol; bad options
# exit 2 with one line naming the option. Never its times: a benchmark is not a timed test.
#
# usage: bash bench_auth.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 shows each message)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"

# The text form, default fleets (the demo's 3 UAVs, and 100).
if expect_ok text bench auth --repeat 3; then
    if python3 - "$tmp/out" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "text: $(tail -n 5 "$tmp/py")"; fi
import sys
lines = open(sys.argv[1]).read().splitlines()
kv = {}
for line in lines:
    k, sep, v = line.partition(": ")
    assert sep and k not in kv, line
    kv[k] = v
assert kv.pop("benchmark") == "auth", kv
v = {k: float(x) for k, x in kv.items()}
assert v["repeat"] == 3 and v["verify_failures"] == 0 and v["auth_bytes_per_message"] == 92, v
assert v["signer_bytes"] > 64 and v["trust_list_bytes"] > 0, v
types = ["intent", "plan", "track", "obstacle_map", "conflict_report", "status", "agreement"]
for t in types:
    assert v[t + "_bytes"] > 92, t
    for what in ("sign", "verify"):
        lo, mid, hi = (v[f"{t}_{what}_{s}_us"] for s in ("min", "median", "max"))
        assert 0 < lo <= mid <= hi, (t, what, lo, mid, hi)
for n in (3, 100):
    p = f"fleet_{n}_"
    assert v[p + "vehicles"] == n and v[p + "plans"] == n and v[p + "maps"] >= 1, n
    assert v[p + "tracks"] == n // 50, n
    for node in ("vehicle", "coordinator", "world"):
        q = p + node + "_"
        for k in ("sent", "received", "copies", "sign_us", "verify_us", "us_per_cycle",
                  "dt_percent", "traffic_bytes", "auth_bytes", "memory_bytes"):
            assert q + k in v, q + k
        assert v[q + "auth_bytes"] == 92 * (v[q + "sent"] + v[q + "received"]), q
        assert abs(v[q + "us_per_cycle"] - v[q + "sign_us"] - v[q + "verify_us"]) < 0.2, q
    # node.h's cycle, with C = 4 copies (COAVOID_NODE_DEFAULT_COPIES): a vehicle sends
    # its intent 1 + C times, a heartbeat, and ACCEPT and SWITCHED (1 + C times) on its
    # plan, and hears every intent, heartbeat (the coordinator's too), plan, agreement
    # (3 + C a plan: its UAV's ACCEPT and SWITCHED, the commit), map and track; the
    # coordinator sends its heartbeat, the report, a plan and a commit per UAV; the world
    # sends the maps and tracks.
    maps, tracks, sends = v[p + "maps"], v[p + "tracks"], 5
    assert v[p + "vehicle_sent"] == sends + 1 + (1 + sends), n
    assert v[p + "vehicle_received"] == sends * (n - 1) + (n + 1) + n + (2 + sends) * n + sends * (maps + tracks), n
    assert v[p + "coordinator_sent"] == 2 + 2 * n, n
    assert v[p + "coordinator_received"] == sends * n + (1 + sends) * n + sends * (maps + tracks), n
    assert v[p + "world_sent"] == sends * (maps + tracks) and v[p + "world_received"] == 0, n
    assert v[p + "world_memory_bytes"] == v["signer_bytes"], n
    assert v[p + "vehicle_memory_bytes"] == v["signer_bytes"] + v["trust_list_bytes"], n
# Refusals: all four timed (a failed refusal would show in verify_failures); never their
# times.
for x in ("copy", "unknown_key", "outsider", "signature"):
    lo, mid, hi = (v[f"refused_{x}_{s}_us"] for s in ("min", "median", "max"))
    assert 0 <= lo <= mid <= hi, (x, lo, mid, hi)
    # Copies: every send of an intent, map tile, track and SWITCHED after its first.
    peers = n - 1
    assert v[p + "vehicle_copies"] == (sends - 1) * (peers + maps + tracks + n), n
    assert v[p + "coordinator_copies"] == (sends - 1) * (n + maps + tracks + n), n
    assert v[p + "world_copies"] == 0, n
assert len(v) == 6 + 7 * len(types) + 4 * 3 + 2 * (4 + 3 * 10), len(v)
PY
fi

if expect_ok json bench auth --repeat 3 --vehicles 5 --json; then
    if python3 - "$tmp/out" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "json: $(tail -n 5 "$tmp/py")"; fi
import json, sys
b = json.load(open(sys.argv[1]))
assert b["benchmark"] == "auth" and b["repeat"] == 3 and b["verify_failures"] == 0, b
assert [t["type"] for t in b["types"]] == ["intent", "plan", "track", "obstacle_map",
                                          "conflict_report", "status", "agreement"], b["types"]
for t in b["types"]:
    assert t["bytes"] > 92 and 0 < t["sign_min_us"] <= t["sign_median_us"] <= t["sign_max_us"], t
    assert 0 < t["verify_min_us"] <= t["verify_median_us"] <= t["verify_max_us"], t
assert [x["refusal"] for x in b["refusals"]] == ["copy", "unknown_key", "outsider", "signature"], b["refusals"]
for x in b["refusals"]:
    assert 0 <= x["min_us"] <= x["median_us"] <= x["max_us"], x
assert len(b["fleets"]) == 1 and b["fleets"][0]["vehicles"] == 5, b["fleets"]
nodes = b["fleets"][0]["nodes"]
assert [n["node"] for n in nodes] == ["vehicle", "coordinator", "world"], nodes
# A vehicle: 4 intents x 5 sends, 6 heartbeats, 5 plans, 16 map tiles x 5, 5 x 7 agreements;
# the coordinator: heartbeat, report, 5 plans, 5 commits.
assert nodes[0]["received"] == 20 + 6 + 5 + 5 * 16 + 35 and nodes[1]["sent"] == 12, nodes
PY
fi

if "$bin" bench auth --help >"$tmp/help" 2>&1 && grep -q -- '--vehicles N' "$tmp/help"; then
    pass
else
    fail "bench auth --help: $(head -c 300 "$tmp/help")"
fi
if "$bin" bench --help >"$tmp/help" 2>&1 && grep -q "coavoid bench auth" "$tmp/help"; then
    pass
else
    fail "bench --help does not name auth: $(head -c 300 "$tmp/help")"
fi

expect_bad "repeat 0" "--repeat" bench auth --repeat 0
expect_bad "repeat missing" "--repeat" bench auth --repeat
expect_bad "vehicles 0" "--vehicles" bench auth --vehicles 0
expect_bad "vehicles 65536" "--vehicles" bench auth --vehicles 65536
expect_bad "vehicles empty entry" "--vehicles" bench auth --vehicles 3,
expect_bad "vehicles twice listed" "--vehicles" bench auth --vehicles 3,3
expect_bad "vehicles too many" "--vehicles" bench auth --vehicles 1,2,3,4,5,6,7,8,9
expect_bad "vehicles given twice" "--vehicles" bench auth --vehicles 3 --vehicles 4
expect_bad "json value" "--json" bench auth --json=yes
expect_bad "unknown option" "--bogus" bench auth --bogus

finish
