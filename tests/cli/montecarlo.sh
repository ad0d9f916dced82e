#!/bin/bash
# SPDX-License-Identifier: MIT
# `coavoid montecarlo` on small runs: the CSV, the JSON summary and the SVG are well formed;
# the summary is what the CSV says (recomputed here); a seed gives the same rows (times
# aside) twice and with --jobs 1 or 2; every plan the centralised planner solves is at most
# as costly as a decoupled one (lexicographically, in exact units), which the command also
# checks itself and would exit 3 on; a saved encounter replays to the same plan with
# `coavoid plan`; progress goes to stderr; bad options exit 2 with one line naming them.
#
# usage: bash montecarlo.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 shows each message)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"

# check NAME CSV JSON SVG: the files are well formed and agree.
check() {
    local name=$1
    shift
    if python3 - "$@" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "$name: $(tail -n 5 "$tmp/py")"; fi
import csv, json, math, sys
import xml.etree.ElementTree as ET

csv_path, json_path, svg_path = sys.argv[1:4]
header = ["seed", "vehicles", "index", "redraws", "hills", "tracks", "first_conflict_step",
          "method", "status", "deviation", "deviation_units", "effort", "expanded",
          "generated", "orders_tried", "time_us", "optimal", "bound_deviation", "beta",
          "max_orders", "work", "first", "count"]
methods = ["centralised", "decoupled_fixed", "decoupled_reordered"]
with open(csv_path, newline="") as f:
    reader = csv.reader(f)
    assert next(reader) == header
    rows = [dict(zip(header, r)) for r in reader]
b = json.load(open(json_path))
assert b["command"] == "montecarlo" and b["horizon"] >= 1 and b["dt"] > 0, b
count, first = b["count"], b["first"]
sizes = [s["vehicles"] for s in b["sizes"]]
# Every encounter once per method, in order: sizes as given, then index, then method.
expect = [(n, j, m) for n in sizes for j in range(first, first + count) for m in methods]
got = [(int(r["vehicles"]), int(r["index"]), r["method"]) for r in rows]
assert got == expect, (got[:6], expect[:6])
for r in rows:
    assert r["status"] in ("solved", "infeasible", "budget_exhausted"), r
    assert int(r["seed"]) == int(b["seed"]), r
    assert 1 <= int(r["first_conflict_step"]) < b["horizon"], r
    assert 1 <= int(r["hills"]) <= 3 and 0 <= int(r["tracks"]) <= 2, r
    assert float(r["time_us"]) >= 0 and int(r["expanded"]) >= 0, r
    solved = r["status"] == "solved"
    if solved:  # the reference conflicts: every plan moves someone
        assert float(r["deviation"]) > 0 and int(r["deviation_units"]) > 0 and int(r["effort"]) > 0, r
    else:
        assert r["deviation"] == r["deviation_units"] == r["effort"] == "", r
    assert int(r["orders_tried"]) >= 1, r
    if r["method"] != "decoupled_reordered":
        assert int(r["orders_tried"]) == 1, r
    # The run's encounters on every row; optimal and the bound on the centralised ones.
    assert (int(r["first"]), int(r["count"])) == (first, count), r
    if r["method"] == "centralised":
        assert r["optimal"] in ("0", "1") and float(r["bound_deviation"]) >= 0, r
        assert r["optimal"] == "0" or (solved and r["bound_deviation"] == r["deviation"]), r
    else:
        assert r["optimal"] == r["bound_deviation"] == "", r

def quantile(x, p):  # numpy's default (linear), as the command's
    h = (len(x) - 1) * p
    lo = math.floor(h)
    return x[lo] + (h - lo) * (x[lo + 1] - x[lo]) if lo + 1 < len(x) else x[-1]

def close(a, b):
    return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))

