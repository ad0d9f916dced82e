#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Builds the paper's illustrative encounter and checks it shows what the paper's figures do.

Three UAVs in the vertical plane y = 0 (ids: 1 red, 2 blue, 3 green):
  red   flies left to right low and must climb over a block of terrain;
  blue  flies directly above red, so red's climb forces blue to climb too;
  green flies right to left at an altitude between them and meets them over the terrain,
        where it cannot pass between them and must go around them.

The properties the paper's figures 1-4 illustrate (checked with `coavoid plan`):
  fig 1  centralised: solved; green manoeuvres around the pair;
  fig 2  decoupled red, blue, green: solved at the centralised cost;
  fig 3  decoupled green, red, blue: solved at a higher cost, green flies straight
         and red and blue both manoeuvre around it;
  fig 4  decoupled blue, green, red: red (planned last) cannot clear the terrain.

Usage: paper_scenario.py COAVOID [--write FILE] [--search]
  default: check the parameters below and print the outcome of every mode;
  --search: try a grid of parameters and print every set that shows all four figures.
"""
import itertools
import json
import subprocess
import sys
import tempfile

BASE = dict(dt=1.0, horizon=24, speed=10.0, climb_r=2.0, climb_g=3.0, radius=15.0,
            half_height=5.0, red_z=100.0, blue_sep=16.0, green_z=112.0, terrain=(100.0, 200.0),
            terrain_top=104.0, green_x=300.0)


def scenario(p):
    x0, x1 = p["terrain"]
    far = 2000.0
    veh = lambda i, prio, climb, z, xa, xb: {
        "id": i, "priority": prio, "cruise_speed": p["speed"], "climb_rate": climb,
        "steep_factor": 2, "radius": p["radius"], "half_height": p["half_height"],
        "route": [[xa, 0.0, z], [xb, 0.0, z]]}
    return {
        "name": "paper figure 1-4 encounter: red and blue over terrain, green head-on",
        "dt": p["dt"], "horizon": p["horizon"], "beta": 60000,
        "vehicles": [
            veh(1, 1, p["climb_r"], p["red_z"], 0.0, far),
            veh(2, 2, p["climb_r"], p["red_z"] + p["blue_sep"], 0.0, far),
            veh(3, 3, p["climb_g"], p["green_z"], p["green_x"], p["green_x"] - far),
        ],
        "obstacles": [{"type": "box", "min": [x0, -60.0, 0.0], "max": [x1, 60.0, p["terrain_top"]]}],
    }


def run(coavoid, path, *args):
    out = subprocess.run([coavoid, "plan", path, *args], capture_output=True, text=True)
    if out.returncode == 2:
        raise SystemExit(out.stderr)
    return json.loads(out.stdout)


def outcomes(coavoid, sc):
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(sc, f)
        path = f.name
    res = {"central": run(coavoid, path, "--mode", "centralised")}
    for name, order in (("fig2", "1,2,3"), ("fig3", "3,1,2"), ("fig4", "2,3,1")):
        res[name] = run(coavoid, path, "--mode", "decoupled", "--priority", order)
    return res


def cost(r):
    return (r["cost"]["deviation"], r["cost"]["effort"])


def moved(r, vid):
    return any(v["deviation"] > 0 for v in r["vehicles"] if v["id"] == vid)


def shows_paper(res):
    c, f2, f3, f4 = res["central"], res["fig2"], res["fig3"], res["fig4"]
    if c["status"] != "solved" or not moved(c, 3):
        return False
    if f2["status"] != "solved" or abs(cost(f2)[0] - cost(c)[0]) > 1e-9 or cost(f2)[1] != cost(c)[1]:
        return False
    if f3["status"] != "solved" or cost(f3) <= cost(c) or moved(f3, 3):
        return False
    return f4["status"] == "infeasible" and f4.get("failed_vehicle") == 1


def describe(res):
    for name in ("central", "fig2", "fig3", "fig4"):
        r = res[name]
        c = r.get("cost")
        print(f"{name:8s} {r['status']:17s} order={r['priority_order']} "
              f"cost={c} failed={r.get('failed_vehicle')} expanded={r['stats']['nodes_expanded']}")


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    coavoid = sys.argv[1]
    if "--search" in sys.argv:
        grid = itertools.product((14.0, 16.0, 18.0, 20.0), (106.0, 108.0, 110.0, 112.0, 114.0),
                                 (2.0, 3.0, 4.0), (20, 24))
        for sep, gz, gclimb, n in grid:
            p = dict(BASE, blue_sep=sep, green_z=gz, climb_g=gclimb, horizon=n)
            try:
                res = outcomes(coavoid, scenario(p))
            except SystemExit as e:
                print("skip", sep, gz, gclimb, n, e)
                continue
            ok = shows_paper(res)
            print(f"sep={sep} green_z={gz} green_climb={gclimb} N={n}: {'MATCH' if ok else '-'}",
                  flush=True)
            if ok:
                describe(res)
        return
    sc = scenario(BASE)
    if "--write" in sys.argv:
        with open(sys.argv[sys.argv.index("--write") + 1], "w") as f:
            json.dump(sc, f, indent=2)
            f.write("\n")
    res = outcomes(coavoid, sc)
    describe(res)
    print("shows the paper's four figures:", shows_paper(res))


if __name__ == "__main__":
    main()
