#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid predict` follows docs/scenario-format.md ("Prediction result") exactly on the shipped
# scenarios and on a few written here (ids out of input order, initial offsets, tracks with
# uncertainty); bad arguments exit 2 with one line naming the argument; and `coavoid bench
# predict` runs and prints its keys (never its times: a benchmark is not a timed test).
#
# usage: bash predict.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 shows each message)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
scenarios=$src/scenarios

# The contract, checked on every result: exactly the three fields with their types, every
# conflict entry well formed and naming things the scenario has, pairs without sigma at
# probability 1, conflicts in the documented order (kind, a, b), and clusters equal to the
# connected components of the UAV-UAV conflicts plus each UAV whose conflicts are only with
# obstacles or tracks, recomputed here independently: ids ascending, clusters by their
# smallest id.
cat >"$tmp/contract.py" <<'PY'
import json, sys

def contract(r, s, threshold):
    assert isinstance(r, dict), "result is not an object"
    assert list(r) == ["scenario", "conflicts", "clusters"], f"fields {list(r)}"
    assert r["scenario"] == s["name"], "scenario is not the name"
    num = lambda x: isinstance(x, (int, float)) and not isinstance(x, bool)
    integer = lambda x: isinstance(x, int) and not isinstance(x, bool)
    ids = {v["id"] for v in s["vehicles"]}
    tracks = {t["id"]: t for t in s.get("tracks", [])}
    obstacles = s.get("obstacles", [])
    kinds = ["vehicle", "track", "obstacle"]
    assert isinstance(r["conflicts"], list)
    keys = []
    for c in r["conflicts"]:
        assert isinstance(c, dict), c
        for f in ("kind", "a", "b", "first_step", "probability"):
            assert f in c, f"conflict without {f}: {c}"
        assert c["kind"] in kinds, c
        assert integer(c["a"]) and c["a"] in ids, c
        assert integer(c["b"]), c
        assert integer(c["first_step"]) and 0 <= c["first_step"] < s["horizon"], c
        assert num(c["probability"]) and 0 < c["probability"] <= 1, c
        for f in ("first_time", "min_horizontal", "min_vertical"):
            assert f not in c or num(c[f]), c
        if "first_time" in c:
            assert abs(c["first_time"] - c["first_step"] * s["dt"]) < 1e-9, c
        uncertain = False
        if c["kind"] == "vehicle":
            assert c["b"] in ids and c["a"] < c["b"], c
        elif c["kind"] == "track":
            assert c["b"] in tracks, c
            uncertain = any(x > 0 for x in tracks[c["b"]].get("sigma", [0, 0]))
        else:
            assert 0 <= c["b"] < len(obstacles), c
        if uncertain:
            assert c["probability"] >= threshold, c
        else:
            assert c["probability"] == 1, c
        keys.append((kinds.index(c["kind"]), c["a"], c["b"]))
    assert keys == sorted(keys) and len(set(keys)) == len(keys), f"order {keys}"

    parent = {}
    def find(x):
        while parent.setdefault(x, x) != x:
            x = parent[x]
        return x
    for c in r["conflicts"]:
        find(c["a"])
        if c["kind"] == "vehicle":
            parent[find(c["a"])] = find(c["b"])
    groups = {}
    for x in parent:
        groups.setdefault(find(x), []).append(x)
    want = sorted(sorted(g) for g in groups.values())
    assert isinstance(r["clusters"], list)
    for g in r["clusters"]:
        assert isinstance(g, list) and g and all(integer(i) for i in g), g
        assert g == sorted(g), f"cluster not ascending: {g}"
    assert [g[0] for g in r["clusters"]] == sorted(g[0] for g in r["clusters"]), "cluster order"
    assert r["clusters"] == want, f"clusters {r['clusters']}, components {want}"

r = json.load(open(sys.argv[1]))
s = json.load(open(sys.argv[2]))
threshold = float(sys.argv[3])
contract(r, s, threshold)
conflict = lambda kind, a, b: next((c for c in r["conflicts"]
                                    if (c["kind"], c["a"], c["b"]) == (kind, a, b)), None)
kinds = lambda kind: [c for c in r["conflicts"] if c["kind"] == kind]
for line in sys.argv[4].strip().splitlines():
    if not eval(line):
        sys.exit(f"assertion failed: {line}\n{json.dumps(r)[:800]}")
PY