for s in b["sizes"]:
    n = s["vehicles"]
    assert s["encounters"] == count and s["beta"] >= 1 and s["max_orders"] >= 1, s
    enc = {}
    for r in rows:
        if int(r["vehicles"]) == n:
            enc.setdefault(int(r["index"]), {})[r["method"]] = r
            assert (int(r["beta"]), int(r["max_orders"])) == (s["beta"], s["max_orders"]), r
    assert s["redraws"] == sum(int(e["centralised"]["redraws"]) for e in enc.values()), s
    assert [m["method"] for m in s["methods"]] == methods, s
    for m in s["methods"]:
        st = [e[m["method"]]["status"] for e in enc.values()]
        assert (m["solved"], m["infeasible"], m["budget_exhausted"]) == (
            st.count("solved"), st.count("infeasible"), st.count("budget_exhausted")), m
        assert close(m["success_rate"], m["solved"] / count), m
        assert 0 <= m["wilson_low"] <= m["success_rate"] <= m["wilson_high"] <= 1, m
        times = sorted(float(e[m["method"]]["time_us"]) * 1e-3 for e in enc.values())
        # the run's times are the CSV's (to 0.1 us)
        assert close(m["time_ms"]["max"], times[-1]) and close(m["time_ms"]["median"], quantile(times, 0.5)), (m["time_ms"], times)
        nodes = sorted(int(e[m["method"]]["expanded"]) for e in enc.values())
        assert close(m["nodes_expanded"]["median"], quantile(nodes, 0.5)), m
        if m["method"] == "centralised":
            # Every plan found is proven optimal or bounded; plan over bound is >= 1.
            assert m["optimal"] + m["bounded"] == m["solved"], m
            assert m["optimal"] == sum(1 for e in enc.values() if e["centralised"]["optimal"] == "1"), m
            br = m["bound_ratio"]
            assert br["count"] <= m["solved"], m
            assert br["count"] == 0 or 1 <= br["min"] <= br["median"] <= br["max"], m
            assert br["count"] == 0 or close(br["equal_share"] * br["count"], m["optimal"]) or m["optimal"] > br["count"], m
            continue
        both = [e for e in enc.values()
                if e["centralised"]["status"] == "solved" and e[m["method"]]["status"] == "solved"]
        for e in both:
            c, d = e["centralised"], e[m["method"]]
            # Centralised is optimal: never beaten, lexicographically in exact units.
            assert (int(d["deviation_units"]), int(d["effort"])) >= (
                int(c["deviation_units"]), int(c["effort"])), (c, d)
        ratios = sorted(int(e[m["method"]]["deviation_units"]) / int(e["centralised"]["deviation_units"])
                        for e in both)
        r = m["deviation_ratio"]
        assert r["count"] == len(both), (r, len(both))
        if both:
            for key, p in (("min", 0), ("p25", 0.25), ("median", 0.5), ("p75", 0.75),
                           ("p90", 0.9), ("max", 1)):
                assert close(r[key], quantile(ratios, p)), (key, r[key], quantile(ratios, p))
            assert close(r["mean"], sum(ratios) / len(ratios)), r
            eq = sum(1 for e in both if e[m["method"]]["deviation_units"] == e["centralised"]["deviation_units"])
            assert close(r["equal_share"], eq / len(both)), r
        # A decoupled plan is a plan: the centralised search cannot have proven none.
        assert not any(e["centralised"]["status"] == "infeasible" and e[m["method"]]["status"] == "solved"
                       for e in enc.values()), m
        cs = lambda e: e["centralised"]["status"] == "solved"
        ds = lambda e: e[m["method"]]["status"] == "solved"
        assert m["fails_where_centralised_solves"] == sum(1 for e in enc.values() if cs(e) and not ds(e)), m
        assert m["solves_where_centralised_fails"] == sum(1 for e in enc.values() if ds(e) and not cs(e)), m
    # Reordering tries the fixed order first: it solves whatever the fixed order solves.
    for e in enc.values():
        if e["decoupled_fixed"]["status"] == "solved":
            assert e["decoupled_reordered"]["deviation_units"] == e["decoupled_fixed"]["deviation_units"], e

root = ET.parse(svg_path).getroot()
assert root.tag == "{http://www.w3.org/2000/svg}svg", root.tag
texts = " ".join(t.text or "" for t in root.iter("{http://www.w3.org/2000/svg}text"))
for n in sizes:
    assert f"{n} UAVs" in texts, texts
assert "centralised plan / its lower bound (CDF)" in texts, texts
bars = [r for r in root.iter("{http://www.w3.org/2000/svg}rect") if r.get("fill") not in ("white", "none")]
assert len(bars) >= 3 * len(sizes), len(bars)
PY
}

# rows_equal NAME A B: two CSVs are the same but for their times (the last column).
rows_equal() {
    if diff <(cut -d, -f1-15 "$2") <(cut -d, -f1-15 "$3") >"$tmp/diff"; then
        pass
    else
        fail "$1: the rows differ: $(head -c 400 "$tmp/diff")"
    fi
}

