#!/usr/bin/env python3
"""Compares two hysid JSON reports number by number (exact equality of every leaf; timing
fields are skipped). Exit status 1 and the first differences when they differ.

Usage: compare_reports.py before.json after.json
"""
import json
import sys

SKIPPED = {"elapsed_s"}


def walk(a, b, path, out):
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            out.append((path, "keys", sorted(set(a) ^ set(b))))
            return 0
        return sum(walk(a[k], b[k], f"{path}.{k}", out) for k in a if k not in SKIPPED)
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append((path, "length", (len(a), len(b))))
            return 0
        return sum(walk(u, v, f"{path}[{i}]", out) for i, (u, v) in enumerate(zip(a, b)))
    if a != b:
        out.append((path, a, b))
    return 1


def main():
    before, after = (json.load(open(p)) for p in sys.argv[1:3])
    differences = []
    leaves = walk(before, after, "", differences)
    print(f"compared {leaves} leaves; {len(differences)} differ")
    for d in differences[:20]:
        print(*d)
    sys.exit(1 if differences else 0)


if __name__ == "__main__":
    main()
