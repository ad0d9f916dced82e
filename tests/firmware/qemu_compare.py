#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Compares the firmware check's results (its semihosting output, apps/firmware/check.c)
with the host's `coavoid plan` on the same scenarios, exactly.

Usage: qemu_compare.py FIRMWARE_OUTPUT DOUBLE_COAVOID SINGLE_COAVOID -- SCENARIO.json...

For every scenario and every mode of its "qemu_modes", each host binary (double and
single precision) is run as `coavoid plan SCENARIO --mode MODE` (decoupled: the priority
order, one order) and must agree with the firmware on: the status, nodes expanded and
generated, the planning order, the failed vehicle, every offset of every planned vehicle,
the effort and the deviation in m^2 (the same double, bit for bit). The planner's exact
deviation_units, which `coavoid plan` does not print, is checked against the offsets:
sum_i W_i * S * A(a, b) over the planned vehicles' steps, computed here in rational
arithmetic from the contract (trajectory.h: w_i = fl(fl(v dt) fl(c dt)) = W_i 2^E, S the
lcm of 2 s_i).

Predictions: `coavoid predict SCENARIO` (defaults) in each build must list the same
conflicts in the same order as the firmware's coa_predict: kind, a, b and first_step.
The real numbers (first_time, min_horizontal, min_vertical as floats, probability as a
double) must equal the single-precision build's bit for bit; the double build computes
them from unrounded positions, so only its conflict set is compared (as tests/precision
does). Prints one line per difference; exits 1 when anything differed.

Also prints the instructions each call executed on the emulated Cortex-M4F, when the
firmware was run under qemu -icount shift=0: its SysTick ticks times the ratio of its
calibration loop (a known instruction count over its ticks). Guest instructions, not
cycles or time (qemu is not cycle-accurate); printed, never compared.

Message checks (apps/firmware/check_crypto.c's `crypto` lines): the fleet tag and the
Ed25519 signature the firmware computed over its fixed datagrams must equal the host
libsodium's, bit for bit, the signature must verify and the changed datagram must not; the
drivers' own checks (src/auth/auth.c on the part) must stamp an intent, accept it and
refuse an outsider's copy by its tag (-126); an intent built, encoded (1,398 bytes) and
stamped on the part must come through a receiver's checks, decoder and conversion
(`crypto message-*` lines, apps/firmware/check_messages.c); their instructions are
printed as well.
"""
import ctypes
import ctypes.util
import functools
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
    predicts, conflicts = {}, {}
    crypto = []
    calibration = None
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
            elif t[0] == "calibrate":
                calibration = (int(t[1]), int(t[2]))
            elif t[0] == "predict":
                predicts[t[1]] = t[3]
                runs[(t[1], "predict")] = dict(zip(t[2::2], t[3::2]))
            elif t[0] == "conflict":
                conflicts.setdefault(t[1], []).append(t[2:])
            elif t[0] == "crypto":
                crypto.append(t[1:])
            elif t[0] == "error":
                errors.append(raw.strip())
            elif t[0] == "done":
                done = True
    return runs, offsets, errors, done, predicts, conflicts, calibration, crypto


@functools.lru_cache(maxsize=None)
def host_crypto(size):
    """The tag and signature check_crypto.c computes for a datagram of `size` bytes, by the
    host's libsodium: the same patterns (byte i of the datagram 7i + 3, of the key seed i,
    of the fleet key i + 16, each mod 256)."""
    na = ctypes.CDLL(ctypes.util.find_library("sodium") or "libsodium.so.23")
    if na.sodium_init() < 0:
        sys.exit("qemu_compare.py: sodium_init failed")
    pk, sk = ctypes.create_string_buffer(32), ctypes.create_string_buffer(64)
    na.crypto_sign_ed25519_seed_keypair(pk, sk, bytes(range(32)))
    signed = bytes((i * 7 + 3) & 0xFF for i in range(size - 72))
    signature = ctypes.create_string_buffer(64)
    na.crypto_sign_ed25519_detached(signature, None, signed, ctypes.c_ulonglong(len(signed)), sk)
    tagged = signed + signature.raw
    tag = ctypes.create_string_buffer(8)
    na.crypto_shorthash_siphash24(tag, tagged, ctypes.c_ulonglong(len(tagged)),
                                  bytes((i + 16) & 0xFF for i in range(16)))
    return {"tag": tag.raw.hex(), "sign": signature.raw.hex()}


def compare_crypto(crypto, bad):
    """Checks the firmware's crypto lines against the host; returns how many were compared."""
    want = {"tag": "hex", "sign": "hex", "verify": "0", "refuse": "-1", "stamp": "0",
            "check": "0", "outsider": "-126"}
    seen = {(t[0], t[1]) for t in crypto}
    want.update({"message-build": "0", "message-encode": "1398", "message-stamp": "0",
                 "message-receive": "0"})
    required = [(w, size) for w in ("tag", "sign", "verify", "refuse") for size in ("192", "1398")]
    required += [(w, "1398") for w in ("stamp", "check", "outsider")]
    required += [("message-" + w, "1398") for w in ("encode", "stamp", "receive")]
    required += [("message-build", "0")]
    for what, size in required:
        if (what, size) not in seen:
            bad.append(f"crypto {what} {size}: the firmware reported none")
    compared = 0
    for t in crypto:
        if t[0] == "memory":
            continue
        what, size, value = t[0], int(t[1]), t[2]
        if what in ("tag", "sign"):
            host = host_crypto(size)[what]
            if value != host:
                bad.append(f"crypto {what} {size}: firmware {value} != host libsodium {host}")
        elif what in want and t[3] != want[what]:
            bad.append(f"crypto {what} {size}: firmware rc {t[3]}, expected {want[what]}")
        compared += 1
    return compared