# 2, 3 and 4 UAVs; a small beta keeps the 4-UAV centralised searches cheap (and some run
# out of it, which must be reported as budget exhausted, not hidden).
set_a=(--vehicles 2,3,4 --count 5 --seed 7 --beta 2000 --quiet)
if expect_ok first montecarlo "${set_a[@]}" --csv "$tmp/a.csv" --svg "$tmp/a.svg" --json; then
    cp "$tmp/out" "$tmp/a.json"
    check first "$tmp/a.csv" "$tmp/a.json" "$tmp/a.svg"
fi
if expect_ok again montecarlo "${set_a[@]}" --csv "$tmp/b.csv" --json; then
    rows_equal "same seed" "$tmp/a.csv" "$tmp/b.csv"
    if python3 - "$tmp/a.json" "$tmp/out" <<'PY'; then pass; else fail "same seed: different summary"; fi
import json, sys
def strip(b):  # times aside
    for s in b["sizes"]:
        for m in s["methods"]:
            m.pop("time_ms")
    return b
a, b = (strip(json.load(open(p))) for p in sys.argv[1:])
sys.exit(0 if a == b else "summaries differ")
PY
fi
if expect_ok jobs montecarlo "${set_a[@]}" --jobs 2 --csv "$tmp/c.csv"; then
    rows_equal "--jobs 2" "$tmp/a.csv" "$tmp/c.csv"
fi
# A run split in two parts (--first) gives the whole run's rows: each encounter is drawn
# from its own index, not from those before it.
if expect_ok "first 0" montecarlo --vehicles 2 --count 2 --seed 7 --beta 2000 --quiet --csv "$tmp/p0.csv" &&
    expect_ok "first 2" montecarlo --vehicles 2 --count 3 --first 2 --seed 7 --beta 2000 --quiet \
        --csv "$tmp/p2.csv" --svg "$tmp/p2.svg" --json; then
    cp "$tmp/out" "$tmp/p2.json"
    check "first 2" "$tmp/p2.csv" "$tmp/p2.json" "$tmp/p2.svg"
    rows_equal "parts" <(grep -E '^(seed|7,2,)' "$tmp/a.csv") <(cat "$tmp/p0.csv" && tail -n +2 "$tmp/p2.csv")
fi
# Another seed draws other encounters.
if expect_ok other_seed montecarlo --vehicles 2 --count 5 --seed 8 --quiet --csv "$tmp/d.csv"; then
    if [ "$(grep -c '^8,2,' "$tmp/d.csv")" -eq 15 ] &&
        ! diff -q <(cut -d, -f2-15 "$tmp/d.csv") <(grep -E '^(seed|7,2,)' "$tmp/a.csv" | cut -d, -f2-15) >/dev/null; then
        pass
    else
        fail "seed 8 gave the rows of seed 7, or not 15 rows"
    fi
fi
# beta 1 cannot finish a joint search: the centralised answer is then its incumbent, the
# first priority order that works, so it solves just what reordering solves, and the
# encounters no order solves are budget exhausted (nothing proven).
if expect_ok budget montecarlo --vehicles 3 --count 3 --beta 1 --quiet --csv "$tmp/e.csv" --svg "$tmp/e.svg" --json; then
    cp "$tmp/out" "$tmp/e.json"
    check budget "$tmp/e.csv" "$tmp/e.json" "$tmp/e.svg"
    if python3 -c '
import json, sys
c, _, r = json.load(open(sys.argv[1]))["sizes"][0]["methods"]
sys.exit(0 if c["solved"] == r["solved"] and c["budget_exhausted"] == 3 - c["solved"] - c["infeasible"] else (c, r))' "$tmp/e.json"; then
        pass
    else
        fail "beta 1: centralised does not answer what reordering solves"
    fi
fi

# The text summary: one block per UAV count with a row per method.
if expect_ok text montecarlo --vehicles 2,3 --count 3 --quiet; then
    if grep -q '^2 UAVs: 3 encounters' "$tmp/out" && grep -q '^3 UAVs: 3 encounters' "$tmp/out" &&
        [ "$(grep -c '^  decoupled_reordered ' "$tmp/out")" -eq 4 ]; then
        pass
    else
        fail "text summary: $(head -c 400 "$tmp/out")"
    fi
fi