# check NAME SCENARIO THRESHOLD ASSERTIONS [OPTIONS...]: `coavoid predict SCENARIO
# OPTIONS` exits 0 with nothing on stderr, its result meets the contract (for that
# threshold) and every line of ASSERTIONS (Python, with r the result, conflict(kind, a, b)
# the entry or None, kinds(kind) the entries of a kind).
check() {
    local name=$1 scenario=$2 threshold=$3 asserts=$4
    shift 4
    "$bin" predict "$scenario" "$@" >"$tmp/out.json" 2>"$tmp/err"
    local rc=$?
    if [ "$rc" -ne 0 ] || [ -s "$tmp/err" ]; then
        fail "$name: exit $rc, expected 0: $(head -c 300 "$tmp/err")"
    elif ! python3 "$tmp/contract.py" "$tmp/out.json" "$scenario" "$threshold" "$asserts" \
        >"$tmp/py" 2>&1; then
        fail "$name: $(tail -n 5 "$tmp/py")"
    else
        pass
    fi
}


# ---- the shipped scenarios ----

# Head-on at the same altitude: one certain conflict between 1 and 2, planned together.
check headon "$scenarios/headon.json" 0.01 '
len(r["conflicts"]) == 1
conflict("vehicle", 1, 2)["probability"] == 1
r["clusters"] == [[1, 2]]
'

# The track has sigma, so its conflict has a probability: near 1 (the nominal paths cross
# at 2 m vertical distance, well inside 13 m of combined half-heights) but not 1, since
# with sigma [5, 2] the vertical factor Phi((13 - 2)/2) - Phi((-13 - 2)/2) is 1 - 1.9e-8.
check track_crossing "$scenarios/track_crossing.json" 0.01 '
[(c["kind"], c["a"], c["b"]) for c in r["conflicts"]] == [("track", 1, 901)]
0.999 < conflict("track", 1, 901)["probability"] < 1
r["clusters"] == [[1]]
'
# So at threshold 1, which only a certain conflict reaches, it is not listed.
check track_crossing_threshold_1 "$scenarios/track_crossing.json" 1 '
r["conflicts"] == [] and r["clusters"] == []
' --threshold 1
check track_crossing_threshold_half "$scenarios/track_crossing.json" 0.5 '
conflict("track", 1, 901) is not None
' --threshold=0.5
# A track whose error grows by 100 m/s is far less certain than one that does not grow:
# listed, if at all, with a lower probability.
"$bin" predict "$scenarios/track_crossing.json" >"$tmp/fixed.json" 2>/dev/null
fixed=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["conflicts"][0]["probability"])' \
    "$tmp/fixed.json" 2>/dev/null || echo 1)
check track_crossing_growth "$scenarios/track_crossing.json" 0.01 "
all(c['probability'] < $fixed for c in kinds('track'))
" --sigma-growth 100,100

check polytope_hill "$scenarios/polytope_hill.json" 0.01 '
[(c["kind"], c["a"], c["b"]) for c in r["conflicts"]] == [("obstacle", 1, 0)]
r["clusters"] == [[1]]
'

check initial_conflict "$scenarios/initial_conflict.json" 0.01 '
conflict("vehicle", 1, 2)["first_step"] == 0
'

# The paper's encounter: red (1) meets the terrain alone; blue (2) and green (3) meet
# head-on 4 m apart vertically; red and blue are 16 m apart, red and green 12 m (against
# 10 m of combined half-heights): two groups to plan.
check paper "$scenarios/paper.json" 0.01 '
conflict("obstacle", 1, 0) is not None
conflict("vehicle", 2, 3) is not None
kinds("vehicle") == [conflict("vehicle", 2, 3)]
r["clusters"] == [[1], [2, 3]]
'

