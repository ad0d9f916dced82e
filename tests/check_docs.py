#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The documents say what is true of the code now, and git keeps how it got there (the
project's rule). Fails, one line per finding (FILE:LINE: reason), on:

- a git commit id in any Markdown file of the tree (CHANGELOG.md included), or in a
  comment of the C sources and headers, LCM types, CMake, shell, awk and Python files
  under src, include, apps, tests, scripts, cmake and lcmtypes;
- a lab notebook's phrase in docs/*.md or README.md ("this stop", "second pass",
  "(issue N, continued)", "was X, now Y", "before issue N", ...);
- docs/evaluation.md or docs/benchmarks.md over 25,000 bytes: a reference, not a log.

A commit id is a token of 7-40 lowercase hex digits with at least one letter a-f and one
digit, not part of a longer word or number (so not 0x..., not a float's digits) and not a
known word such as ed25519; in a source file, a token that also appears in one of its
string literals (a test vector named in a comment) is not one. A token of 7-12 decimal
digits is one only when git, if the tree is a repository, knows it as a commit.

Usage: check_docs.py ROOT
"""
import os
import re
import subprocess
import sys

LIMIT_BYTES = 25000
REFERENCE_DOCS = ("docs/evaluation.md", "docs/benchmarks.md")
CODE_DIRS = ("src", "include", "apps", "tests", "scripts", "cmake", "lcmtypes")
C_LIKE = (".c", ".h", ".lcm")
HASH_COMMENTS = (".sh", ".py", ".cmake", ".awk")
NOT_IDS = {"ed25519", "x25519"}

HEX = re.compile(r"(?<![0-9A-Za-z_.])[0-9a-f]{7,40}(?![0-9A-Za-z_])")
DIGITS = re.compile(r"(?<![0-9A-Za-z_.,])[0-9]{7,12}(?![0-9A-Za-z_]|,[0-9])")
PHRASES = [
    (re.compile(r"\bthis stop\b", re.I), "lab notebook: 'this stop'"),
    (re.compile(r"\bprevious stop\b", re.I), "lab notebook: 'previous stop'"),
    (re.compile(r"\bsecond pass\b", re.I), "lab notebook: 'second pass'"),
    (re.compile(r"continued\)", re.I), "lab notebook: '(..., continued)'"),
    (re.compile(r"\bwas/now\b", re.I), "was/now narrative"),
    (re.compile(r"\bwas\b[^.;:()]{0,60},\s*now\b", re.I), "was/now narrative ('was X, now Y')"),
    (re.compile(r"\(was [^)]{1,40}\)", re.I), "was/now narrative ('(was X)')"),
    (re.compile(r"\b(before|after|since|until|at the end of) issue \d+", re.I),
     "history: names an issue as a point in time"),
    (re.compile(r"\b(before|after) this change\b", re.I), "history: 'before/after this change'"),
]


def is_commit_like(token):
    return (token not in NOT_IDS and re.search(r"[a-f]", token) is not None
            and re.search(r"[0-9]", token) is not None)


def skip_dir(name):
    return name.startswith((".", "build", "_install")) or name == "node_modules"


def markdown_files(root):
    for path, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not skip_dir(d))
        for f in sorted(files):
            if f.endswith(".md"):
                yield os.path.join(path, f)


def code_files(root):
    for top in CODE_DIRS:
        for path, dirs, files in os.walk(os.path.join(root, top)):
            dirs[:] = sorted(d for d in dirs if not skip_dir(d))
            for f in sorted(files):
                if f.endswith(C_LIKE + HASH_COMMENTS) or f == "CMakeLists.txt":
                    yield os.path.join(path, f)
    yield os.path.join(root, "CMakeLists.txt")


def c_parts(text):
    """(comments, strings): comments as (line, text) pairs, and the string literals' text."""
    comments, strings = [], []
    i, n, line = 0, len(text), 1
    while i < n:
        if text.startswith("/*", i) or text.startswith("//", i):
            end = text.find("*/", i + 2) + 2 if text[i + 1] == "*" else text.find("\n", i)
            end = n if end < 2 or end < i else end
            for k, part in enumerate(text[i:end].split("\n")):
                comments.append((line + k, part))
            line += text.count("\n", i, end)
            i = end
        elif text[i] in "\"'":
            j = i + 1
            while j < n and text[j] != text[i] and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            strings.append(text[i + 1:j])
            i = j + 1
        else:
            line += text[i] == "\n"
            i += 1
    return comments, strings


def hash_parts(text):
    """(comments, strings) of a shell, CMake, awk or Python file: '#' at a word's start
    outside quotes begins a comment; quoted text is a string."""
    comments, strings = [], []
    for number, line in enumerate(text.split("\n"), 1):
        quote, start = None, 0
        for k, c in enumerate(line):
            if quote:
                if c == quote:
                    strings.append(line[start:k])
                    quote = None
            elif c in "\"'":
                quote, start = c, k + 1
            elif c == "#" and (k == 0 or line[k - 1].isspace()):
                comments.append((number, line[k:]))
                break
    return comments, strings


def known_commits(root, tokens):
    """The decimal tokens git knows as commits (none when ROOT is not a repository)."""
    if not tokens:
        return set()
    try:
        out = subprocess.run(["git", "-C", root, "cat-file", "--batch-check"],
                             input="\n".join(sorted(tokens)) + "\n", capture_output=True,
                             text=True, timeout=60, check=False).stdout
    except (OSError, subprocess.SubprocessError):
        return set()
    found = set()
    for token, answer in zip(sorted(tokens), out.splitlines()):
        if answer.split()[1:2] == ["commit"]:
            found.add(token)
    return found


def scan(root):
    findings = []  # (path, line, reason)
    decimal = []   # (path, line, token): commits only if git says so

    def ids(path, number, text, strings=()):
        for m in HEX.finditer(text):
            if is_commit_like(m.group()) and not any(m.group() in s for s in strings):
                findings.append((path, number, "a commit id: " + m.group()))
        for m in DIGITS.finditer(text):
            decimal.append((path, number, m.group()))

    for path in markdown_files(root):
        rel = os.path.relpath(path, root)
        lines = open(path, encoding="utf-8").read().split("\n")
        phrases = rel == "README.md" or (rel.startswith("docs" + os.sep) and rel.count(os.sep) == 1)
        for number, text in enumerate(lines, 1):
            ids(rel, number, text)
            for pattern, reason in PHRASES if phrases else ():
                if pattern.search(text):
                    findings.append((rel, number, reason))
    for path in code_files(root):
        if not os.path.isfile(path):
            continue
        rel = os.path.relpath(path, root)
        text = open(path, encoding="utf-8", errors="replace").read()
        comments, strings = c_parts(text) if path.endswith(C_LIKE) else hash_parts(text)
        for number, comment in comments:
            ids(rel, number, comment, strings)
    commits = known_commits(root, {t for _, _, t in decimal})
    findings += [(p, n, "a commit id: " + t) for p, n, t in decimal if t in commits]
    for rel in REFERENCE_DOCS:
        path = os.path.join(root, rel)
        if os.path.isfile(path) and os.path.getsize(path) > LIMIT_BYTES:
            findings.append((rel, 1, "%d bytes, over %d: a reference, not a log"
                             % (os.path.getsize(path), LIMIT_BYTES)))
    return findings


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: check_docs.py ROOT\n")
        return 2
    findings = scan(sys.argv[1])
    for path, number, reason in sorted(set(findings)):
        print("%s:%d: %s" % (path, number, reason))
    if findings:
        return 1
    print("doc_history: no commit ids, no lab notebook's phrases; the reference docs within "
          "%d bytes" % LIMIT_BYTES)
    return 0


if __name__ == "__main__":
    sys.exit(main())