# Seed 1's first two 3-UAV encounters fail in the fixed order: its ratio row has no
# numbers (a ratio is at least 1, so 0.000 there would be a made-up value), but still the
# shares.
if expect_ok text_empty montecarlo --vehicles 3 --count 2 --beta 1 --quiet; then
    rows=$(grep -E '^  decoupled_fixed +0 ' "$tmp/out")
    if [ "$(printf '%s\n' "$rows" | grep -c -- ' -  *- ')" -eq 1 ] &&
        ! printf '%s\n' "$rows" | grep -q '0\.000'; then
        pass
    else
        fail "text summary without ratios: $(head -c 600 "$tmp/out")"
    fi
fi

# A saved encounter is a scenario file that `coavoid plan` plans the same way.
mkdir "$tmp/saved"
if expect_ok save montecarlo --vehicles 3 --count 2 --seed 7 --quiet --save "$tmp/saved" --csv "$tmp/f.csv"; then
    file="$tmp/saved/montecarlo-7-3-1.json"
    "$bin" plan "$file" --mode centralised >"$tmp/plan.json" 2>"$tmp/err"
    if python3 - "$tmp/plan.json" "$tmp/f.csv" <<'PY'; then pass; else fail "replay of $file: $(cat "$tmp/err")"; fi
import csv, json, sys
plan = json.load(open(sys.argv[1]))
row = [r for r in csv.DictReader(open(sys.argv[2]))
       if r["index"] == "1" and r["method"] == "centralised"][0]
assert plan["status"] == row["status"], (plan["status"], row["status"])
assert plan["stats"]["nodes_expanded"] == int(row["expanded"]), (plan["stats"], row)
if row["status"] == "solved":
    assert abs(plan["cost"]["deviation"] - float(row["deviation"])) < 1e-5, (plan["cost"], row)
    assert plan["cost"]["effort"] == int(row["effort"]), (plan["cost"], row)
PY
    [ "$(ls "$tmp/saved" | wc -l)" -eq 2 ] && pass || fail "--save: $(ls "$tmp/saved")"
fi

# Progress: without --quiet and with stderr not a terminal, a line per 10 % and the last.
if "$bin" montecarlo --vehicles 2 --count 20 >"$tmp/out" 2>"$tmp/err"; then
    if grep -q '^montecarlo: 20/20 encounters (100%), ' "$tmp/err" &&
        ! grep -qv '^montecarlo: [0-9]*/20 encounters ' "$tmp/err"; then
        pass
    else
        fail "progress: $(head -c 400 "$tmp/err")"
    fi
else
    fail "progress: exit status $?"
fi

if "$bin" montecarlo --help >"$tmp/help" 2>&1 && grep -q -- '--vehicles N' "$tmp/help"; then
    pass
else
    fail "montecarlo --help: $(head -c 300 "$tmp/help")"
fi

# --figure-from: the closed loop's figure from several --fly runs' CSVs (written here, so
# that the test needs no simulation): the table's counts are the files', the same loss in
# two files adds up, the SVG is well formed with a series per UAV count and mode.
python3 - "$tmp" <<'PY'
import random, sys
head = ("seed,vehicles,index,redraws,hills,tracks,first_conflict_step,method,status,"
        "deviation,deviation_units,effort,expanded,generated,orders_tried,time_us,"
        "loss,delay,jitter,net_seed,stop_step,stop_messages")
rng = random.Random(5)
def write(path, loss, rows, delay="0"):
    with open(path, "w") as f:
        f.write(head + "\n")
        for n, i, mode, lost in rows:
            f.write(f"1,{n},{i},0,1,0,3,centralised,solved,1.0,8,1,5,5,1,3.0,{loss},{delay},0,9,,\n")
            f.write(f"1,{n},{i},0,1,0,3,flown_{mode},{'loss_of_separation' if lost else 'separated'}"
                    f",,,,,,,,{loss},{delay},0,9,,\n")
            f.write(f"1,{n},{i},0,1,0,3,flown_centralised_stop,loss_of_separation,,,,,,,,{loss},{delay},0,9,0,0\n")
for name, loss in (("f0", "0"), ("f3", "0.3"), ("f3b", "0.3"), ("f5", "0.5")):
    write(f"{sys.argv[1]}/{name}.csv", loss,
          [(n, i, m, rng.random() < 0.4) for n in (2, 4) for i in range(7) for m in ("centralised", "decoupled")])
