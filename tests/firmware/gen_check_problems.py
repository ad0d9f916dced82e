#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes apps/firmware/check_problems.h, the planning problems of the firmware check
(apps/firmware/check.c), from the scenario files tests/firmware/qemu/*.json, so that the
emulated firmware and the host's `coavoid plan` solve the same numbers.

Usage: gen_check_problems.py OUT.h SCENARIO.json...

Every real number must be exactly representable in float (the firmware's coa_real_t):
the host reads the JSON in double and its single-precision build rounds to float, the
firmware gets the float literal; only exact values make both the same number. Refused
otherwise. The scenario's "beta" is required (the firmware's buffer is fixed), and the
field "qemu_modes" (ignored by coavoid, as every field the format does not define) lists
the modes the firmware runs: "decoupled" (priority order, one order) and "centralised";
"qemu_planner_bytes", when given, the planner buffer the firmware plans it in (at most the
check's; the example firmware's is 32 KiB).
The header is committed; tests/firmware/qemu.sh regenerates it and fails when it differs.
"""
import json
import os
import struct
import sys


def real(x, where):
    x = float(x)
    if struct.unpack("<f", struct.pack("<f", x))[0] != x:
        sys.exit(f"gen_check_problems: {where}: {x!r} is not exactly representable in float")
    return repr(x) + "f"


def vec(p, where):
    return "{" + ", ".join(real(c, f"{where}[{i}]") for i, c in enumerate(p)) + "}"


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: gen_check_problems.py OUT.h SCENARIO.json...")
    out, files = sys.argv[1], sorted(sys.argv[2:])
    body = []
    table = []
    max_vehicles = max_tracks = max_horizon = 0
    for p, path in enumerate(files):
        name = os.path.splitext(os.path.basename(path))[0]
        with open(path) as f:
            s = json.load(f)
        w = name
        if "beta" not in s:
            sys.exit(f"gen_check_problems: {path}: needs a \"beta\" (the firmware's buffer is fixed)")
        modes = s.get("qemu_modes", ["decoupled"])
        planner_bytes = int(s.get("qemu_planner_bytes", 0))
        if not modes or any(m not in ("decoupled", "centralised") for m in modes):
            sys.exit(f"gen_check_problems: {path}: qemu_modes: decoupled and/or centralised")
        vs, obs, trs = s["vehicles"], s.get("obstacles", []), s.get("tracks", [])
        max_vehicles = max(max_vehicles, len(vs))
        max_tracks = max(max_tracks, len(trs))
        max_horizon = max(max_horizon, int(s["horizon"]))
        rows = []
        for i, v in enumerate(vs):
            body.append(f"static const coa_vec3_t p{p}_v{i}_route[] = {{\n    " +
                        ",\n    ".join(vec(q, f"{w}.vehicles[{i}].route[{k}]")
                                       for k, q in enumerate(v["route"])) + "};")
            rows.append(
                f"    {{.id = {int(v['id'])}u, .priority = {int(v['priority'])}u, "
                f".cruise_speed = {real(v['cruise_speed'], w)}, "
                f".climb_rate = {real(v['climb_rate'], w)}, "
                f".steep_factor = {int(v.get('steep_factor', 2))}u,\n"
                f"     .volume = {{{real(v['radius'], w)}, {real(v['half_height'], w)}}}, "
                f".route = p{p}_v{i}_route, .route_count = {len(v['route'])}u, "
                f".initial_offset = {int(v.get('initial_offset', 0))}, "
                f".max_offset = {int(v.get('max_offset', -1))}}}")
        body.append(f"static const coa_vehicle_t p{p}_vehicles[] = {{\n" + ",\n".join(rows) + "};")
        if obs:
            rows = []
            for j, o in enumerate(obs):
                if o["type"] == "box":
                    rows.append(f"    {{.kind = COA_OBSTACLE_BOX, .box = {{{vec(o['min'], w)}, "
                                f"{vec(o['max'], w)}}}}}")
                else:
                    body.append(f"static const coa_vec3_t p{p}_o{j}_vertices[] = {{\n    " +
                                ",\n    ".join(vec(q, f"{w}.obstacles[{j}]")
                                               for q in o["vertices"]) + "};")
                    rows.append(f"    {{.kind = COA_OBSTACLE_POLYTOPE, .polytope = "
                                f"{{p{p}_o{j}_vertices, {len(o['vertices'])}u}}}}")
            body.append(f"static const coa_obstacle_t p{p}_obstacles[] = {{\n" +
                        ",\n".join(rows) + "};")
        if trs:
            rows = []
            for j, t in enumerate(trs):
                sigma = t.get("sigma", [0, 0])
                common = (f"{{.id = {int(t['id'])}u, .volume = {{{real(t['radius'], w)}, "
                          f"{real(t['half_height'], w)}}},\n     ")
                if "path" in t:
                    body.append(f"static const coa_track_point_t p{p}_t{j}_path[] = {{\n    " +
                                ",\n    ".join(f"{{{real(q[0], w)}, {vec(q[1:], w)}}}"
                                               for q in t["path"]) + "};")
                    motion = (f".path = p{p}_t{j}_path, .path_count = {len(t['path'])}u")
                else:
                    motion = (f".position = {vec(t['position'], w)}, "
                              f".velocity = {vec(t['velocity'], w)}")
                rows.append(common + motion + f",\n     .sigma_horizontal = {real(sigma[0], w)}, "
                            f".sigma_vertical = {real(sigma[1], w)}}}")
            body.append(f"static const coa_track_t p{p}_tracks[] = {{\n" + ",\n".join(rows) + "};")
        table.append(
            f"    {{.name = \"{name}\", .dt = {real(s['dt'], w)}, .horizon = {int(s['horizon'])}u, "
            f".beta = {int(s['beta'])}u, .planner_bytes = {planner_bytes}u,\n"
            f"     .decoupled = {'true' if 'decoupled' in modes else 'false'}, "
            f".centralised = {'true' if 'centralised' in modes else 'false'},\n"
            f"     .vehicles = p{p}_vehicles, .vehicle_count = {len(vs)}u,\n"
            f"     .obstacles = {f'p{p}_obstacles' if obs else 'NULL'}, "
            f".obstacle_count = {len(obs)}u,\n"
            f"     .tracks = {f'p{p}_tracks' if trs else 'NULL'}, .track_count = {len(trs)}u}}")
    text = ("/* SPDX-License-Identifier: MIT */\n"
            "/* Generated by tests/firmware/gen_check_problems.py from the scenarios in\n"
            " * tests/firmware/qemu/: do not edit (tests/firmware/qemu.sh fails when it is stale). */\n"
            "#ifndef COAVOID_CHECK_PROBLEMS_H\n#define COAVOID_CHECK_PROBLEMS_H\n\n"
            f"#define FWC_MAX_VEHICLES {max_vehicles}u\n"
            f"#define FWC_MAX_TRACKS {max(max_tracks, 1)}u\n"
            f"#define FWC_MAX_HORIZON {max_horizon}u\n"
            f"#define FWC_PROBLEM_COUNT {len(files)}u\n\n" +
            "\n".join(body) +
            "\n\nstatic const fwc_problem_t fwc_problems[FWC_PROBLEM_COUNT] = {\n" +
            ",\n".join(table) + "};\n\n#endif /* COAVOID_CHECK_PROBLEMS_H */\n")
    with open(out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
