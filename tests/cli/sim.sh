#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid sim` follows docs/scenario-format.md ("Simulation result"): every shipped scenario
# that `coavoid plan` solves in a mode flies without a loss of separation in that mode,
# K = 2N steps by default, K + 1 samples per UAV at t = k dt, each on its reference raised
# by a whole number of climb steps that change by actions; planning runs where there is a
# conflict; the flown costs are at least the one-shot plan's; a run is repeatable byte for
# byte; the UAVs fall back to planning for themselves when the coordinator stops, and stay
# separated; the coordinator cut after M messages of a cycle (STEP:M); a scenario already in conflict reports its loss (exit 1) instead of crashing;
# UAVs decide in priority order whatever their ids; the simulated network (--loss, --delay,
# --jitter, --net-seed) and montecarlo's closed loop (--fly) over it; bad arguments and inputs, and numbers
# beyond what a message carries anywhere in the run, exit 2 with one line.
#
# usage: bash sim.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 prints each result)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
scenarios=$src/scenarios
if ! "$bin" sim --help >/dev/null 2>&1; then
    echo "FAIL: coavoid has no sim command (CMake adds this test only with LCM)" >&2
    exit 1
fi

# The contract, and the flight's geometry recomputed here from the scenario: x, y on the
# reference at t = k dt and z the reference's raised by (offset * climb_rate * dt) with a
# whole offset whose steps are actions (0, +-1, +-steep_factor). Then every line of the
# extra assertions (Python; r is the result, s the scenario, offsets[id] the flown
# offsets).
cat >"$tmp/check.py" <<'PY'
import json, math, sys

r = json.load(open(sys.argv[1]))
s = json.load(open(sys.argv[2]))
mode = sys.argv[3]
num = lambda x: isinstance(x, (int, float)) and not isinstance(x, bool)
integer = lambda x: isinstance(x, int) and not isinstance(x, bool)

for f in ("scenario", "mode", "steps", "replans", "loss_of_separation", "deviation",
          "effort", "vehicles"):
    assert f in r, f"no {f}"
assert r["scenario"] == s["name"], "scenario is not the name"
assert r["mode"] == mode, r["mode"]
assert integer(r["steps"]) and r["steps"] >= 1
assert integer(r["replans"]) and r["replans"] >= 0
assert isinstance(r["loss_of_separation"], bool)
assert num(r["deviation"]) and r["deviation"] >= 0
assert integer(r["effort"]) and r["effort"] >= 0
K = r["steps"]
dt = s["dt"]

def reference(v, t):
    """The contract's reference: along the route at cruise_speed, z linear per leg, the
    last leg extended."""
    pts = v["route"]
    d = v["cruise_speed"] * t
    start = 0.0
    for i in range(len(pts) - 1):
        a, b = pts[i], pts[i + 1]
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if d < start + length or i == len(pts) - 2:
            u = (d - start) / length
            return [a[j] + u * (b[j] - a[j]) for j in range(3)]
        start += length

offsets = {}
assert [v["id"] for v in r["vehicles"]] == [v["id"] for v in s["vehicles"]], "vehicle order"
for v, sv in zip(r["vehicles"], s["vehicles"]):
    flown = v["flown"]
    assert isinstance(flown, list) and len(flown) == K + 1, f"{len(flown)} samples, K = {K}"
    dh = sv["climb_rate"] * dt
    steep = sv.get("steep_factor", 2)
    row = []
    for k, p in enumerate(flown):
        assert len(p) == 4 and all(num(x) for x in p), p
        assert abs(p[0] - k * dt) < 1e-9, f"sample {k} at t = {p[0]}"
        ref = reference(sv, k * dt)
        # Rounding of the core's precision (float in a COAVOID_SINGLE_PRECISION build), far
        # below a climb step.
        tol = 1e-5 * max(1.0, abs(ref[0]), abs(ref[1]), abs(ref[2]))
        assert abs(p[1] - ref[0]) <= tol and abs(p[2] - ref[1]) <= tol, \
            f"UAV {v['id']} off its reference horizontally at k = {k}: {p} vs {ref}"
        o = (p[3] - ref[2]) / dh
        assert abs(o - round(o)) * dh <= tol, f"UAV {v['id']} z at k = {k} is {o} climb steps off"
        row.append(round(o))
    assert row[0] == sv.get("initial_offset", 0), f"UAV {v['id']} starts at {row[0]}"
    for a, b in zip(row, row[1:]):
        assert b - a in (0, 1, -1, steep, -steep), f"UAV {v['id']}: {a} -> {b} is no action"
    offsets[v["id"]] = row

for line in sys.argv[4].strip().splitlines():
    if not eval(line):
        sys.exit(f"assertion failed: {line}\n{json.dumps(r)[:600]}")
PY

# sim_json NAME SCENARIO MODE EXPECTED_EXIT ASSERTIONS [OPTIONS...]: `coavoid sim SCENARIO
# --mode MODE --json OPTIONS` exits EXPECTED_EXIT with nothing on stderr, and its result
# meets the contract, the geometry and ASSERTIONS. The result stays in $tmp/NAME.json.
sim_json() {
    local name=$1 scenario=$2 mode=$3 want=$4 asserts=$5
    shift 5
    "$bin" sim "$scenario" --mode "$mode" --json "$@" >"$tmp/$name.json" 2>"$tmp/err"
    local rc=$?
    if [ -n "${VERBOSE:-}" ]; then
        python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); r.pop("vehicles"); print(sys.argv[2], r)' \
            "$tmp/$name.json" "$name" 2>/dev/null
    fi
    if [ "$rc" -ne "$want" ] || [ -s "$tmp/err" ]; then
        fail "$name: exit $rc, expected $want: $(head -c 300 "$tmp/err")"
    elif ! python3 "$tmp/check.py" "$tmp/$name.json" "$scenario" "$mode" "$asserts" \
        >"$tmp/py" 2>&1; then
        fail "$name: $(tail -n 5 "$tmp/py")"
    else
        pass
    fi
}