write(f"{sys.argv[1]}/delay.csv", "0.3", [(2, 0, "centralised", False)], delay="0.1")
PY
if "$bin" montecarlo --figure-from "$tmp/f0.csv,$tmp/f3.csv,$tmp/f5.csv,$tmp/f3b.csv" --svg "$tmp/fig.svg" >"$tmp/fig.txt" 2>"$tmp/err" && [ ! -s "$tmp/err" ]; then
    if python3 - "$tmp" <<'PY'; then pass; else fail "--figure-from: table or figure wrong"; fi
import csv, re, sys
import xml.dom.minidom
d = sys.argv[1]
want = {}
for name in ("f0", "f3", "f5", "f3b"):
    for r in csv.DictReader(open(f"{d}/{name}.csv")):
        if r["method"] in ("flown_centralised", "flown_decoupled"):
            k = (int(r["vehicles"]), r["method"][6:], float(r["loss"]))
            e, l = want.get(k, (0, 0))
            want[k] = (e + 1, l + (r["status"] == "loss_of_separation"))
got = {}
for line in open(f"{d}/fig.txt").read().splitlines()[2:]:
    n, mode, loss, enc, lost = line.split()[:5]
    got[(int(n), mode, float(loss.rstrip("%")) / 100)] = (int(enc), int(lost))
assert got == want, (got, want)
svg = xml.dom.minidom.parse(f"{d}/fig.svg")
polylines = svg.getElementsByTagName("polyline")
assert len(polylines) == 4  # 2 sizes x 2 modes
assert len(svg.getElementsByTagName("circle")) == 12   # x 3 losses
PY
else
    fail "--figure-from: exit $?: $(head -c 300 "$tmp/err")"
fi
head -n 5 "$tmp/f0.csv" >"$tmp/two.csv"; tail -n 3 "$tmp/f3.csv" >>"$tmp/two.csv"
head -n 3 "$tmp/f0.csv" >"$tmp/short.csv"; printf '1,2,0,0,1,0,3,flown_decoupled,separated' >>"$tmp/short.csv"
{ head -n 1 "$tmp/f0.csv"; echo "1,2,0,0,1,0,3,flown_decoupled,separated,,,,,,,,0,0,0,9,,,"; } >"$tmp/fields.csv"
{ head -n 1 "$tmp/f0.csv"; echo "1,11,0,0,1,0,3,flown_decoupled,separated,,,,,,,,0,0,0,9,,"; } >"$tmp/eleven.csv"
{ head -n 1 "$tmp/f0.csv"; echo "1,2,0,0,1,0,3,flown_decoupled,crashed,,,,,,,,0,0,0,9,,"; } >"$tmp/status.csv"
{ head -n 1 "$tmp/f0.csv"; echo "1,2,0,0,1,0,3,flown_decoupled,separated,,,,,,,,1,0,0,9,,"; } >"$tmp/loss1.csv"
{ head -n 1 "$tmp/f0.csv"; echo "1,2,0,0,1,0,3,flown_decoupled,separated,,,,,,,,nan,0,0,9,,"; } >"$tmp/nan.csv"
{ head -n 1 "$tmp/f0.csv"; python3 -c 'print("x" * 5000)'; } >"$tmp/long.csv"
head -n 1 "$tmp/f0.csv" >"$tmp/empty.csv"
"$bin" montecarlo --vehicles 2 --count 1 --quiet --csv "$tmp/plain.csv" >/dev/null 2>&1
many=$(printf "$tmp/f0.csv,%.0s" $(seq 17)); many=${many%,}
expect_bad "figure without svg" "--svg" montecarlo --figure-from "$tmp/f0.csv"
expect_bad "figure with vehicles" "--figure-from" montecarlo --figure-from "$tmp/f0.csv" --svg "$tmp/g.svg" --vehicles 2
expect_bad "figure missing file" "no-such.csv" montecarlo --figure-from "$tmp/no-such.csv" --svg "$tmp/g.svg"
expect_bad "figure empty entry" "--figure-from" montecarlo --figure-from "$tmp/f0.csv,,$tmp/f3.csv" --svg "$tmp/g.svg"
expect_bad "figure 17 files" "--figure-from" montecarlo --figure-from "$many" --svg "$tmp/g.svg"
expect_bad "figure plain csv" "plain.csv:1: not the header" montecarlo --figure-from "$tmp/plain.csv" --svg "$tmp/g.svg"
expect_bad "figure two losses" "two.csv:7: a second loss" montecarlo --figure-from "$tmp/two.csv" --svg "$tmp/g.svg"
expect_bad "figure other delay" "delay.csv:3: delay or jitter" montecarlo --figure-from "$tmp/f3.csv,$tmp/delay.csv" --svg "$tmp/g.svg"
expect_bad "figure no newline" "short.csv:4: a line too long, or no newline" montecarlo --figure-from "$tmp/short.csv" --svg "$tmp/g.svg"
expect_bad "figure long line" "long.csv:2: a line too long" montecarlo --figure-from "$tmp/long.csv" --svg "$tmp/g.svg"
expect_bad "figure fields" "fields.csv:2: not 22 fields" montecarlo --figure-from "$tmp/fields.csv" --svg "$tmp/g.svg"
expect_bad "figure vehicles" "eleven.csv:2: vehicles" montecarlo --figure-from "$tmp/eleven.csv" --svg "$tmp/g.svg"
expect_bad "figure status" "status.csv:2: a flown row's status" montecarlo --figure-from "$tmp/status.csv" --svg "$tmp/g.svg"
expect_bad "figure loss 1" "loss1.csv:2: loss, delay or jitter" montecarlo --figure-from "$tmp/loss1.csv" --svg "$tmp/g.svg"
expect_bad "figure nan" "nan.csv:2: loss, delay or jitter" montecarlo --figure-from "$tmp/nan.csv" --svg "$tmp/g.svg"
expect_bad "figure no rows" "empty.csv:1: no flown rows" montecarlo --figure-from "$tmp/empty.csv" --svg "$tmp/g.svg"
expect_bad "figure svg unwritable" "--svg" montecarlo --figure-from "$tmp/f0.csv" --svg "$tmp/none/g.svg"

