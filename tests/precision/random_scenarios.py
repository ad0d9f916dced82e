#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Seeded random encounters built to make float and double disagree if they can.

Usage: random_scenarios.py [--exact] SEED COUNT OUTDIR
Writes OUTDIR/random_<seed>_<i>.json, i = 0..COUNT-1; the same seed writes the same files.

--exact: only routes whose sampled positions are exactly representable in float (legs
along the axes, 2^j m long; so every position the core computes from them is exact in
both precisions), the case where single and double precision must plan identically and
where exact_oracle.py knows the right answer. Without it, routes also run along
directions whose samples round (their lengths or fractions are not dyadic), where the two
precisions may legitimately decide a touch differently (docs/library.md, "Precision").

Every number written is a multiple of 1/8 below 2^16 in magnitude (so exactly the same
value in float and in double), and the encounters are aimed at the edges of the conflict
test, where one rounding can turn "touching" (no conflict, by the contract) into
"overlapping": UAVs and tracks whose protected volumes meet exactly, or 1/8 m either side
of that, horizontally, vertically or both; boxes whose faces are exactly a radius or a
half-height from a route; routes along the axes, along exact Pythagorean directions
(3-4-5, 5-12-13, 8-15-17) and along directions whose lengths are irrational; legs whose
lengths are powers of two (sampled exactly) and legs that are not.
"""
import json
import os
import random
import sys

Q = 8  # coordinates are multiples of 1/Q m


def q(x):
    return round(x * Q) / Q


# Unit directions given as integer vectors; the last ones have irrational lengths.
DIRECTIONS = [(1, 0), (0, 1), (-1, 0), (0, -1), (3, 4), (-4, 3), (5, -12), (8, 15),
              (1, 1), (-1, 2), (2, -3)]


def near(rng, exact):
    """exact, or 1/Q either side of it: the touching case and its two neighbours."""
    return exact + rng.choice((0.0, 0.0, 0.0, -1.0 / Q, 1.0 / Q))


def vehicle(rng, vid, centre, t_meet, dt, horizon, lead, exact):
    """A UAV at `centre` at time t_meet (lead is None), or passing the lead UAV there at
    a distance that makes their protected volumes touch, or nearly, or anything."""
    speed = rng.choice((8.0, 10.0, 12.5, 16.0))
    climb = rng.choice((1.0, 2.0, 2.5))
    radius = rng.choice((5.0, 7.5, 10.0))
    half = rng.choice((2.0, 2.5, 4.0))
    dx, dy = rng.choice(DIRECTIONS[:4] if exact else DIRECTIONS)
    norm = (dx * dx + dy * dy) ** 0.5
    ux, uy = dx / norm, dy / norm
    lateral = along = vertical = 0.0
    if lead is not None:
        rsum = radius + lead["radius"]
        hsum = half + lead["half_height"]
        # Across the lead's position at t_meet: abreast at exactly rsum, or at a 3-4-5
        # displacement of length rsum (so the touch is at a sample instant, off the axes).
        pick = rng.randrange(4)
        if pick == 0:
            lateral = near(rng, rsum)
        elif pick == 1:
            lateral, along = near(rng, 0.6 * rsum), 0.8 * rsum
        elif pick == 2:
            lateral, along = 0.8 * rsum, near(rng, 0.6 * rsum)
        else:
            lateral = rng.uniform(-30, 30)
        lateral *= rng.choice((-1, 1))
        vertical = rng.choice((0.0, near(rng, hsum), near(rng, hsum + climb * dt),
                               rng.uniform(-12, 12))) * rng.choice((-1, 1))
    travelled = speed * t_meet
    sx = centre[0] - ux * (travelled - along) - uy * lateral
    sy = centre[1] - uy * (travelled - along) + ux * lateral
    z = centre[2] + vertical
    # A first leg of 2^j m is sampled exactly (the fraction along it is exact); otherwise
    # the leg ends where the direction vector lands on the grid.
    reach = speed * dt * horizon * 1.5
    if exact or rng.random() < 0.5:
        length = rng.choice((128.0, 256.0, 1024.0))
        ex, ey = sx + ux * length, sy + uy * length
    else:
        k = int(reach / norm) + 1
        ex, ey = sx + dx * k, sy + dy * k
    start = [q(sx), q(sy), q(z)]
    climb_by = rng.choice((0.0, 0.0, rng.randint(-2, 2) * 8.0 if exact else q(rng.uniform(-20, 20))))
    end = [q(ex), q(ey), q(z + climb_by)]
    route = [start, end]
    if rng.random() < 0.3:
        # A dog-leg beyond the first leg's end (in exact mode, a right angle of 2^9 m).
        if exact:
            route.append([end[0] - uy * 512.0, end[1] + ux * 512.0, end[2]])
        else:
            route.append([q(end[0] + rng.uniform(-200, 200)),
                          q(end[1] + rng.uniform(-200, 200)), end[2]])
    v = {"id": vid, "priority": rng.randint(1, 3), "cruise_speed": speed,
         "climb_rate": climb, "steep_factor": rng.choice((2, 3)), "radius": radius,
         "half_height": half, "route": route}
    if rng.random() < 0.2:
        v["initial_offset"] = rng.choice((-1, 1))
    if rng.random() < 0.3:
        v["max_offset"] = rng.randint(max(2, abs(v.get("initial_offset", 0))), 6)
    return v


def obstacle(rng, v):
    """A box or polytope whose face lies exactly (or 1/8 m off) a protected size away."""
    (x0, y0, z0), (x1, y1, _) = v["route"][0], v["route"][1]
    r, h = v["radius"], v["half_height"]
    mx, my = q((x0 + x1) / 2), q((y0 + y1) / 2)
    if rng.random() < 0.7:
        top = near(rng, z0 - h)
        return {"type": "box", "min": [mx - 40, my - 40, q(top - 50)],
                "max": [mx + 40, my + 40, q(top)]}
    apex = near(rng, z0 - h)
    return {"type": "polytope",
            "vertices": [[mx - 60, my - 60, q(apex - 80)], [mx + 60, my - 60, q(apex - 80)],
                         [mx + 60, my + 60, q(apex - 80)], [mx - 60, my + 60, q(apex - 80)],
                         [mx, my, q(apex)]]}


def track(rng, centre, t_meet, v):
    dx, dy = rng.choice(DIRECTIONS[:8])
    norm = (dx * dx + dy * dy) ** 0.5
    speed = rng.choice((5.0, 10.0, 20.0))
    vx, vy = q(dx / norm * speed), q(dy / norm * speed)
    radius, half = rng.choice((5.0, 10.0)), rng.choice((2.0, 4.0))
    dz = rng.choice((0.0, near(rng, half + v["half_height"])))
    t = {"id": 900 + rng.randint(0, 99), "radius": radius, "half_height": half,
         "position": [q(centre[0] - vx * t_meet), q(centre[1] - vy * t_meet),
                      q(centre[2] + dz)],
         "velocity": [vx, vy, 0.0]}
    if rng.random() < 0.3:
        t["sigma"] = [rng.choice((1.0, 2.5, 5.0)), rng.choice((0.5, 1.0, 2.0))]
    return t


def scenario(rng, name, exact):
    dt = rng.choice((0.5, 1.0, 1.0, 2.0))
    horizon = rng.randint(8, 14)
    n = rng.choice((1, 2, 2, 3, 3))
    centre = [q(rng.uniform(-500, 500)), q(rng.uniform(-500, 500)), q(rng.uniform(50, 300))]
    t_meet = dt * rng.randint(2, horizon - 2)
    vehicles = [vehicle(rng, 1, centre, t_meet, dt, horizon, None, exact)]
    for i in range(1, n):
        vehicles.append(vehicle(rng, i + 1, centre, t_meet, dt, horizon, vehicles[0], exact))
    s = {"name": name, "dt": dt, "horizon": horizon, "beta": 4000, "vehicles": vehicles}
    if n == 1 or rng.random() < 0.3:
        s["obstacles"] = [obstacle(rng, rng.choice(vehicles))]
    if n == 1 or rng.random() < 0.25:
        tr = track(rng, centre, t_meet, vehicles[0])
        tr["id"] = 900 + n  # distinct from the UAVs' ids
        s["tracks"] = [tr]
    return s


def main():
    args = sys.argv[1:]
    exact = bool(args) and args[0] == "--exact"
    if exact:
        args = args[1:]
    if len(args) != 3:
        sys.exit("usage: random_scenarios.py [--exact] SEED COUNT OUTDIR")
    seed, count, outdir = int(args[0]), int(args[1]), args[2]
    rng = random.Random(seed)
    os.makedirs(outdir, exist_ok=True)
    for i in range(count):
        name = f"random_{seed}_{i}"
        with open(os.path.join(outdir, name + ".json"), "w") as f:
            json.dump(scenario(rng, name, exact), f)
            f.write("\n")


if __name__ == "__main__":
    main()