# A field of a JSON file (python expression on r).
field() { python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$@"; }

# ---- every shipped scenario, in each mode its one-shot plan solves ----

for scenario in "$scenarios"/*.json; do
    base=$(basename "$scenario" .json)
    horizon=$(field "$scenario" 'r["horizon"]')
    "$bin" predict "$scenario" >"$tmp/predict.json" 2>/dev/null
    conflicts=$(field "$tmp/predict.json" 'len(r["conflicts"])')
    for mode in centralised decoupled; do
        "$bin" plan "$scenario" --mode "$mode" >"$tmp/plan-$base-$mode.json" 2>/dev/null
        plan_rc=$?
        if [ "$plan_rc" -eq 0 ]; then
            # Planning must have run where the references conflict.
            sim_json "$base-$mode" "$scenario" "$mode" 0 "
r['loss_of_separation'] is False
r['steps'] == 2 * $horizon
$conflicts == 0 or r['replans'] >= 1
r['fallbacks'] == 0
"
        elif [ "$plan_rc" -eq 1 ]; then
            # No plan from the start (a conflict at t = 0): the loss is reported, exit 1.
            sim_json "$base-$mode" "$scenario" "$mode" 1 "
r['loss_of_separation'] is True
r['first_loss']['step'] == 0
"
        else
            fail "$base: coavoid plan --mode $mode exits $plan_rc"
        fi
    done
done

# The shipped scenarios include both kinds, so neither branch above is vacuous.
[ -s "$tmp/paper-centralised.json" ] && [ -s "$tmp/initial_conflict-decoupled.json" ] \
    && pass || fail "the shipped scenarios changed: paper or initial_conflict is missing"

# ---- what was flown against the one-shot plan ----

# Closed loop against one-shot: the loop's first plan is the one-shot problem (everyone at
# k = 0 over the same horizon), and the UAVs fly it; planning again later can only add
# deviation (a plan holds its last offset past its end, and later plans start from where
# the UAVs are). So the flown costs are at least the one-shot plan's, lexicographically.
for mode in centralised decoupled; do
    for base in paper headon; do
        plan=$tmp/plan-$base-$mode.json
        flown=$tmp/$base-$mode.json
        dev=$(field "$plan" 'r["cost"]["deviation"]')
        eff=$(field "$plan" 'r["cost"]["effort"]')
        if python3 - "$flown" "$dev" "$eff" <<'PY'; then pass; else fail "$base $mode: flown costs below the one-shot plan's ($dev, $eff)"; fi
import json, sys
r = json.load(open(sys.argv[1]))
dev, eff = float(sys.argv[2]), int(sys.argv[3])
sys.exit(0 if (r["deviation"], r["effort"]) >= (dev, eff) else 1)
PY
    done
done

# Head-on, and the paper's three UAVs: nothing new enters the horizon after the first
# plan, so the UAVs fly exactly the one-shot plan over its N steps (in the paper's case
# centrally only because the coordinator plans all clustered UAVs together once UAV 1,
# alone over the terrain, finds the others in its way).
for mode in centralised decoupled; do
    for base in paper headon; do
        if python3 - "$tmp/$base-$mode.json" "$tmp/plan-$base-$mode.json" \
            "$scenarios/$base.json" <<'PY'; then pass; else fail "$base $mode: the flown offsets are not the one-shot plan's"; fi
import json, sys
r, p, s = (json.load(open(f)) for f in sys.argv[1:4])
n = s["horizon"]
for v, pv, sv in zip(r["vehicles"], p["vehicles"], s["vehicles"]):
    z0 = sv["route"][0][2]
    dh = sv["climb_rate"] * s["dt"]
    flown = [round((q[3] - z0) / dh) for q in v["flown"][: n + 1]]
    if flown != pv["offsets"] or r["deviation"] != p["cost"]["deviation"]:
        sys.exit(f"UAV {v['id']}: {flown} vs {pv['offsets']}")
PY
    done
done

# ---- determinism ----

for args in "paper.json --mode centralised" "late_encounter.json --mode decoupled" \
    "track_crossing.json --mode centralised --json" "late_encounter.json --mode centralised --coordinator-stops 13 --json"; do
    read -r -a a <<<"$args"
    "$bin" sim "$scenarios/${a[0]}" "${a[@]:1}" >"$tmp/run1" 2>&1
    "$bin" sim "$scenarios/${a[0]}" "${a[@]:1}" >"$tmp/run2" 2>&1
    if [ -s "$tmp/run1" ] && cmp -s "$tmp/run1" "$tmp/run2"; then pass; else fail "two runs of sim $args differ"; fi
done

# ---- the simulated network (--loss, --delay, --jitter, --net-seed) ----

# Zero loss, delay and jitter given: the same flight as without them, plus the network's
# object; given a loss, a seed gives one run, another seed other deliveries; a delay
# leaves copies in flight at the end; every copy is delivered, dropped or in flight.
p=$scenarios/paper.json
"$bin" sim "$p" --mode centralised --json --insecure >"$tmp/net-none.json" 2>&1
"$bin" sim "$p" --mode centralised --json --insecure --loss 0 --delay 0 --jitter 0 >"$tmp/net-zero.json" 2>&1
if python3 - "$tmp/net-none.json" "$tmp/net-zero.json" <<'PY'; then pass; else fail "sim with a zero network is not the run without one"; fi
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert "network" not in a
n = b.pop("network")
assert a == b, "flights differ"
assert n["loss"] == 0 and n["delay"] == 0 and n["jitter"] == 0 and n["seed"] == 1, n
assert n["dropped"] == 0 and n["in_flight"] == 0 and n["delivered"] > n["sent"] > 0, n
PY
for m in centralised decoupled; do
    for run in a:5 b:5 c:6; do
        "$bin" sim "$p" --mode $m --json --insecure --loss 0.3 --jitter 0.2 --net-seed "${run#*:}" >"$tmp/net-$m-${run%:*}" 2>&1
    done
done
if python3 - "$tmp"/net-centralised-[abc] "$tmp"/net-decoupled-[abc] <<'PY'; then pass; else fail "sim --loss: one seed is not one run, or another seed the same"; fi
import json, sys
for a, b, c in (sys.argv[1:4], sys.argv[4:7]):
    A, B, C = (open(f).read() for f in (a, b, c))
    assert A == B, f"{a} and {b} differ"
    na, nc = json.loads(A)["network"], json.loads(C)["network"]
    assert na["seed"] == 5 and nc["seed"] == 6
    assert na != nc, "seeds 5 and 6 dropped the same copies"
    for n in (na, nc):
        assert 0.2 < n["dropped"] / (n["dropped"] + n["delivered"] + n["in_flight"]) < 0.4, n
PY
"$bin" sim "$p" --mode decoupled --insecure --delay 0.3 >"$tmp/net-delay.txt" 2>&1
if grep -q '^network: loss 0, delay 0.3 s, jitter 0 s, seed 1: [0-9]* messages sent, copies to other nodes [0-9]* delivered, 0 dropped, [1-9][0-9]* in flight$' "$tmp/net-delay.txt"; then pass; else fail "sim --delay: no network line with copies in flight"; fi
expect_bad "loss 1" "--loss" sim "$p" --mode decoupled --loss 1
expect_bad "loss negative" "--loss" sim "$p" --mode decoupled --loss=-0.1
expect_bad "loss word" "--loss" sim "$p" --mode decoupled --loss some
expect_bad "loss twice" "--loss" sim "$p" --mode decoupled --loss 0.1 --loss 0.2
expect_bad "delay negative" "--delay" sim "$p" --mode decoupled --delay=-1
expect_bad "delay nan" "--delay" sim "$p" --mode decoupled --delay nan
expect_bad "jitter missing" "--jitter" sim "$p" --mode decoupled --jitter
expect_bad "delay a cycle" "--delay" sim "$p" --mode decoupled --delay 0.5 --jitter 0.5
expect_bad "seed word" "--net-seed" sim "$p" --mode decoupled --loss 0.1 --net-seed x
# --seed N, the old spelling of --net-seed N, flies the same with one warning naming it.
"$bin" sim "$p" --mode decoupled --insecure --loss 0.3 --net-seed 4 >"$tmp/seed-new" 2>"$tmp/seed-new.err"
"$bin" sim "$p" --mode decoupled --insecure --loss 0.3 --seed 4 >"$tmp/seed-old" 2>"$tmp/seed-old.err"
if cmp -s "$tmp/seed-new" "$tmp/seed-old" && [ ! -s "$tmp/seed-new.err" ] &&
    [ "$(wc -l <"$tmp/seed-old.err")" -eq 1 ] && grep -q 'warning: --seed .*deprecated.*--net-seed' "$tmp/seed-old.err"; then
    pass
else
    fail "sim --seed (old spelling): not the --net-seed flight with one warning: $(head -c 300 "$tmp/seed-old.err")"
fi

# ---- montecarlo --fly: the closed loop of the random encounters ----

# Each encounter flown as `coavoid sim` flies it (the saved encounter, flown by sim, has
# the verdict of its flown_* CSV row); deterministic whatever --jobs; the network's options
# only with --fly, and under dt.
mkdir -p "$tmp/mc"
"$bin" montecarlo --vehicles 2,3 --count 4 --fly --loss 0.2 --quiet --jobs 1 --csv "$tmp/fly1.csv" --save "$tmp/mc" --json >"$tmp/fly1.json" 2>&1
"$bin" montecarlo --vehicles 2,3 --count 4 --fly --loss 0.2 --quiet --jobs 2 --csv "$tmp/fly2.csv" --json >"$tmp/fly2.json" 2>&1
"$bin" montecarlo --vehicles 3 --count 4 --fly --quiet --csv "$tmp/fly0.csv" --save "$tmp/mc" >/dev/null 2>&1
if python3 - "$tmp/fly1.json" "$tmp/fly2.json" "$tmp/fly1.csv" "$tmp/fly2.csv" <<'PY'; then pass; else fail "montecarlo --fly: report or CSV wrong, or depends on --jobs"; fi
import csv, json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert a["network"] == {"loss": 0.2, "delay": 0, "jitter": 0, "insecure": True}, a["network"]
for z, y in zip(a["sizes"], b["sizes"]):
    assert z["closed_loop"] == y["closed_loop"], "depends on --jobs"
    assert [m["mode"] for m in z["closed_loop"]] == ["centralised", "decoupled"]
    for m in z["closed_loop"]:
        assert 0 <= m["losses_where_centralised_solved"] <= m["centralised_solved"] <= 4
        assert m["dropped"] > 0 and m["delivered"] > 0, m
rows = [[r[:15] for r in csv.reader(open(f))] for f in sys.argv[3:5]]
assert rows[0] == rows[1], "CSV depends on --jobs"
flown = [r for r in rows[0] if r[7].startswith("flown_")]
assert len(flown) == 16 and {r[8] for r in flown} <= {"separated", "loss_of_separation"}
PY
# At loss 0 each flown row is what coavoid sim says of the saved encounter.
ok=1 seen=0
while IFS=, read -r seed n index _ _ _ _ method status _; do
    case $method in flown_*) ;; *) continue ;; esac
    seen=$((seen + 1))
    "$bin" sim "$tmp/mc/montecarlo-$seed-$n-$index.json" --mode "${method#flown_}" --insecure >/dev/null 2>&1
    rc=$?
    want=0; [ "$status" = loss_of_separation ] && want=1
    [ "$rc" = "$want" ] || { ok=0; echo "montecarlo-$seed-$n-$index ${method#flown_}: sim exits $rc, CSV says $status"; }
done < <(tail -n +2 "$tmp/fly0.csv")
if [ $ok = 1 ] && [ $seen = 8 ]; then pass; else fail "montecarlo --fly: a flown verdict differs from coavoid sim's ($seen rows)"; fi
# The coordinator-stop sweep (--coordinator-stops-sweep), at loss 0.2 with its own network
# seed: every stopped run's verdict is what coavoid sim says of the saved encounter
# stopped there, with the row's network seed (so the sweep's replay of the coordinator is
# the real stopped run), and so are the unstopped rows'; the summary is the CSV's counts.
"$bin" montecarlo --vehicles 2,3 --count 2 --fly --loss 0.2 --net-seed 7 --coordinator-stops-sweep all \
    --quiet --csv "$tmp/sweep.csv" --save "$tmp/mc" --json >"$tmp/sweep.json" 2>&1
ok=1 seen=0
while IFS=, read -r seed n index _ _ _ _ method status _ _ _ _ _ _ _ loss _ _ net s m _; do
    case $method in flown_*) ;; *) continue ;; esac
    seen=$((seen + 1))
    mode=${method#flown_} stop=()
    [ "$mode" = centralised_stop ] && mode=centralised stop=(--coordinator-stops "$s:$m")
    "$bin" sim "$tmp/mc/montecarlo-$seed-$n-$index.json" --mode "$mode" --insecure --loss "$loss" \
        --net-seed "$net" "${stop[@]}" >/dev/null 2>&1
    rc=$?
    want=0; [ "$status" = loss_of_separation ] && want=1
    [ "$rc" = "$want" ] || { ok=0; echo "montecarlo-$seed-$n-$index $method ${stop[*]}: sim exits $rc, CSV says $status"; }
done < <(tail -n +2 "$tmp/sweep.csv")
if [ $ok = 1 ] && [ $seen -gt 100 ]; then pass; else fail "montecarlo sweep: a stopped run's verdict differs from coavoid sim's ($seen rows)"; fi
if python3 - "$tmp/sweep.json" "$tmp/sweep.csv" <<'PY'; then pass; else fail "montecarlo sweep: the summary is not the CSV's"; fi
import csv, json, sys
j = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
assert j["network"]["net_seed"] == 7 and j["network"]["coordinator_stops"] == "all", j["network"]
for z in j["sizes"]:
    n = str(z["vehicles"])
    kept = {r["index"] for r in rows if r["vehicles"] == n and r["method"] == "flown_decoupled"
            and r["status"] == "separated"}
    stops = [r for r in rows if r["vehicles"] == n and r["method"] == "flown_centralised_stop"]
    lost = [r for r in stops if r["status"] == "loss_of_separation"]
    want = {"runs": len(stops), "losses": len(lost),
            "encounters_with_losses": len({r["index"] for r in lost}),
            "decoupled_separated": len(kept),
            "losses_where_decoupled_separated": len([r for r in lost if r["index"] in kept]),
            "encounters_with_losses_where_decoupled_separated":
                len({r["index"] for r in lost if r["index"] in kept})}
    assert z["coordinator_stops"] == want, (z["coordinator_stops"], want)
    # Every cycle is swept, at m = 0 at least, and the cut points of a cycle are 0, 1, ...
    widest = 0
    for i in {r["index"] for r in stops}:
        cuts = {}
        for r in stops:
            if r["index"] == i:
                cuts.setdefault(int(r["stop_step"]), []).append(int(r["stop_messages"]))
        assert sorted(cuts) == list(range(25)), sorted(cuts)
        assert all(v == list(range(len(v))) for v in cuts.values()), cuts
        widest = max([widest] + [len(v) for v in cuts.values()])
    assert widest >= 3, "no cycle with a plan: the cuts between plan rows are not swept"
PY
# montecarlo --merge of the sweep (the run above, split here into its two encounters
# as --first 0 --count 1 and --first 1 --count 1 would write them: the same rows): the
# run's own JSON summary to the digit, whatever the parts' order; a part whose stop rows
# are out of order, or end before the last cycle, is refused.
python3 - "$tmp" <<'PY'
import csv, sys
d = sys.argv[1]
rows = list(csv.reader(open(f"{d}/sweep.csv")))
first, count = rows[0].index("first"), rows[0].index("count")
def write(name, keep):
    with open(f"{d}/{name}.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(rows[0])
        for r in keep:
            w.writerow(r)
for i in ("0", "1"):
    part = [r[:first] + [i, "1"] + r[count + 1:] for r in rows[1:] if r[2] == i]
    write(f"sweep-{i}", part)
    if i == "1":
        write("sweep-cut", part[:-1])  # the last cycle's stop row
        stops = [k for k, r in enumerate(part) if r[7] == "flown_centralised_stop"]
        part[stops[1]], part[stops[2]] = part[stops[2]], part[stops[1]]
        write("sweep-swapped", part)
PY
if "$bin" montecarlo --merge "$tmp/sweep-1.csv,$tmp/sweep-0.csv" --json >"$tmp/merged.json" 2>"$tmp/err" &&
    cmp -s "$tmp/sweep.json" "$tmp/merged.json"; then
    pass
else
    fail "montecarlo --merge of the sweep's parts: not the run's summary: $(head -c 300 "$tmp/err"; diff "$tmp/sweep.json" "$tmp/merged.json" | head -c 400)"
fi
expect_bad "mc merge sweep cut" "sweep-cut.csv: encounter 1 of 3 UAVs: stop rows of some cycles only" montecarlo --merge "$tmp/sweep-0.csv,$tmp/sweep-cut.csv"
expect_bad "mc merge sweep order" "stop 0:2 out of order" montecarlo --merge "$tmp/sweep-0.csv,$tmp/sweep-swapped.csv"
# --net-seed given as --seed is the default; another one draws another network.
"$bin" montecarlo --vehicles 2 --count 3 --fly --loss 0.3 --quiet --csv "$tmp/ns-default.csv" >/dev/null 2>&1
"$bin" montecarlo --vehicles 2 --count 3 --fly --loss 0.3 --net-seed 1 --quiet --csv "$tmp/ns-1.csv" >/dev/null 2>&1
"$bin" montecarlo --vehicles 2 --count 3 --fly --loss 0.3 --net-seed 2 --quiet --csv "$tmp/ns-2.csv" >/dev/null 2>&1
if python3 - "$tmp/ns-default.csv" "$tmp/ns-1.csv" "$tmp/ns-2.csv" <<'PY'; then pass; else fail "montecarlo --net-seed: default or effect wrong"; fi
import csv, sys
# time_us and net_seed_option (the option as given) left out
a, b, c = ([r[:15] + r[16:34] for r in csv.reader(open(f))] for f in sys.argv[1:4])
assert a == b
seeds = lambda rows: {r[18] for r in rows[1:]}  # net_seed, time_us left out
assert seeds(a).isdisjoint(seeds(c))
assert [r[:7] for r in a] == [r[:7] for r in c], "--net-seed changed the encounters"
PY
expect_bad "mc net seed without fly" "--net-seed" montecarlo --vehicles 2 --count 1 --net-seed 3
expect_bad "mc net seed word" "--net-seed" montecarlo --vehicles 2 --count 1 --fly --net-seed x
expect_bad "mc sweep without fly" "--coordinator-stops-sweep" montecarlo --vehicles 2 --count 1 --coordinator-stops-sweep all
expect_bad "mc sweep kind" "--coordinator-stops-sweep" montecarlo --vehicles 2 --count 1 --fly --coordinator-stops-sweep some
expect_bad "mc sweep missing" "--coordinator-stops-sweep" montecarlo --vehicles 2 --count 1 --fly --coordinator-stops-sweep
expect_bad "mc loss without fly" "--loss" montecarlo --vehicles 2 --count 1 --loss 0.1
expect_bad "mc loss 1" "--loss" montecarlo --vehicles 2 --count 1 --fly --loss 1
expect_bad "mc delay a cycle" "--delay" montecarlo --vehicles 2 --count 1 --fly --delay 0.6 --jitter 0.4
expect_bad "mc fly value" "--fly" montecarlo --vehicles 2 --count 1 --fly=yes

# ---- the coordinator stops ----

# Stopped before cycle 0: the UAVs, unanswered at the answer wait of cycle 0, plan for
# themselves there; each falls back twice (after that answer, and for good once the
# coordinator's silence outlasts coordinator_timeout).
sim_json headon-stop0 "$scenarios/headon.json" centralised 0 '
r["loss_of_separation"] is False
r["fallbacks"] == 4
r["deviation"] == 580
r["coordinator_stopped_at"] == 0
r["replans"] >= 1
' --coordinator-stops 0
# Late encounter: the coordinator resolves the head-on pair at once and stops at step 13,
# before UAV 3's crossing (which conflicts with UAV 1 around t = 35 s) has entered its
# horizon; the UAVs fall back and solve the crossing themselves. Without the stop nobody
# falls back.
sim_json late-stop13 "$scenarios/late_encounter.json" centralised 0 '
r["loss_of_separation"] is False
r["fallbacks"] == 3
r["replans"] >= 2
any(offsets[1][k] != 0 or offsets[3][k] != 0 for k in range(30, 38))
all(offsets[3][k] == 0 for k in range(0, 14))
' --coordinator-stops 13
sim_json late-alive "$scenarios/late_encounter.json" centralised 0 '
r["loss_of_separation"] is False
r["fallbacks"] == 0
any(offsets[1][k] != 0 or offsets[3][k] != 0 for k in range(30, 38))
'
# The crossing needs a manoeuvre: flying their references, UAVs 1 and 3 meet at t = 35 s.
if python3 - "$scenarios/late_encounter.json" <<'PY'; then pass; else fail "late_encounter: 1 and 3 do not meet on their references"; fi
import json, math, sys
s = json.load(open(sys.argv[1]))
v = {u["id"]: u for u in s["vehicles"]}
def at(u, t):
    a, b = u["route"][0], u["route"][1]
    L = math.hypot(b[0] - a[0], b[1] - a[1])
    f = u["cruise_speed"] * t / L
    return [a[j] + f * (b[j] - a[j]) for j in range(3)]
p, q = at(v[1], 35.0), at(v[3], 35.0)
sys.exit(0 if math.hypot(p[0] - q[0], p[1] - q[1]) < 30 and abs(p[2] - q[2]) < 10 else 1)
PY

# --coordinator-stops STEP:M, the coordinator cut after M of its messages of cycle STEP
# (whatever they are). STEP:0 is STEP (plus the count's keys). Head-on's cycle 0 is the
# conflict report, the plan's two rows, the heartbeat: cut after the rows, the UAVs fly
# the coordinator's plan (500 m^2, 18) though it is gone before its heartbeat; cut after
# the report, they fall back and plan for themselves (580 m^2, 20, as when it stops at 0).
# The paper's cycle 0 has 8 messages (report, 1 + 2 + 3 plan rows, heartbeat).
"$bin" sim "$scenarios/headon.json" --mode centralised --json --coordinator-stops 0 >"$tmp/stop0.json" 2>&1
"$bin" sim "$scenarios/headon.json" --mode centralised --json --coordinator-stops 0:0 >"$tmp/stop00.json" 2>&1
if python3 - "$tmp/stop0.json" "$tmp/stop00.json" <<'PY'; then pass; else fail "--coordinator-stops 0:0 is not --coordinator-stops 0"; fi
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
extra = {k: b.pop(k) for k in ("coordinator_stopped_after", "coordinator_messages_sent",
                               "coordinator_messages_cut")}
assert a == b and extra == {"coordinator_stopped_after": 0, "coordinator_messages_sent": 0,
                            "coordinator_messages_cut": 0}, extra
PY
# Cycle 0 of the head-on: the report, the plan's two rows, the heartbeat, then (its poll)
# the COMMIT. Stopped after the rows, or after the heartbeat, no COMMIT comes, but each UAV
# heard the other accept: at the answer wait both commit the plan themselves (all or
# none) and fly it as if the COMMIT had come; stopped after the COMMIT, both fly it.
sim_json headon-cut3 "$scenarios/headon.json" centralised 0 '
r["loss_of_separation"] is False
(r["deviation"], r["effort"]) == (500, 18)
r["coordinator_stopped_at"] == 0 and r["coordinator_stopped_after"] == 3
r["coordinator_messages_sent"] == 3 and r["coordinator_messages_cut"] == 1
r["fallbacks"] == 2
' --coordinator-stops 0:3
sim_json headon-cut4 "$scenarios/headon.json" centralised 0 '
r["loss_of_separation"] is False
(r["deviation"], r["effort"]) == (500, 18)
r["coordinator_messages_sent"] == 4
' --coordinator-stops 0:4
sim_json headon-cut5 "$scenarios/headon.json" centralised 0 '
r["loss_of_separation"] is False
(r["deviation"], r["effort"]) == (500, 18)
r["coordinator_messages_sent"] == 5
' --coordinator-stops 0:5
sim_json headon-cut1 "$scenarios/headon.json" centralised 0 '
r["loss_of_separation"] is False
(r["deviation"], r["effort"]) == (580, 20)
r["coordinator_messages_sent"] == 1 and r["coordinator_messages_cut"] == 3
' --coordinator-stops 0:1
# Cycle 0 of the paper's encounter: 18 messages (its plans, their commits, the ABORT of
# a proposal a newer plan superseded with its 4 copies, the heartbeat and its copies).
sim_json paper-cut-all "$scenarios/paper.json" centralised 0 '
r["coordinator_messages_sent"] == 18 and r["coordinator_messages_cut"] == 0
' --coordinator-stops 0:18
sim_json paper-cut-beyond "$scenarios/paper.json" centralised 0 '
r["coordinator_stopped_after"] == 24 and r["coordinator_messages_sent"] == 18
' --coordinator-stops 0:24
# With loss the cut is the same mechanism (the network's): a run repeats byte for byte.
for run in 1 2; do
    "$bin" sim "$scenarios/paper.json" --mode centralised --coordinator-stops 0:4 --loss 0.3 \
        --delay 0.2 --net-seed 5 >"$tmp/cut-loss$run.txt" 2>&1
done
if grep -Eq '^coordinator: stopped in cycle 0 after 4 of its messages \(4 went out in it, [0-9]+ more were cut\)$' "$tmp/cut-loss1.txt" \
    && grep -q '^network: ' "$tmp/cut-loss1.txt" && cmp -s "$tmp/cut-loss1.txt" "$tmp/cut-loss2.txt"; then
    pass
else
    fail "sim --coordinator-stops 0:4 with loss: $(tail -n 2 "$tmp/cut-loss1.txt")"
fi
# Without :M the text has no coordinator line.
"$bin" sim "$scenarios/headon.json" --mode centralised --coordinator-stops 0 >"$tmp/stop0.txt" 2>&1
if ! grep -q '^coordinator:' "$tmp/stop0.txt"; then pass; else fail "--coordinator-stops 0 prints a coordinator line"; fi

# A joint search that runs out of beta is not the end: the centralised planner answers its
# incumbent, the priority order's plan, not proven optimal. Head-on's joint search stores
# more than 20 nodes, so with beta 20 the one-shot plan is that incumbent, and the loop
# flies it from the coordinator's first plan, as the decoupled fleet would.
python3 - "$scenarios/headon.json" "$tmp/headon_beta.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["beta"] = 20
json.dump(s, open(sys.argv[2], "w"))
PY
"$bin" plan "$tmp/headon_beta.json" --mode centralised >"$tmp/plan_beta.json" 2>/dev/null
if [ "$(field "$tmp/plan_beta.json" 'r["status"], r["optimal"], r["stats"]["limit"]')" = "('solved', False, 'beta')" ]; then pass; else fail "headon with beta 20: the one-shot centralised plan is not the incumbent stopped by beta"; fi
sim_json headon-beta20 "$tmp/headon_beta.json" centralised 0 '
r["loss_of_separation"] is False
r["replans"] == 1
r["deviation"] == 580
'

# ---- steps, text output and the figure ----

sim_json headon-steps5 "$scenarios/headon.json" decoupled 0 '
r["steps"] == 5
' --steps 5
"$bin" sim "$scenarios/headon.json" --mode centralised --svg "$tmp/fig.svg" >"$tmp/text" 2>"$tmp/err"
rc=$?
if [ "$rc" -eq 0 ] && [ ! -s "$tmp/err" ] && grep -q '^loss of separation: no$' "$tmp/text" \
    && grep -q '^fallbacks: 0$' "$tmp/text" && grep -q '^replans: 1$' "$tmp/text"; then
    pass
else
    fail "text output: exit $rc: $(head -c 400 "$tmp/text") $(head -c 200 "$tmp/err")"
fi
if grep -q '<svg' "$tmp/fig.svg" && grep -q '</svg>' "$tmp/fig.svg"; then pass; else fail "--svg wrote no SVG document"; fi

# Track ids a track message cannot carry (0, repeated) are the scenario's to choose: the
# run goes on, and both tracks are avoided.
python3 - "$scenarios/track_crossing.json" "$tmp/track_ids.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = s["tracks"][0]
s["tracks"] = [dict(t, id=0), dict(t, id=0, position=[250, 250, 102], velocity=[0, -10, 0])]
json.dump(s, open(sys.argv[2], "w"))
PY
sim_json track-ids "$tmp/track_ids.json" decoupled 0 '
r["loss_of_separation"] is False
r["replans"] >= 1
'

# Ids against priorities: UAV 1 (priority 2) and UAV 2 (priority 1) cross at the same
# altitude and meet within the first step, so the lower priority must climb at cycle 0,
# knowing the higher priority's intent. The UAVs are stepped in priority order, not by
# id (stepped by id, UAV 1 decided before it had heard UAV 2 and flew into it over step 0),
# so the loop flies what the one-shot decoupled plan gives: UAV 1 climbs, UAV 2 does not.
python3 - "$tmp/ids_against_priorities.json" <<'PY'
import json, sys
uav = {"cruise_speed": 20.0, "climb_rate": 10.0, "radius": 15.0, "half_height": 5.0}
json.dump({"name": "crossing, ids against priorities", "dt": 1.0, "horizon": 10, "vehicles": [
    dict(uav, id=1, priority=2, route=[[0, -40, 100], [0, 400, 100]]),
    dict(uav, id=2, priority=1, route=[[-40, 0, 100], [400, 0, 100]])]}, open(sys.argv[1], "w"))
PY
"$bin" plan "$tmp/ids_against_priorities.json" --mode decoupled >"$tmp/plan_ids.json" 2>/dev/null
sim_json ids-against-priorities "$tmp/ids_against_priorities.json" decoupled 0 "
r['loss_of_separation'] is False
offsets[1][1] != 0 and all(o == 0 for o in offsets[2])
(r['deviation'], r['effort']) == ($(field "$tmp/plan_ids.json" 'r["cost"]["deviation"]'), $(field "$tmp/plan_ids.json" 'r["cost"]["effort"]'))
"

# ---- bad arguments and inputs ----

h=$scenarios/headon.json
expect_bad "no scenario" "missing SCENARIO" sim --mode centralised
expect_bad "no mode" "--mode" sim "$h"
expect_bad "bad mode" "--mode" sim "$h" --mode sideways
expect_bad "mode twice" "--mode" sim "$h" --mode decoupled --mode decoupled
expect_bad "steps 0" "--steps" sim "$h" --mode decoupled --steps 0
expect_bad "steps word" "--steps" sim "$h" --mode decoupled --steps many
expect_bad "steps negative" "--steps" sim "$h" --mode decoupled --steps=-3
expect_bad "steps missing" "--steps" sim "$h" --mode decoupled --steps
expect_bad "json value" "--json" sim "$h" --mode decoupled --json=yes
expect_bad "svg missing" "--svg" sim "$h" --mode decoupled --svg
expect_bad "svg unwritable" "--svg" sim "$h" --mode decoupled --svg "$tmp/no/such/dir/f.svg"
expect_bad "stop decoupled" "--coordinator-stops" sim "$h" --mode decoupled --coordinator-stops 1
expect_bad "stop after K" "--coordinator-stops" sim "$h" --mode centralised --steps 4 --coordinator-stops 5
expect_bad "stop word" "--coordinator-stops" sim "$h" --mode centralised --coordinator-stops soon
for bad in 1:x :1 1: 1:2:3 1:-1 -1:0 1:1000001 "1 :2"; do
    expect_bad "stop $bad" "--coordinator-stops" sim "$h" --mode centralised --coordinator-stops "$bad"
done
expect_bad "unknown option" "--fast" sim "$h" --mode decoupled --fast
expect_bad "two scenarios" "unexpected argument" sim "$h" "$h" --mode decoupled
expect_bad "missing file" "no-such.json" sim "$tmp/no-such.json" --mode decoupled
printf '{"name": "x", "dt": 1' >"$tmp/truncated.json"
expect_bad "truncated file" "truncated.json" sim "$tmp/truncated.json" --mode centralised
python3 - "$h" "$tmp/long.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["horizon"] = 41
json.dump(s, open(sys.argv[2], "w"))
PY
# An intent of 41 samples is what one datagram holds: a horizon of 40 steps.
expect_bad "horizon 41" "at most 40" sim "$tmp/long.json" --mode decoupled
python3 - "$h" "$tmp/crowd.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
base = s["vehicles"][0]
s["vehicles"] = [dict(base, id=i + 1, route=[[0, 100 * i, 100], [600, 100 * i, 100]])
                 for i in range(33)]
json.dump(s, open(sys.argv[2], "w"))
PY
expect_bad "33 vehicles" "vehicles" sim "$tmp/crowd.json" --mode decoupled

# Scenarios that `coavoid plan` takes but whose numbers a message cannot carry
# (COA_LCM_MAX_* in coavoid_lcm.h), at the start or somewhere in the run: refused before
# the run, naming the field, instead of a node failing in it (exit 3).
python3 - "$h" "$scenarios/track_crossing.json" "$tmp" <<'PY'
import copy, json, sys
h, tc = (json.load(open(f)) for f in sys.argv[1:3])
def write(name, base, part, index, **fields):
    s = copy.deepcopy(base)
    item = s[part][index]
    for k, v in fields.items():
        if v is None:
            del item[k]
        else:
            item[k] = v
    json.dump(s, open(f"{sys.argv[3]}/limit_{name}.json", "w"))
# (1e30, not the 1e300 that double takes: a COAVOID_SINGLE_PRECISION build's loader refuses
# what float cannot hold before sim sees it.)
write("radius", h, "vehicles", 1, radius=1e30)
write("half_height", h, "vehicles", 1, half_height=2e5)
write("cruise", h, "vehicles", 1, cruise_speed=2e4)
write("steep", h, "vehicles", 1, climb_rate=3000.0, steep_factor=4)
write("priority", h, "vehicles", 1, priority=3000000000)
write("far", h, "vehicles", 1, route=[[1e15, 0, 0], [1e15 + 1e9, 0, 0]])
# 9.9e6 m at t = 0, 1e7 m at t = 50 s: within the run's 48 steps and last horizon of 24.
write("runaway", h, "vehicles", 1, route=[[9.9e6, 0, 100], [9.9e6 + 1000, 0, 100]],
      cruise_speed=2000.0)
write("slope", h, "vehicles", 1, route=[[0, 500, 0], [1, 500, 1e5]], cruise_speed=1.0)
write("track_velocity", tc, "tracks", 0, velocity=[1e30, 0, 0])
write("track_sigma", tc, "tracks", 0, sigma=[1.0, 2e5])
write("track_runaway", tc, "tracks", 0, position=[9.99e6, 0, 100], velocity=[1000, 0, 0])
write("track_leg", tc, "tracks", 0, position=None, velocity=None,
      path=[[0, 0, 0, 100], [1, 5e4, 0, 100], [2, 5e4, 1, 100]])
s = copy.deepcopy(h)
s["obstacles"] = [{"type": "box", "min": [0, 1000, 0], "max": [10, 2e7, 10]}]
json.dump(s, open(f"{sys.argv[3]}/limit_box.json", "w"))
PY
for name in radius far runaway track_velocity track_runaway box; do
    "$bin" plan "$tmp/limit_$name.json" --mode decoupled >/dev/null 2>&1
    rc=$?
    if [ "$rc" -le 1 ]; then pass; else fail "limit_$name: coavoid plan refuses it too (exit $rc), so it tests nothing of sim's own"; fi
done
also="beyond what"
expect_bad "radius 1e30" "vehicles[1].radius: 1e+30 m" sim "$tmp/limit_radius.json" --mode decoupled
expect_bad "half-height 2e5" "vehicles[1].half_height" sim "$tmp/limit_half_height.json" --mode centralised
expect_bad "cruise speed 2e4" "vehicles[1].cruise_speed" sim "$tmp/limit_cruise.json" --mode decoupled
expect_bad "steep climb of 12000 m/s" "vehicles[1].climb_rate" sim "$tmp/limit_steep.json" --mode decoupled
expect_bad "priority 3e9" "vehicles[1].priority" sim "$tmp/limit_priority.json" --mode decoupled
expect_bad "route at 1e15 m" "vehicles[1].route" sim "$tmp/limit_far.json" --mode decoupled
expect_bad "route leaving the range in the run" "t = 51 s" sim "$tmp/limit_runaway.json" --mode decoupled
expect_bad "route climbing at 1e5 m/s" "vehicles[1].route" sim "$tmp/limit_slope.json" --mode decoupled
expect_bad "track velocity 1e30" "tracks[0].velocity" sim "$tmp/limit_track_velocity.json" --mode decoupled
expect_bad "track sigma 2e5" "tracks[0].sigma[1]" sim "$tmp/limit_track_sigma.json" --mode decoupled
expect_bad "track leaving the range in the run" "tracks[0]: at t = 11 s" sim "$tmp/limit_track_runaway.json" --mode centralised
expect_bad "track path leg at 5e4 m/s" "tracks[0].path[1]" sim "$tmp/limit_track_leg.json" --mode decoupled
expect_bad "box at 2e7 m" "obstacles[0].max" sim "$tmp/limit_box.json" --mode decoupled
also=
# A shorter run that stays in range is flown: the check is over this run, not any run.
sim_json runaway-short "$tmp/limit_runaway.json" decoupled 0 '
r["steps"] == 20
' --steps 20

# ---- coavoid keygen: the fleet's signing keys ----

# A secret key file per node, for its owner only, and a trust file with every public key
# and its role; two runs give different keys.
mkdir -p "$tmp/keys" "$tmp/keys2"
if expect_status "keygen" 0 keygen "$scenarios/paper.json" --dir "$tmp/keys" &&
    "$bin" keygen "$scenarios/paper.json" --dir "$tmp/keys2" 2>/dev/null; then
    if [ "$(stat -c %a "$tmp/keys/coordinator.key" "$tmp/keys/world.key" "$tmp/keys/vehicle-1.key" \
        "$tmp/keys/vehicle-2.key" "$tmp/keys/vehicle-3.key" | sort -u)" = 600 ] &&
        grep -Eq '^coavoid-secret-key 101 [0-9a-f]{128}$' "$tmp/keys/vehicle-1.key" &&
        [ "$(grep -Ec '^(1 coordinator 65001|2 world 65000|10[123] vehicle [123]) [0-9a-f]{64}$' \
            "$tmp/keys/trust.txt")" = 5 ] &&
        ! cmp -s "$tmp/keys/trust.txt" "$tmp/keys2/trust.txt"; then
        pass
    else
        fail "keygen: unexpected files: $(ls -l "$tmp/keys") $(cat "$tmp/keys/trust.txt")"
    fi
fi
expect_bad "keygen without --dir" "--dir" keygen "$scenarios/paper.json"
# A directory that does not exist is made, for its owner only (the README's first
# `keygen ... --dir keys/` on a fresh checkout); a file in its place, a missing parent and
# a refused scenario are errors that leave nothing behind.
if expect_status "keygen into a new directory" 0 keygen "$scenarios/paper.json" --dir "$tmp/new"; then
    if [ "$(stat -c %a "$tmp/new")" = 700 ] && [ -s "$tmp/new/trust.txt" ]; then
        pass
    else
        fail "keygen into a new directory: $(stat -c '%a %n' "$tmp/new" "$tmp/new"/* 2>&1)"
    fi
fi
: >"$tmp/plain"
expect_bad "keygen into a file" "not a directory" keygen "$scenarios/paper.json" --dir "$tmp/plain"
expect_bad "keygen, a missing parent" "cannot create" keygen "$scenarios/paper.json" \
    --dir "$tmp/none/keys"
expect_bad "keygen, a refused scenario" "$tmp/none.json" keygen "$tmp/none.json" --dir "$tmp/left"
if [ -e "$tmp/left" ]; then
    fail "keygen, a refused scenario: it created $tmp/left"
else
    pass
fi

finish
