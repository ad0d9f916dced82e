#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The layers of docs/design.md, checked on the sources, from the table itself.

Each file under src/, include/, apps/ and tests/ belongs to the layer whose "where" cell
names it (the longest match); a file no row names is a failure, so a new library cannot
go unchecked. Each #include is then resolved: a project header to its own layer, which
must be the file's or one of its "uses"; a system header to the words of "never uses"
(HEADERS below). Each src/ folder's CMakeLists.txt may link only its layers' targets.
Usage: check_layering.py SOURCE_TREE [DESIGN_MD]
"""
import os
import re
import sys

# What each word of "never uses" means as headers (docs/design.md says the same).
HEADERS = {
    "heap": {"stdlib.h", "malloc.h"},
    "stdio": {"stdio.h"},
    "threads": {"pthread.h", "threads.h"},
    "clocks": {"time.h", "sys/time.h"},
    "sockets": {"sys/socket.h", "netinet/in.h", "arpa/inet.h", "sys/un.h"},
    "random numbers": {"sodium.h", "sodium/randombytes.h", "sys/random.h"},
    "LCM": set(),  # every lcm/ header but the coders' lcm_coretypes.h: see is_lcm
}
EVERY_ABOVE = "every layer above"
# Generated at build time from lcmtypes/: the messaging layer's headers.
GENERATED = {"coavoid_lcmtypes/": "lcmtypes/", "lcm/lcm_coretypes.h": "lcmtypes/"}
# Libraries a src/ folder may link that are no layer of ours, and what they count as.
EXTERNAL_TARGETS = {"coavoid::liblcm": "LCM", "coavoid::sodium_arm": None}
SOURCE_DIRS = ("src", "include", "apps", "tests")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]')


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def words(cell):
    return [w.strip() for w in cell.split(",") if w.strip()]


def read_table(design):
    """The rows of the table under '## Layers', in order."""
    text = open(design, encoding="utf-8").read()
    section = text.split("\n## Layers\n", 1)[1].split("\n## ", 1)[0]
    lines = []
    for ln in section.splitlines():
        if ln.startswith("|"):
            lines.append(ln)
        elif lines:
            break  # the first table only
    head = cells(lines[0])
    want = ["layer", "where", "CMake target", "uses", "never uses"]
    if any(h not in head for h in want):
        sys.exit(f"{design}: the layer table lacks a column of {want}")
    rows = []
    for line in lines[2:]:
        c = dict(zip(head, cells(line)))
        rows.append({
            "name": c["layer"],
            "where": re.findall(r"`([^`]+)`", c["where"]),
            "targets": set(re.findall(r"`(coavoid[_:][:\w]*)`", c["CMake target"])),
            "uses": words(c["uses"]),
            "never": words(c["never uses"]),
        })
    return rows


def check_table(rows, design):
    """Uses name layers above; never uses are known words. Returns the failures."""
    bad, seen = [], []
    for row in rows:
        if row["uses"] == [EVERY_ABOVE]:
            row["uses"] = list(seen)
        for used in row["uses"]:
            if used not in seen:
                bad.append(f"{design}: layer '{row['name']}' uses '{used}', not a layer above it")
        for word in row["never"]:
            if word not in HEADERS:
                bad.append(f"{design}: layer '{row['name']}': 'never uses' {word!r} is not "
                           f"one of {sorted(HEADERS)}")
        seen.append(row["name"])
    return bad


def layer_of(rows, rel):
    best, length = None, -1
    for row in rows:
        for w in row["where"]:
            hit = rel == w or (w.endswith("/") and rel.startswith(w))
            if hit and len(w) > length:
                best, length = row, len(w)
    return best


def project_headers(src):
    found = {}
    for top in SOURCE_DIRS:
        for root, _, files in os.walk(os.path.join(src, top)):
            for f in files:
                if f.endswith(".h"):
                    found[f] = os.path.relpath(os.path.join(root, f), src)
    return found


def resolve(src, rel, inc, headers):
    """The project file an include names, or None for a system header."""
    for prefix, where in GENERATED.items():
        if inc.startswith(prefix):
            return where
    here = os.path.join(os.path.dirname(rel), inc)
    if os.path.isfile(os.path.join(src, here)):
        return os.path.normpath(here)
    if os.path.isfile(os.path.join(src, "include", inc)):
        return os.path.join("include", inc)
    if "/" not in inc and inc in headers:
        return headers[inc]
    return None


def is_lcm(inc):
    return inc.startswith("lcm/") and inc != "lcm/lcm_coretypes.h"


def check_include(rows, row, rel, inc, target):
    if target is not None:
        other = layer_of(rows, target)
        if other is None or other is row or other["name"] in row["uses"]:
            return None
        return f"{rel}: includes {inc}, of layer '{other['name']}', not one '{row['name']}' uses"
    for word in row["never"]:
        if inc in HEADERS.get(word, ()) or (word == "LCM" and is_lcm(inc)):
            return f"{rel}: includes {inc}: layer '{row['name']}' never uses {word}"
    return None


def source_files(src):
    for top in SOURCE_DIRS:
        for root, dirs, files in os.walk(os.path.join(src, top)):
            dirs.sort()
            for f in sorted(files):
                if f.endswith((".c", ".h")):
                    yield os.path.relpath(os.path.join(root, f), src)


def check_sources(src, rows):
    bad, count, headers = [], 0, project_headers(src)
    for rel in source_files(src):
        row = layer_of(rows, rel)
        if row is None:
            bad.append(f"{rel}: in no layer of the table")
            continue
        count += 1
        with open(os.path.join(src, rel), encoding="utf-8") as f:
            for line in f:
                m = INCLUDE.match(line)
                if m:
                    target = resolve(src, rel, m.group(1), headers)
                    fail = check_include(rows, row, rel, m.group(1), target)
                    if fail:
                        bad.append(fail)
    return bad, count


def target_name(token):
    """A library's one name: coavoid_lcm and its alias coavoid::lcm are coavoid::lcm."""
    return token.replace("coavoid_", "coavoid::", 1) if token.startswith("coavoid_") else token