# Every shipped scenario meets the contract at the default threshold and at 1, and gives
# the same bytes twice.
for f in "$scenarios"/*.json; do
    name=$(basename "$f" .json)
    check "contract_$name" "$f" 0.01 'True'
    check "contract_${name}_threshold_1" "$f" 1 'True' --threshold 1
    "$bin" predict "$f" >"$tmp/once" 2>/dev/null
    "$bin" predict "$f" >"$tmp/twice" 2>/dev/null
    if cmp -s "$tmp/once" "$tmp/twice"; then pass; else fail "$name: two runs differ"; fi
done

# ---- ids out of input order, initial offsets ----

# The core works in input order (plan indices); the contract speaks ids: a < b by id, and
# clusters by their smallest id. 7 and 3 meet head-on, 9 and 2 too (elsewhere), 5 flies
# into a box alone.
cat >"$tmp/ids.json" <<'JSON'
{
  "name": "ids out of order",
  "dt": 1.0,
  "horizon": 24,
  "vehicles": [
    {"id": 7, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, 0, 100], [600, 0, 100]]},
    {"id": 9, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, 2000, 100], [600, 2000, 100]]},
    {"id": 5, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, 4000, 100], [600, 4000, 100]]},
    {"id": 3, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[300, 0, 100], [-300, 0, 100]]},
    {"id": 2, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[300, 2000, 100], [-300, 2000, 100]]}
  ],
  "obstacles": [
    {"type": "box", "min": [5000, 5000, 0], "max": [5100, 5100, 50]},
    {"type": "box", "min": [100, 3950, 0], "max": [150, 4050, 200]}
  ]
}
JSON
check ids_out_of_order "$tmp/ids.json" 0.01 '
[(c["kind"], c["a"], c["b"]) for c in r["conflicts"]] == [("vehicle", 2, 9), ("vehicle", 3, 7), ("obstacle", 5, 1)]
r["clusters"] == [[2, 9], [3, 7], [5]]
'

# Everything meets at one point at t = 10 s: four UAVs, a track (without sigma) and three
# towers, so every pair the command sizes for (UAV-UAV, UAV-track, UAV-obstacle) is a
# candidate and a conflict: the workspace and the conflict array are exactly full, which
# must not be an overflow.
cat >"$tmp/crowded.json" <<'JSON'
{
  "name": "everything at one point",
  "dt": 1.0,
  "horizon": 20,
  "vehicles": [
    {"id": 1, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[-100, 0, 100], [100, 0, 100]]},
    {"id": 2, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[100, 0, 100], [-100, 0, 100]]},
    {"id": 3, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, -100, 100], [0, 100, 100]]},
    {"id": 4, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, 100, 100], [0, -100, 100]]}
  ],
  "obstacles": [
    {"type": "box", "min": [-5, -5, 0], "max": [5, 5, 200]},
    {"type": "box", "min": [-3, -3, 0], "max": [3, 3, 150]},
    {"type": "polytope", "vertices": [[-1, -1, 90], [1, -1, 90], [0, 1, 90], [0, 0, 110]]}
  ],
  "tracks": [
    {"id": 50, "radius": 10, "half_height": 5, "position": [-70, -70, 100], "velocity": [7, 7, 0]}
  ]
}
JSON
check crowded "$tmp/crowded.json" 0.01 '
len(kinds("vehicle")) == 6 and len(kinds("track")) == 4 and len(kinds("obstacle")) == 12
r["clusters"] == [[1, 2, 3, 4]]
'

# initial_offset lifts a UAV's plan by offset * climb_rate * dt: 2 steps of 2 m leave the
# head-on pair 4 m apart (conflict), 3 steps 6 m... and 10 steps 20 m (none: 10 m needed).
offset_scenario() {
    cat >"$tmp/offset_$1.json" <<JSON
{
  "name": "head-on, one UAV lifted by $1 climb steps",
  "dt": 1.0,
  "horizon": 24,
  "vehicles": [
    {"id": 1, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[0, 0, 100], [600, 0, 100]]},
    {"id": 2, "priority": 2, "cruise_speed": 10, "climb_rate": 2, "radius": 15,
     "half_height": 5, "route": [[300, 0, 100], [-300, 0, 100]], "initial_offset": $1}
  ]
}
JSON
}
offset_scenario 2
offset_scenario 10
offset_scenario -10
check initial_offset_2 "$tmp/offset_2.json" 0.01 '
conflict("vehicle", 1, 2) is not None
'
check initial_offset_10 "$tmp/offset_10.json" 0.01 '
r["conflicts"] == [] and r["clusters"] == []
'
check initial_offset_minus_10 "$tmp/offset_-10.json" 0.01 '
r["conflicts"] == []
'

# --help prints the usage with the default threshold and exits 0.
if "$bin" predict --help >"$tmp/help" 2>&1 && grep -q -- '--threshold P' "$tmp/help" &&
    grep -q 'default 0.01' "$tmp/help" && grep -q -- '--sigma-growth' "$tmp/help"; then
    pass
else
    fail "predict --help: $(head -c 300 "$tmp/help")"
fi
if "$bin" --help | grep -q '^  predict'; then pass; else fail "coavoid --help does not list predict"; fi

# ---- bad arguments ----
headon=$scenarios/headon.json
expect_bad "no scenario" "SCENARIO.json" predict
expect_bad "missing file" "$tmp/nonexistent.json" predict "$tmp/nonexistent.json"
expect_bad "two scenarios" "'$headon'" predict "$headon" "$headon"
expect_bad "threshold 0" "--threshold" predict "$headon" --threshold 0
expect_bad "threshold 1.5" "--threshold" predict "$headon" --threshold 1.5
expect_bad "threshold negative" "--threshold" predict "$headon" --threshold -0.5
expect_bad "threshold abc" "--threshold" predict "$headon" --threshold abc
expect_bad "threshold nan" "--threshold" predict "$headon" --threshold nan
expect_bad "threshold inf" "--threshold" predict "$headon" --threshold inf
expect_bad "threshold trailing" "--threshold" predict "$headon" --threshold 0.5x
expect_bad "threshold empty" "--threshold" predict "$headon" --threshold=
expect_bad "threshold missing" "--threshold" predict "$headon" --threshold
expect_bad "threshold twice" "--threshold" predict "$headon" --threshold 0.5 --threshold 0.5
expect_bad "sigma-growth one number" "--sigma-growth" predict "$headon" --sigma-growth 1
expect_bad "sigma-growth negative" "--sigma-growth" predict "$headon" --sigma-growth=-1,0
expect_bad "sigma-growth words" "--sigma-growth" predict "$headon" --sigma-growth a,b
expect_bad "sigma-growth three" "--sigma-growth" predict "$headon" --sigma-growth 1,2,3
expect_bad "sigma-growth missing" "--sigma-growth" predict "$headon" --sigma-growth
expect_bad "unknown option" "--bogus" predict "$headon" --bogus
expect_bad "plan's option" "--mode" predict "$headon" --mode centralised

# A bad scenario gets the loader's message, the same as `coavoid plan` gives.
python3 - "$headon" "$tmp/bad_radius.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["vehicles"][1]["radius"] = -1
json.dump(s, open(sys.argv[2], "w"))
PY
expect_bad "bad scenario" "$tmp/bad_radius.json: vehicles[1].radius: " predict "$tmp/bad_radius.json"
"$bin" plan "$tmp/bad_radius.json" --mode centralised 2>"$tmp/plan_err" >/dev/null
"$bin" predict "$tmp/bad_radius.json" 2>"$tmp/predict_err" >/dev/null
if cmp -s "$tmp/plan_err" "$tmp/predict_err"; then pass; else
    fail "plan and predict word a bad scenario differently: $(cat "$tmp/plan_err" "$tmp/predict_err")"
fi
printf '{"name": "x", "dt": 1, "horizon": ' >"$tmp/truncated.json"
expect_bad "truncated JSON" "$tmp/truncated.json" predict "$tmp/truncated.json"

# ---- bench predict ----
bench_keys='benchmark broad_phase vehicles tracks horizon dt_s seed repeat side_m median_ms min_ms max_ms pair_tests candidate_pairs all_pairs conflicts workspace_bytes'

# bench NAME ASSERTIONS ARGS...: `coavoid bench predict ARGS` exits 0 with nothing on
# stderr and prints every key once; ASSERTIONS see the values as b (numbers where they
# are numbers), from 'key: value' lines or, with --json, the object.
bench() {
    local name=$1 asserts=$2
    shift 2
    "$bin" bench predict "$@" >"$tmp/bench" 2>"$tmp/err"
    local rc=$?
    if [ "$rc" -ne 0 ] || [ -s "$tmp/err" ]; then
        fail "$name: exit $rc, expected 0: $(head -c 300 "$tmp/err")"
        return
    fi
    if python3 - "$tmp/bench" "$bench_keys" "$asserts" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "$name: $(tail -n 5 "$tmp/py")"; fi
import json, sys
text = open(sys.argv[1]).read()
if text.lstrip().startswith("{"):
    b = json.loads(text)
else:
    b = {}
    for line in text.splitlines():
        key, sep, value = line.partition(": ")
        assert sep and key not in b, f"bad line {line!r}"
        try:
            b[key] = int(value)
        except ValueError:
            try:
                b[key] = float(value)
            except ValueError:
                b[key] = value
for key in sys.argv[2].split():
    assert key in b, f"no {key} in {sorted(b)}"
for key in sys.argv[2].split()[2:]:
    assert isinstance(b[key], (int, float)) and b[key] >= 0, f"{key}: {b[key]!r}"
assert b["min_ms"] <= b["median_ms"] <= b["max_ms"], "min <= median <= max"
for line in sys.argv[3].strip().splitlines():
    assert eval(line), f"assertion failed: {line}: {b}"
with open(sys.argv[1] + ".last", "w") as f:
    json.dump(b, f)
PY
}

bench bench_small '
b["vehicles"] == 50 and b["horizon"] == 10 and b["repeat"] == 3 and b["seed"] == 1
b["all_pairs"] == 50 * 49 // 2
b["tracks"] == 1
b["benchmark"] == "predict" and b["broad_phase"] == "on"
b["workspace_bytes"] > 0
' --vehicles 50 --horizon 10 --repeat 3
cp "$tmp/bench.last" "$tmp/bench_a"
# The same seed builds the same airspace: the same work and the same conflicts.
bench bench_same_seed '
True
' --vehicles 50 --horizon 10 --repeat 3
if python3 - "$tmp/bench_a" "$tmp/bench.last" <<'PY'; then pass; else fail "bench: the same seed gave different work"; fi
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
keys = ("pair_tests", "candidate_pairs", "conflicts", "workspace_bytes")
sys.exit(0 if all(a[k] == b[k] for k in keys) else f"{a} vs {b}")
PY
bench bench_json '
b["vehicles"] == 120 and b["horizon"] == 20 and b["seed"] == 7 and b["repeat"] == 1
' --json --vehicles=120 --horizon=20 --seed=7 --repeat=1
cp "$tmp/bench.last" "$tmp/bench_broad"
# The broad phase finds exactly what testing every pair finds.
bench bench_all_pairs '
b["broad_phase"] == "off"
' --vehicles 120 --horizon 20 --seed 7 --repeat 1 --all-pairs
if python3 - "$tmp/bench_broad" "$tmp/bench.last" <<'PY'; then pass; else fail "bench: the broad phase and all pairs found different conflicts"; fi
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
sys.exit(0 if a["conflicts"] == b["conflicts"] and a["pair_tests"] <= b["pair_tests"] else f"{a} vs {b}")
PY
bench bench_fixed_square '
b["side_m"] == 2000
' --vehicles 60 --horizon 5 --repeat 1 --side-km 2 --seed 0

if "$bin" bench predict --help >"$tmp/help" 2>&1 && grep -q -- '--vehicles N' "$tmp/help"; then
    pass
else
    fail "bench predict --help: $(head -c 300 "$tmp/help")"
fi

expect_bad "bench alone" "bench" bench
expect_bad "bench unknown" "'nothing'" bench nothing
expect_bad "bench no vehicles" "--vehicles" bench predict --horizon 10
expect_bad "bench no horizon" "--horizon" bench predict --vehicles 10
expect_bad "bench vehicles 0" "--vehicles" bench predict --vehicles 0 --horizon 10
expect_bad "bench vehicles abc" "--vehicles" bench predict --vehicles abc --horizon 10
expect_bad "bench vehicles too many" "--vehicles" bench predict --vehicles 65536 --horizon 10
expect_bad "bench vehicles huge" "--vehicles" bench predict --vehicles 99999999999999999999999 --horizon 10
expect_bad "bench horizon 0" "--horizon" bench predict --vehicles 10 --horizon 0
expect_bad "bench horizon too long" "--horizon" bench predict --vehicles 10 --horizon 10001
expect_bad "bench horizon missing" "--horizon" bench predict --vehicles 10 --horizon
expect_bad "bench repeat 0" "--repeat" bench predict --vehicles 10 --horizon 10 --repeat 0
expect_bad "bench seed negative" "--seed" bench predict --vehicles 10 --horizon 10 --seed -1
expect_bad "bench seed 2^64" "--seed" bench predict --vehicles 10 --horizon 10 --seed 18446744073709551616
expect_bad "bench side 0" "--side-km" bench predict --vehicles 10 --horizon 10 --side-km 0
expect_bad "bench json value" "--json" bench predict --vehicles 10 --horizon 10 --json=yes
expect_bad "bench twice" "--vehicles" bench predict --vehicles 10 --vehicles 10 --horizon 10
expect_bad "bench unknown option" "--bogus" bench predict --vehicles 10 --horizon 10 --bogus
expect_bad "bench too large" "--vehicles" bench predict --vehicles 65535 --horizon 10000

finish
