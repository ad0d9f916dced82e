#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Single and double precision must give the same plans: runs both builds of coavoid on
each scenario and compares what they print.

Usage: compare.py [--exact] DOUBLE_COAVOID SINGLE_COAVOID SCENARIO.json...

Plans (`coavoid plan`, centralised, decoupled, and decoupled --reorder): the exit status
and the whole result must be equal, every field of it, numbers compared exactly, except
stats.time_us (a clock), stats.workspace_bytes (the planner's fixed header holds
per-step sweeps of coa_real_t, so it is smaller in float; see docs/library.md, "Precision"),
stats.workspace_touched_bytes (which counts that header) and stats.work (a table row is charged for the offsets whose band can reach an obstacle,
found with the build's arithmetic, so the counts may differ by a few units; stats.limit,
compared, says whether the budget stopped either run).

Predictions (`coavoid predict`): the exit status, the clusters and each conflict's kind,
a, b and first_step must be equal; the real numbers a conflict reports are measured on
positions rounded to the build's precision, so they may differ by rounding, within
    lengths and times: TOL_REL * S, S the scenario's scale (its largest coordinate or
                       distance travelled, at least 1 m or 1 s),
    probability:       2 * TOL_REL * S / sigma, sigma the smallest nonzero one-sigma of
                       the scenario (the probability's slope in a distance is below
                       1/sigma), and exactly equal when no sigma is involved (P = 1);
and a pair with uncertainty may be listed by one build only when its probability is
within that tolerance of the threshold.

With --exact (scenarios from random_scenarios.py --exact), the double build's predicted
conflict steps must also equal the exact ones (exact_oracle.py), so that agreeing is not
enough: both must be right.

The two builds run side by side (two processes at a time), which halves the wall time on
two cores. Prints one line per difference and a summary; exits 1 when anything differed.
"""
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import exact_oracle  # noqa: E402

IGNORED = {"time_us", "workspace_bytes", "workspace_touched_bytes", "work"}
MODES = (["--mode", "centralised"], ["--mode", "decoupled"],
         ["--mode", "decoupled", "--reorder"])
# 2^-14: float's unit roundoff is 2^-24, and a reported length passes through a few dozen
# roundings of numbers no larger than the scene (sampling, differences, a square root).
TOL_REL = 2.0 ** -14
THRESHOLD = 0.01  # coavoid predict's default


def run_both(double, single, args):
    """(exit status, parsed stdout or None, stderr) of each build, run concurrently."""
    procs = [subprocess.Popen([b] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for b in (double, single)]
    results = []
    for p in procs:
        out, err = p.communicate()
        results.append((p.returncode, json.loads(out) if out.strip() else None, err.strip()))
    return results


def strip(x):
    """x without the keys that may legitimately differ, at any depth."""
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in IGNORED}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x


def first_difference(a, b, path="$"):
    if type(a) is not type(b):
        return f"{path}: {a!r} != {b!r}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}.{k}: only in {'double' if k in a else 'single'}"
            d = first_difference(a[k], b[k], f"{path}.{k}")
            if d:
                return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: length {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}[{i}]")
            if d:
                return d
        return None
    return None if a == b else f"{path}: {a!r} != {b!r}"


def scale_and_sigma(scenario):
    """The scenario's length scale and its smallest nonzero one-sigma (None if none)."""
    s = 1.0
    reach = scenario["dt"] * scenario["horizon"]
    s = max(s, reach)

    def walk(x):
        nonlocal s
        if isinstance(x, (int, float)) and not isinstance(x, bool):
            s = max(s, abs(x))
        elif isinstance(x, list):
            for v in x:
                walk(v)

    for v in scenario.get("vehicles", []):
        walk(v.get("route", []))
        s = max(s, v.get("cruise_speed", 0) * reach, v.get("climb_rate", 0) * reach)
    for o in scenario.get("obstacles", []):
        walk([o.get("min", []), o.get("max", []), o.get("vertices", [])])
    sigmas = []
    for t in scenario.get("tracks", []):
        walk([t.get("position", []), t.get("path", [])])
        vel = t.get("velocity", [0, 0, 0])
        s = max(s, max(abs(c) for c in vel) * reach + max(abs(c) for c in
                                                            t.get("position", [0])))
        sigmas += [x for x in t.get("sigma", []) if x > 0]
    return s, (min(sigmas) if sigmas else None)


