#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every function of src/ and apps/ is at most 80 lines, signature to closing brace (the
project's rule: a longer one says what it does in the names of the parts it should be split
into); in the vehicle protocol (src/protocol/), which an autopilot team reads and certifies,
at most 60, and each of its files at most 800 lines. Tests are exempt: a Check test body
lists its cases. Usage: check_function_length.py SRC
"""
import os
import re
import sys

LIMIT = 80
# The vehicle protocol's tighter limits: per function, and per file.
PROTOCOL = os.path.join("src", "protocol")
PROTOCOL_LIMIT = 60
PROTOCOL_FILE_LINES = 800


def functions(path):
    """(name, first line, length) of each function: a line that is just '{' opens one, the
    line that is just '}' closes it, and the signature starts at the last line before it
    that begins at column 0."""
    lines = open(path, encoding="utf-8").read().split("\n")
    for i, line in enumerate(lines):
        if line != "{":
            continue
        j = i - 1
        while j > 0 and "(" not in lines[j]:
            j -= 1
        while j > 0 and not re.match(r"[A-Za-z]", lines[j]):
            j -= 1
        end = i
        while end < len(lines) and lines[end] != "}":
            end += 1
        names = re.findall(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(", lines[j])
        yield (names[0] if names else "?"), j + 1, end - j + 1


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "."
    bad = 0
    count = 0
    for top in ("src", "apps"):
        for root, _, files in os.walk(os.path.join(src, top)):
            for f in sorted(files):
                if not f.endswith(".c"):
                    continue
                path = os.path.join(root, f)
                rel = os.path.relpath(path, src)
                limit = PROTOCOL_LIMIT if rel.startswith(PROTOCOL + os.sep) else LIMIT
                if limit == PROTOCOL_LIMIT:
                    lines = open(path, encoding="utf-8").read().count("\n")
                    if lines > PROTOCOL_FILE_LINES:
                        print(f"function_length: {rel} is {lines} lines "
                              f"(at most {PROTOCOL_FILE_LINES} in {PROTOCOL})", file=sys.stderr)
                        bad += 1
                for name, line, length in functions(path):
                    count += 1
                    if length > limit:
                        print(f"function_length: {rel}:{line}: {name} is {length} lines "
                              f"(at most {limit})", file=sys.stderr)
                        bad += 1
    if bad:
        print(f"function_length: {bad} of {count} functions are too long", file=sys.stderr)
        return 1
    print(f"function_length: {count} functions, all at most {LIMIT} lines "
          f"({PROTOCOL_LIMIT} in {PROTOCOL}, whose files are at most {PROTOCOL_FILE_LINES})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