# --merge: a run rebuilt from the CSVs of its parts (--first, --count) prints the whole
# run's summary and draws its figure, times aside (each part timed its own plans), whatever
# the parts' order; the whole run's own CSV gives its summary to the digit, times included
# (a run's times are its CSV's). Parts that do not make one run are refused with one line
# naming the file: the same encounter twice, one left out, other options, a row repeated,
# changed or cut off, a CSV without the columns the summary needs.
# same NAME A B: two summaries (text or JSON) are equal but for the planning times.
same() {
    if python3 - "$2" "$3" >"$tmp/py" 2>&1 <<'PY'; then pass; else fail "$1: $(tail -n 3 "$tmp/py")"; fi
import json, re, sys
def load(path):
    text = open(path).read()
    if text.startswith("{"):
        b = json.loads(text)
        for s in b["sizes"]:
            for m in s["methods"]:
                m.pop("time_ms")
        return b
    times = re.compile(r"^(  \S+ +\d+ +\d+ +\d+ +[\d.]+% +[\d.]+- *[\d.]+%)( +[\d.]+){3}")
    lines = [times.sub(r"\1 t t t", line) for line in text.splitlines()]
    assert sum(" t t t" in line for line in lines) >= 6, "no method rows"
    return lines
a, b = load(sys.argv[1]), load(sys.argv[2])
sys.exit(0 if a == b else f"summaries differ: {a} {b}"[:600])
PY
}
# equal NAME A B: two files are equal byte for byte.
equal() { if cmp -s "$2" "$3"; then pass; else fail "$1: $(diff "$2" "$3" | head -c 400)"; fi; }
run=(--vehicles "3,2" --seed 5 --beta 2000 --quiet)
expect_ok "merge: whole" montecarlo "${run[@]}" --count 5 --csv "$tmp/w.csv" --svg "$tmp/w.svg" && cp "$tmp/out" "$tmp/w.txt"
expect_ok "merge: whole json" montecarlo "${run[@]}" --count 5 --csv "$tmp/wj.csv" --json && cp "$tmp/out" "$tmp/wj.json"
expect_ok "merge: part 1" montecarlo "${run[@]}" --count 2 --csv "$tmp/p1.csv"
expect_ok "merge: part 2" montecarlo "${run[@]}" --first 2 --count 3 --csv "$tmp/p2.csv"
if expect_ok "merge: the whole run's CSV" montecarlo --merge "$tmp/w.csv" --svg "$tmp/mw.svg"; then
    equal "merge: the whole run's summary" "$tmp/w.txt" "$tmp/out"
    equal "merge: the whole run's figure" "$tmp/w.svg" "$tmp/mw.svg"