def compare_predict(d, s, scenario):
    """None when the two prediction results agree by the rule above, else the reason."""
    if s is None or d is None:
        return None if s == d else "one build printed nothing"
    if d["clusters"] != s["clusters"] or d["scenario"] != s["scenario"]:
        return f"clusters {d['clusters']} != {s['clusters']}"
    scale, sigma = scale_and_sigma(scenario)
    tol_len = TOL_REL * scale
    tol_p = 2.0 * tol_len / sigma if sigma else 0.0
    key = lambda c: (c["kind"], c["a"], c["b"])
    dc = {key(c): c for c in d["conflicts"]}
    sc = {key(c): c for c in s["conflicts"]}
    for k in set(dc) ^ set(sc):
        c = dc.get(k) or sc.get(k)
        if not (c["probability"] < 1.0 and abs(c["probability"] - THRESHOLD) <= tol_p):
            return f"conflict {k} only in {'double' if k in dc else 'single'}"
    for k in set(dc) & set(sc):
        a, b = dc[k], sc[k]
        if a["first_step"] != b["first_step"]:
            return f"conflict {k}: first_step {a['first_step']} != {b['first_step']}"
        for f in ("first_time", "min_horizontal", "min_vertical"):
            if abs(a[f] - b[f]) > tol_len:
                return f"conflict {k}: {f} {a[f]!r} != {b[f]!r} (tolerance {tol_len:.3g})"
        if abs(a["probability"] - b["probability"]) > tol_p:
            return (f"conflict {k}: probability {a['probability']!r} != "
                    f"{b['probability']!r} (tolerance {tol_p:.3g})")
        if set(a) != set(b):
            return f"conflict {k}: fields {sorted(a)} != {sorted(b)}"
    return None


def main():
    args = sys.argv[1:]
    exact = bool(args) and args[0] == "--exact"
    if exact:
        args = args[1:]
    if len(args) < 3:
        sys.exit("usage: compare.py [--exact] DOUBLE_COAVOID SINGLE_COAVOID SCENARIO.json...")
    double, single, files = args[0], args[1], args[2:]
    exact_conflicts = 0
    compared = 0
    differed = 0
    statuses = {}
    for path in files:
        with open(path) as f:
            scenario = json.load(f)
        for mode in MODES:
            args = ["plan", path] + mode
            (rd, od, ed), (rs, os_, es) = run_both(double, single, args)
            compared += 1
            what = f"{path} {' '.join(mode)}"
            status = od.get("status") if od else f"exit {rd}"
            statuses[status] = statuses.get(status, 0) + 1
            if rd != rs:
                diff = f"exit {rd} != {rs} ({ed or es})"
            elif rd == 2:
                diff = None if ed == es else f"error {ed!r} != {es!r}"
            else:
                diff = first_difference(strip(od), strip(os_))
            if diff:
                differed += 1
                print(f"DIFF plan {what}: {diff}")
        (rd, od, ed), (rs, os_, es) = run_both(double, single, ["predict", path])
        compared += 1
        diff = f"exit {rd} != {rs}" if rd != rs else compare_predict(od, os_, scenario)
        if diff:
            differed += 1
            print(f"DIFF predict {path}: {diff}")
        if exact and od is not None:
            want = exact_oracle.first_steps(scenario)
            got = exact_oracle.reported_steps(scenario, od)
            exact_conflicts += len(want)
            if got != want:
                differed += 1
                print(f"DIFF exact {path}: coavoid {sorted(got.items())} != "
                      f"exact {sorted(want.items())}")
    summary = ", ".join(f"{k} {v}" for k, v in sorted(statuses.items()))
    checked = f", {exact_conflicts} exact conflict steps checked" if exact else ""
    print(f"{len(files)} scenarios, {compared} results compared ({summary}){checked}, "
          f"{differed} differed")
    return 1 if differed else 0


if __name__ == "__main__":
    sys.exit(main())
