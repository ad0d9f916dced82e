#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The exact answer that `coavoid predict` must give on a scenario whose sampled
positions are all exactly representable (random_scenarios.py --exact): for every pair of
UAVs, and every UAV and track without sigma, the first step that holds a conflict, by the
contract (docs/scenario-format.md: straight lines between samples, strict inequalities, an
exact touch is no conflict), in rational arithmetic.

Usage: exact_oracle.py COAVOID SCENARIO.json...
Runs `COAVOID predict` on each and compares the first_step of every UAV-UAV and UAV-track
pair (no sigma) with the exact one; prints one line per disagreement and a summary; exits
1 when any disagreed. Obstacles are left out (the box test has the same disc and slabs;
polytopes go through MPR, whose tolerance the contract allows).
"""
import json
import subprocess
import sys
from fractions import Fraction as F
from math import isqrt


def route_at(route, d):
    """The reference at horizontal distance d >= 0 along the route (exact for routes
    whose legs lie along the axes, which --exact scenarios have)."""
    start = F(0)
    for i in range(len(route) - 1):
        p0, p1 = route[i], route[i + 1]
        dx, dy = p1[0] - p0[0], p1[1] - p0[1]
        assert dx == 0 or dy == 0, "exact oracle: legs must lie along the axes"
        length = abs(dx) + abs(dy)
        if d < start + length or i == len(route) - 2:
            u = (d - start) / length
            return [p0[j] + u * (p1[j] - p0[j]) for j in range(3)]
        start += length
    raise AssertionError


def vehicle_samples(s, v):
    dt, n = F(s["dt"]), s["horizon"]
    route = [[F(c) for c in p] for p in v["route"]]
    dz = v.get("initial_offset", 0) * F(v["climb_rate"]) * dt
    out = []
    for k in range(n + 1):
        p = route_at(route, F(v["cruise_speed"]) * k * dt)
        out.append((p[0], p[1], p[2] + dz))
    return out


def track_samples(s, t):
    dt, n = F(s["dt"]), s["horizon"]
    p, v = [F(c) for c in t["position"]], [F(c) for c in t["velocity"]]
    return [tuple(p[j] + v[j] * k * dt for j in range(3)) for k in range(n + 1)]


def sqrt_bounds(x):
    """Rationals lo <= sqrt(x) <= hi, exact (lo == hi) when x is a perfect square."""
    num, den = x.numerator, x.denominator
    rn, rd = isqrt(num), isqrt(den)
    if rn * rn == num and rd * rd == den:
        r = F(rn, rd)
        return r, r
    scale = 10 ** 40
    r = isqrt(num * den * scale * scale)
    return F(r, den * scale), F(r + 1, den * scale)


def step_conflict(a0, a1, b0, b1, rsum, hsum):
    """Whether the open set of u where both volumes overlap meets [0, 1]."""
    q = [a0[j] - b0[j] for j in range(3)]
    w = [(a1[j] - b1[j]) - q[j] for j in range(3)]
    # Vertical: |q_z + u w_z| < hsum, an open interval (or all or nothing).
    if w[2] == 0:
        if not abs(q[2]) < hsum:
            return False
        vlo, vhi = None, None
    else:
        t1, t2 = (-hsum - q[2]) / w[2], (hsum - q[2]) / w[2]
        vlo, vhi = min(t1, t2), max(t1, t2)
    # Horizontal: a u^2 + 2 b u + c < 0.
    a = w[0] ** 2 + w[1] ** 2
    b = q[0] * w[0] + q[1] * w[1]
    c = q[0] ** 2 + q[1] ** 2 - rsum ** 2
    if a == 0:
        if not c < 0:
            return False
        hlo = hhi = None
    else:
        disc = b * b - a * c
        if disc <= 0:
            return False
        slo, shi = sqrt_bounds(disc)
        # Roots (-b -+ sqrt(disc)) / a, bracketed by rationals.
        hlo = ((-b - shi) / a, (-b - slo) / a)
        hhi = ((-b + slo) / a, (-b + shi) / a)
    # Ends as (lower, upper) rational brackets: exact when lower == upper; an irrational
    # root's bracket is 1e-40 wide and never holds a rational end of these sizes.
    lows, highs = [], []
    if vlo is not None:
        lows.append((vlo, vlo))
        highs.append((vhi, vhi))
    if hlo is not None:
        lows.append(hlo)
        highs.append(hhi)

    def less(x, y):
        if x[1] < y[0]:
            return True
        if x[0] >= y[1]:
            return False
        raise AssertionError("exact oracle: cannot separate two interval ends")

    # The open intervals meet each other and the closed step [0, 1] iff every lower end
    # is below every upper end, below 1, and every upper end is above 0.
    one, zero = (F(1), F(1)), (F(0), F(0))
    return (all(less(x, y) for x in lows for y in highs) and
            all(less(x, one) for x in lows) and all(less(zero, y) for y in highs))


def first_steps(s):
    vs = s["vehicles"]
    samples = {v["id"]: vehicle_samples(s, v) for v in vs}
    out = {}
    things = [(v, samples[v["id"]]) for v in vs]
    for i, (va, sa) in enumerate(things):
        others = [("vehicle", vb, sb) for vb, sb in things[i + 1:]]
        others += [("track", t, track_samples(s, t)) for t in s.get("tracks", [])
                   if "sigma" not in t]
        for kind, vb, sb in others:
            rsum = F(va["radius"]) + F(vb["radius"])
            hsum = F(va["half_height"]) + F(vb["half_height"])
            for k in range(s["horizon"]):
                if step_conflict(sa[k], sa[k + 1], sb[k], sb[k + 1], rsum, hsum):
                    a, b = va["id"], vb["id"]
                    out[(kind, min(a, b) if kind == "vehicle" else a,
                         max(a, b) if kind == "vehicle" else b)] = k
                    break
    return out


def reported_steps(s, result):
    """The first steps a `coavoid predict` result reports for the pairs first_steps
    covers (UAV pairs, and UAV-track pairs without sigma)."""
    exact_tracks = {t["id"] for t in s.get("tracks", []) if "sigma" not in t}
    return {(c["kind"], c["a"], c["b"]): c["first_step"] for c in result["conflicts"]
            if c["kind"] == "vehicle" or (c["kind"] == "track" and c["b"] in exact_tracks)}


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: exact_oracle.py COAVOID SCENARIO.json...")
    binary, files = sys.argv[1], sys.argv[2:]
    pairs = conflicts = bad = 0
    for path in files:
        with open(path) as f:
            s = json.load(f)
        want = first_steps(s)
        p = subprocess.run([binary, "predict", path], stdout=subprocess.PIPE, text=True,
                           check=False)
        got = reported_steps(s, json.loads(p.stdout))
        n = len(s["vehicles"])
        pairs += n * (n - 1) // 2 + n * sum(1 for t in s.get("tracks", []) if "sigma" not in t)
        conflicts += len(want)
        if got != want:
            bad += 1
            print(f"DIFF {path}: coavoid {sorted(got.items())} != exact {sorted(want.items())}")
    print(f"{len(files)} scenarios, {pairs} pairs, {conflicts} exact conflicts, "
          f"{bad} scenarios disagreed")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