def linked_targets(cmake_text):
    found = set()
    for call in re.findall(r"target_link_libraries\s*\(([^)]*)\)", cmake_text):
        for token in re.findall(r"\bcoavoid(?:::|_)\w+", call):
            found.add(target_name(token))
    return found


def check_links(src, rows):
    """Each src/ folder's links against the union of its rows' uses."""
    bad = []
    owner = {}  # a target may hold two layers (coavoid::auth: signatures and key files)
    for row in rows:
        for t in row["targets"]:
            owner.setdefault(target_name(t), set()).add(row["name"])
    for folder in sorted(os.listdir(os.path.join(src, "src"))):
        path = os.path.join(src, "src", folder, "CMakeLists.txt")
        if not os.path.isfile(path):
            continue
        mine = [r for r in rows if any(w.startswith(f"src/{folder}/") for w in r["where"])]
        allowed = {r["name"] for r in mine} | {u for r in mine for u in r["uses"]}
        never = {w for r in mine for w in r["never"]}
        for target in sorted(linked_targets(open(path, encoding="utf-8").read())):
            if target in EXTERNAL_TARGETS:
                word = EXTERNAL_TARGETS[target]
                if word in never:
                    bad.append(f"src/{folder}/CMakeLists.txt: links {target}, which is {word}")
            elif target not in owner:
                bad.append(f"src/{folder}/CMakeLists.txt: links {target}, in no layer's targets")
            elif not owner[target] & allowed:
                bad.append(f"src/{folder}/CMakeLists.txt: links {target}, of layer "
                           f"'{min(owner[target])}', not one it uses")
    return bad


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: check_layering.py SOURCE_TREE [DESIGN_MD]")
    src = sys.argv[1]
    design = sys.argv[2] if len(sys.argv) == 3 else os.path.join(src, "docs", "design.md")
    rows = read_table(design)
    bad = check_table(rows, design)
    found, count = check_sources(src, rows)
    bad += found + check_links(src, rows)
    for line in bad:
        print(line)
    if bad:
        print(f"layering: {len(bad)} finding(s) against the layers of {design}")
        return 1
    print(f"layering: {count} files in {len(rows)} layers keep to the table of {design}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
