#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the dearest scenarios the input limits accept (docs/security.md cites their times).

  limits-24.json   10 UAVs (COA_MAX_CENTRALISED) converging over 24 steps, 256 polytopes
                   of 256 vertices along their routes and 64 tracks crossing them: every
                   table row touches items;
  limits-48.json   the same over 48 steps;
  limits-400.json  one polytope beside 10 UAVs over 400 steps with steep factor 10: the
                   tables grow towards the workspace bound with almost nothing in them.

Usage: limits_scenarios.py OUTDIR
Then: coavoid plan OUTDIR/limits-24.json --mode centralised  (and --work to change the budget)
"""
import json
import math
import os
import sys


def polytope(cx, cy, cz, r, n=256):
    """n points on a sphere (a golden-angle spiral): the hull keeps every vertex."""
    pts = []
    for i in range(n):
        z = 1.0 - 2.0 * (i + 0.5) / n
        ring = math.sqrt(1.0 - z * z)
        a = i * math.pi * (3.0 - math.sqrt(5.0))
        pts.append([round(cx + r * ring * math.cos(a), 3), round(cy + r * ring * math.sin(a), 3),
                    round(cz + r * z, 3)])
    return {"type": "polytope", "vertices": pts}


def vehicles(n, reach, steep=2):
    out = []
    for i in range(n):
        a = 2.0 * math.pi * i / n
        start = [reach * math.cos(a), reach * math.sin(a), 100.0]
        end = [-3.0 * reach * math.cos(a), -3.0 * reach * math.sin(a), 100.0]
        out.append({"id": i + 1, "priority": i + 1, "cruise_speed": 10.0, "climb_rate": 2.0,
                    "steep_factor": steep, "radius": 15.0, "half_height": 5.0,
                    "route": [[round(c, 3) for c in start], [round(c, 3) for c in end]]})
    return out


UAVS = 10  # COA_MAX_CENTRALISED: the most one centralised problem takes


def crowded(horizon):
    """Polytopes above and below every route, close enough that each row's box touches some."""
    vs = vehicles(UAVS, 10.0 * horizon / 2)
    obstacles = []
    per = (256 + UAVS - 1) // UAVS
    for j in range(256):
        v = vs[j % UAVS]
        s, e = v["route"]
        f = (j // UAVS + 0.5) / per
        x, y = s[0] + f * (e[0] - s[0]) / 2.0, s[1] + f * (e[1] - s[1]) / 2.0
        z = 100.0 + (40.0 if j % 2 else -40.0)
        obstacles.append(polytope(x, y, z, 8.0))
    tracks = []
    for j in range(64):
        a = 2.0 * math.pi * j / 64
        tracks.append({"id": j, "radius": 10.0, "half_height": 5.0,
                       "position": [300.0 * math.cos(a), 300.0 * math.sin(a), 150.0 + (j % 4) * 20.0],
                       "velocity": [-10.0 * math.cos(a), -10.0 * math.sin(a), 0.0]})
    return {"name": "input limits: %d UAVs, %d steps, 256 polytopes of 256 vertices, 64 tracks" % (UAVS, horizon),
            "dt": 1.0, "horizon": horizon, "vehicles": vs, "obstacles": obstacles, "tracks": tracks}


def long_steep():
    vs = vehicles(UAVS, 2000.0, steep=10)
    return {"name": "input limits: %d UAVs, 400 steps, steep factor 10, one polytope" % UAVS,
            "dt": 1.0, "horizon": 400, "vehicles": vs,
            "obstacles": [polytope(0.0, 0.0, 60.0, 8.0)]}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for name, s in (("limits-24", crowded(24)), ("limits-48", crowded(48)), ("limits-400", long_steep())):
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(s, f)


if __name__ == "__main__":
    main()