def print_crypto(crypto, per_tick):
    print(f"{'message check':14} {'bytes':>6} {'instructions':>13}")
    for t in crypto:
        if t[0] == "memory":
            print("memory on the part: " + " ".join(t[1:]) + " (bytes)")
            continue
        print(f"{t[0]:14} {t[1]:>6} {int(t[t.index('ticks') + 1]) * per_tick:13,.0f}")


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


def float_bits(x):
    return struct.pack(">f", x).hex()


def double_bits(x):
    return struct.pack(">d", x).hex()


def compare_predict(name, path, fw_rc, fw_conflicts, binary, single, bad):
    where = f"{name} predict"
    if fw_rc != "0":
        bad.append(f"{where}: firmware: coa_predict returned {fw_rc}")
        return
    p = subprocess.run([binary, "predict", path], capture_output=True, text=True)
    if p.returncode != 0:
        bad.append(f"{where}: host {binary}: exit {p.returncode}: {p.stderr.strip()}")
        return
    host = json.loads(p.stdout)["conflicts"]
    if len(host) != len(fw_conflicts):
        bad.append(f"{where}: firmware {len(fw_conflicts)} conflicts != host {len(host)} ({binary})")
        return
    for j, (f, h) in enumerate(zip(fw_conflicts, host)):
        kind, a, b, step, t, dh, dv, prob = f
        checks = [("kind", kind, h["kind"]), ("a", int(a), h["a"]), ("b", int(b), h["b"]),
                  ("first_step", int(step), h["first_step"])]
        if single:
            checks += [("first_time", t.zfill(16)[8:], float_bits(h["first_time"])),
                       ("min_horizontal", dh.zfill(16)[8:], float_bits(h["min_horizontal"])),
                       ("min_vertical", dv.zfill(16)[8:], float_bits(h["min_vertical"])),
                       ("probability", prob, double_bits(h["probability"]))]
        for what, got, want in checks:
            if got != want:
                bad.append(f"{where}: conflicts[{j}].{what}: firmware {got} != host {want} "
                           f"({binary})")


def main():
    argv = sys.argv[1:]
    if "--" not in argv or argv.index("--") != 3:
        sys.exit("usage: qemu_compare.py FIRMWARE_OUTPUT DOUBLE_COAVOID SINGLE_COAVOID -- "
                 "SCENARIO.json...")
    out, binaries, scenarios = argv[0], argv[1:3], argv[4:]
    runs, fw_offsets, errors, done, predicts, fw_conflicts, calibration, crypto = parse(out)
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
        if name not in predicts:
            bad.append(f"{name} predict: the firmware reported no prediction")
        else:
            for b, single in zip(binaries, (False, True)):
                compare_predict(name, path, predicts[name], fw_conflicts.get(name, []), b,
                                single, bad)
                compared += 1
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
    if calibration and calibration[1] > 0:
        per_tick = calibration[0] / calibration[1]
        print(f"== instructions on the emulated Cortex-M4F (qemu -icount shift=0: "
              f"{per_tick:.4f} instructions per SysTick tick, from {calibration[0]} "
              f"instructions in {calibration[1]} ticks; not cycles, not time)")
        print(f"{'scenario':10} {'call':12} {'expanded':>9} {'instructions':>13} "
              f"{'per expansion':>14}")
        for (name, mode), kv in sorted(runs.items()):
            if "ticks" not in kv:
                continue
            insns = int(kv["ticks"]) * per_tick
            expanded = int(kv.get("expanded", 0))
            per = f"{insns / expanded:14,.0f}" if expanded else f"{'-':>14}"
            print(f"{name:10} {mode:12} {expanded:9} {insns:13,.0f} {per}")
        print_crypto(crypto, per_tick)
    compared += compare_crypto(crypto, bad)
    for line in bad:
        print(f"firmware_qemu: DIFFERENT: {line}")
    print(f"firmware_qemu: {compared} comparisons (plans and predictions of each host build, "
          f"message checks), {len(bad)} differences")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