fi
if expect_ok "merge: the whole run's CSV, json" montecarlo --merge "$tmp/wj.csv" --json; then
    equal "merge: the whole run's JSON" "$tmp/wj.json" "$tmp/out"
fi
if expect_ok "merge: parts" montecarlo --merge "$tmp/p1.csv,$tmp/p2.csv" --svg "$tmp/m.svg"; then
    same "merge: parts' summary" "$tmp/w.txt" "$tmp/out"
    equal "merge: parts' figure" "$tmp/w.svg" "$tmp/m.svg"
fi
if expect_ok "merge: parts reversed" montecarlo --merge "$tmp/p2.csv,$tmp/p1.csv" --json --svg "$tmp/r.svg"; then
    same "merge: parts reversed, JSON" "$tmp/wj.json" "$tmp/out"
    equal "merge: parts reversed, figure" "$tmp/w.svg" "$tmp/r.svg"
fi
# The closed loop (--fly, a network seed of its own): its table, from its flown rows.
fly=(--vehicles "2,3" --fly --loss 0.2 --net-seed 4 --beta 2000 --quiet)
expect_ok "merge: fly whole" montecarlo "${fly[@]}" --count 3 --csv "$tmp/fw.csv" && cp "$tmp/out" "$tmp/fw.txt"
expect_ok "merge: fly part 1" montecarlo "${fly[@]}" --count 1 --csv "$tmp/fp1.csv"
expect_ok "merge: fly part 2" montecarlo "${fly[@]}" --first 1 --count 2 --csv "$tmp/fp2.csv"
if expect_ok "merge: fly parts" montecarlo --merge "$tmp/fp2.csv,$tmp/fp1.csv"; then
    same "merge: fly parts' summary" "$tmp/fw.txt" "$tmp/out"
    if grep -q '^closed loop: .*loss 0.2, .*network seed 4$' "$tmp/out"; then pass; else fail "merge: fly: $(grep '^closed' "$tmp/out")"; fi
fi
expect_ok "merge: fly CSV to --figure-from" montecarlo --figure-from "$tmp/fw.csv" --svg "$tmp/ff.svg"
# Bad parts.
expect_ok "merge: part 3" montecarlo "${run[@]}" --first 3 --count 2 --csv "$tmp/p3.csv"
expect_ok "merge: other beta" montecarlo --vehicles 3,2 --seed 5 --beta 3000 --quiet --first 2 --count 3 --csv "$tmp/pb.csv"
expect_ok "merge: other seed" montecarlo --vehicles 3,2 --seed 6 --beta 2000 --quiet --first 2 --count 3 --csv "$tmp/ps.csv"
sed '2s/,solved,/,solvedx,/' "$tmp/p1.csv" >"$tmp/status.csv"
sed '3s/,[0-9]*$//' "$tmp/p1.csv" >"$tmp/fields.csv"
sed '2p' "$tmp/p1.csv" >"$tmp/twice.csv"
sed '$d' "$tmp/p1.csv" >"$tmp/cut.csv"
head -c -1 "$tmp/p1.csv" >"$tmp/newline.csv"
cut -d, -f1-16 "$tmp/p1.csv" >"$tmp/old.csv"
many=$(printf "$tmp/p1.csv,%.0s" $(seq 1025)); many=${many%,}
expect_bad "merge: overlap" "both hold encounter 0" montecarlo --merge "$tmp/p1.csv,$tmp/w.csv"
expect_bad "merge: gap" "no part holds encounters 2 to 2" montecarlo --merge "$tmp/p3.csv,$tmp/p1.csv"
expect_bad "merge: other beta" "pb.csv:2: beta 3000" montecarlo --merge "$tmp/p1.csv,$tmp/pb.csv"
expect_bad "merge: other seed" "ps.csv:2: seed" montecarlo --merge "$tmp/p1.csv,$tmp/ps.csv"
expect_bad "merge: fly and not" "fp1.csv:1: with --fly" montecarlo --merge "$tmp/p2.csv,$tmp/fp1.csv"
expect_bad "merge: missing file" "cannot read" montecarlo --merge "$tmp/p1.csv,$tmp/none.csv"
expect_bad "merge: status" "status.csv:2: status 'solvedx'" montecarlo --merge "$tmp/status.csv"
expect_bad "merge: fields" "fields.csv:3: not 23 fields" montecarlo --merge "$tmp/fields.csv"
expect_bad "merge: a row twice" "twice.csv:3: encounter 0 of 3 UAVs: a centralised row where decoupled_fixed" montecarlo --merge "$tmp/twice.csv"
expect_bad "merge: cut short" "encounter 1 of 2 UAVs: some of its rows only" montecarlo --merge "$tmp/cut.csv"
expect_bad "merge: no newline" "newline.csv:13: a line too long, or no newline" montecarlo --merge "$tmp/newline.csv"
expect_bad "merge: old CSV" "old.csv:1: no columns optimal to count" montecarlo --merge "$tmp/old.csv"
expect_bad "merge: not a CSV" "w.svg:1: not the header" montecarlo --merge "$tmp/w.svg"
expect_bad "merge: 1025 files" "--merge: 1 to 1024" montecarlo --merge "$many"
expect_bad "merge: empty entry" "--merge" montecarlo --merge "$tmp/p1.csv,,$tmp/p2.csv"
expect_bad "merge: with vehicles" "--merge: takes --svg and --json only" montecarlo --merge "$tmp/p1.csv" --vehicles 2
expect_bad "merge: with figure" "--merge: not with --figure-from" montecarlo --merge "$tmp/p1.csv" --figure-from "$tmp/fw.csv" --svg "$tmp/x.svg"
expect_bad "merge: svg a part" "--svg" montecarlo --merge "$tmp/p1.csv,$tmp/p2.csv" --svg "$tmp/p2.csv"
if [ "$(head -c 5 "$tmp/p2.csv")" = "seed," ]; then pass; else fail "merge: --svg overwrote a part"; fi

