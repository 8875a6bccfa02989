#!/usr/bin/env python3
"""Prints which top-level modules of src/ each module uses (code only, comments and doc links
ignored) and fails if two modules depend on each other through any chain. Run by .ci/run;
docs/architecture.md draws the layers it checks."""
import collections
import os
import re
import sys

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")
mods = sorted(
    m[:-3] if m.endswith(".rs") else m
    for m in os.listdir(root)
    if m not in ("lib.rs", "main.rs", "cli") and not m.startswith(".")
)
mods = [m for m in mods if m]
deps = collections.defaultdict(set)
for m in mods:
    path = os.path.join(root, m)
    files = [path + ".rs"] if os.path.exists(path + ".rs") else []
    if os.path.isdir(path):
        for dp, _, fs in os.walk(path):
            files += [os.path.join(dp, f) for f in fs if f.endswith(".rs")]
    for f in files:
        for line in open(f, encoding="utf-8"):
            code = line.split("//", 1)[0]
            for d in re.findall(r"crate::([a-z_]+)", code):
                if d != m and d in mods:
                    deps[m].add(d)


def reaches(a, b):
    seen, stack = set(), [a]
    while stack:
        x = stack.pop()
        for d in deps[x]:
            if d == b:
                return True
            if d not in seen:
                seen.add(d)
                stack.append(d)
    return False


for m in mods:
    print(f"{m:12} -> {', '.join(sorted(deps[m])) or '-'}")
cycles = sorted({tuple(sorted((a, b))) for a in mods for b in deps[a] if reaches(b, a)})
if cycles:
    print("import cycles:", ", ".join(f"{a} <-> {b}" for a, b in cycles))
    sys.exit(1)
print("no import cycles between top-level modules")
