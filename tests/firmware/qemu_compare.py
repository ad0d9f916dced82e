#!/usr/bin/env python3
"""Compares the firmware check's results (its semihosting output, apps/firmware/check.c)
with the host's `coavoid plan` on the same scenarios, exactly.

Usage: qemu_compare.py FIRMWARE_OUTPUT COAVOID... -- SCENARIO.json...

For every scenario and every mode of its "qemu_modes", each host binary (double and
single precision) is run as `coavoid plan SCENARIO --mode MODE` (decoupled: the priority
order, one order) and must agree with the firmware on: the status, nodes expanded and
generated, the planning order, the failed vehicle, every offset of every planned vehicle,
the effort and the deviation in m^2 (the same double, bit for bit). The planner's exact
deviation_units, which `coavoid plan` does not print, is checked against the offsets:
sum_i W_i * S * A(a, b) over the planned vehicles' steps, computed here in rational
arithmetic from the contract (trajectory.h: w_i = fl(fl(v dt) fl(c dt)) = W_i 2^E, S the
lcm of 2 s_i). Prints one line per difference; exits 1 when anything differed.
"""
import json
import os
import struct
import subprocess
import sys
from fractions import Fraction
from math import lcm

STATUS = {0: "solved", 1: "infeasible", 2: "budget_exhausted"}


def parse(path):
    runs, offsets, errors = {}, {}, []
    done = False
    with open(path) as f:
        for raw in f:
            t = raw.split()
            if not t:
                continue
            if t[0] == "run":
                kv = dict(zip(t[3::2], t[4::2]))
                runs[(t[1], t[2])] = kv
            elif t[0] == "offsets":
                offsets.setdefault((t[1], t[2]), {})[int(t[3])] = [int(x) for x in t[4:]]
            elif t[0] == "error":
                errors.append(raw.strip())
            elif t[0] == "done":
                done = True
    return runs, offsets, errors, done


def area_scaled(a, b, scale):
    if a * b >= 0:
        return Fraction(abs(a) + abs(b), 2) * scale
    return Fraction(a * a + b * b, 2 * abs(a - b)) * scale


def two_adic(x):
    f = Fraction(x)
    e, n, d = 0, f.numerator, f.denominator
    while n % 2 == 0:
        n //= 2
        e += 1
    while d % 2 == 0:
        d //= 2
        e -= 1
    return e


def expected_units(scenario, rows):
    """The planner's deviation_units for the planned rows {id: offsets}."""
    dt = float(scenario["dt"])
    vs = scenario["vehicles"]
    w = {v["id"]: (float(v["cruise_speed"]) * dt) * (float(v["climb_rate"]) * dt) for v in vs}
    e = min(two_adic(x) for x in w.values())
    scale = lcm(*(2 * int(v.get("steep_factor", 2)) for v in vs))
    total = Fraction(0)
    for vid, row in rows.items():
        weight = Fraction(w[vid]) / Fraction(2) ** e
        total += weight * sum(area_scaled(a, b, scale) for a, b in zip(row, row[1:]))
    assert total.denominator == 1
    return int(total)


def main():
    argv = sys.argv[1:]
    if "--" not in argv or argv.index("--") < 2:
        sys.exit("usage: qemu_compare.py FIRMWARE_OUTPUT COAVOID... -- SCENARIO.json...")
    cut = argv.index("--")
    out, binaries, scenarios = argv[0], argv[1:cut], argv[cut + 1:]
    runs, fw_offsets, errors, done = parse(out)
    bad = []
    for e in errors:
        bad.append(f"firmware: {e}")
    if not done:
        bad.append("firmware: no 'done' line: the check did not run to its end")
    compared = 0
    for path in sorted(scenarios):
        name = os.path.splitext(os.path.basename(path))[0]
        with open(path) as f:
            scenario = json.load(f)
        for mode in scenario.get("qemu_modes", ["decoupled"]):
            fw = runs.get((name, mode))
            if fw is None:
                bad.append(f"{name} {mode}: the firmware reported no result")
                continue
            rows = fw_offsets.get((name, mode), {})
            where = f"{name} --mode {mode}"
            if fw["rc"] != "0":
                bad.append(f"{where}: firmware: the planner returned {fw['rc']}")
                continue
            units = int(fw["units"].replace(":", ""), 16)
            if units != expected_units(scenario, rows):
                bad.append(f"{where}: firmware: deviation_units {units} but its offsets give "
                           f"{expected_units(scenario, rows)}")
            for b in binaries:
                p = subprocess.run([b, "plan", path, "--mode", mode], capture_output=True,
                                   text=True)
                if p.returncode not in (0, 1) or not p.stdout.strip():
                    bad.append(f"{where}: host {b}: exit {p.returncode}: {p.stderr.strip()}")
                    continue
                h = json.loads(p.stdout)
                host_rows = {v["id"]: v["offsets"] for v in h.get("vehicles", [])}
                checks = [
                    ("status", STATUS.get(int(fw["status"]), fw["status"]), h["status"]),
                    ("nodes_expanded", int(fw["expanded"]), h["stats"]["nodes_expanded"]),
                    ("nodes_generated", int(fw["generated"]), h["stats"]["nodes_generated"]),
                    ("priority_order", [int(x) for x in fw["order"].split(",")],
                     h["priority_order"]),
                    ("failed_vehicle", None if fw["failed"] == "none" else int(fw["failed"]),
                     h.get("failed_vehicle")),
                    ("offsets", rows, host_rows),
                ]
                if h["status"] == "solved":
                    deviation = struct.unpack("<d", bytes.fromhex(fw["deviation_bits"])[::-1])[0]
                    checks += [("cost.effort", int(fw["effort"]), h["cost"]["effort"]),
                               ("cost.deviation", deviation.hex(),
                                float(h["cost"]["deviation"]).hex())]
                for what, got, want in checks:
                    if got != want:
                        bad.append(f"{where}: {what}: firmware {got} != host {want} ({b})")
                compared += 1
    for line in bad:
        print(f"firmware_qemu: DIFFERENT: {line}")
    print(f"firmware_qemu: {compared} comparisons (scenario x mode x host build), "
          f"{len(bad)} differences")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