expect_bad "vehicles missing" "--vehicles: required" montecarlo --count 2
also="from 2 to 10"
expect_bad "vehicles 1" "--vehicles" montecarlo --vehicles 1
expect_bad "vehicles 11" "--vehicles" montecarlo --vehicles 2,11
expect_bad "vehicles empty entry" "--vehicles" montecarlo --vehicles 2,,3
expect_bad "vehicles trailing comma" "--vehicles" montecarlo --vehicles 2,
expect_bad "vehicles abc" "--vehicles" montecarlo --vehicles abc
also=
expect_bad "vehicles twice in the list" "listed twice" montecarlo --vehicles 3,2,3
expect_bad "vehicles given twice" "--vehicles" montecarlo --vehicles 2 --vehicles 3
expect_bad "vehicles no value" "--vehicles" montecarlo --vehicles
expect_bad "count 0" "--count" montecarlo --vehicles 2 --count 0
expect_bad "count huge" "--count" montecarlo --vehicles 2 --count 99999999999999999999
expect_bad "seed negative" "--seed" montecarlo --vehicles 2 --seed -1
expect_bad "first negative" "--first" montecarlo --vehicles 2 --first -1
expect_bad "first huge" "--first" montecarlo --vehicles 2 --first 1000000001
expect_bad "figure with first" "--figure-from" montecarlo --figure-from "$tmp/f0.csv" --svg "$tmp/g.svg" --first 2
expect_bad "beta 0" "--beta" montecarlo --vehicles 2 --beta 0
expect_bad "beta too large" "--beta" montecarlo --vehicles 5 --beta 4000000000
expect_bad "max orders 0" "--max-orders" montecarlo --vehicles 2 --max-orders 0
expect_bad "jobs 0" "--jobs" montecarlo --vehicles 2 --jobs 0
expect_bad "jobs 65" "--jobs" montecarlo --vehicles 2 --jobs 65
expect_bad "json value" "--json" montecarlo --vehicles 2 --json=yes
expect_bad "quiet value" "--quiet" montecarlo --vehicles 2 --quiet=1
expect_bad "csv unwritable" "--csv" montecarlo --vehicles 2 --csv "$tmp/none/x.csv"
expect_bad "csv empty" "--csv" montecarlo --vehicles 2 --csv=
expect_bad "svg unwritable" "--svg" montecarlo --vehicles 2 --svg "$tmp/none/x.svg"
expect_bad "svg same as csv" "--svg" montecarlo --vehicles 2 --csv "$tmp/x" --svg "$tmp/x"
expect_bad "save not a directory" "--save" montecarlo --vehicles 2 --save "$tmp/a.csv"
expect_bad "save missing" "--save" montecarlo --vehicles 2 --save "$tmp/none"
expect_bad "unknown option" "--bogus" montecarlo --vehicles 2 --bogus
expect_bad "argument" "'extra'" montecarlo --vehicles 2 extra

finish
