#!/usr/bin/env python3
"""Compares two trees of run directories (two `skid batch` or `skid run` outputs of the same
cases, e.g. before and after a refactoring) and says whether their results are identical.

Every file under either tree must exist in the other. JSON files (summary.json, restart.json,
batch.json, ...) are compared as values with the measurements of the machine left out: keys
that end in `_s`, and `peak_memory_mb`, `wall_time` and `timings`. Every other file (histories,
newton.csv, field frames, case.json) must be byte-identical. Exit status 0 if the trees agree,
1 with the differences listed otherwise.

Usage: scripts/compare_runs.py BEFORE AFTER

To check that a change leaves the results alone:
    git stash; cargo build --release -p skid-cli
    target/release/skid batch cases/drum cases/verification --out out/before
    git stash pop; cargo build --release -p skid-cli
    target/release/skid batch cases/drum cases/verification --out out/after
    scripts/compare_runs.py out/before out/after
"""

import json
import sys
from pathlib import Path

MACHINE_KEYS = {"peak_memory_mb", "wall_time", "timings"}


def results(value):
    """`value` without the measurements of the machine it ran on."""
    if isinstance(value, dict):
        return {
            k: results(v)
            for k, v in value.items()
            if not (k.endswith("_s") or k in MACHINE_KEYS)
        }
    if isinstance(value, list):
        return [results(v) for v in value]
    return value


def first_difference(a, b, path="$"):
    """The JSON path of the first place where `a` and `b` differ, or None."""
    if type(a) is not type(b):
        return path
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}.{k}"
            found = first_difference(a[k], b[k], f"{path}.{k}")
            if found:
                return found
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path} (length {len(a)} against {len(b)})"
        for i, (x, y) in enumerate(zip(a, b)):
            found = first_difference(x, y, f"{path}[{i}]")
            if found:
                return found
        return None
    return None if a == b else f"{path} ({a!r} against {b!r})"


def files(root):
    return {p.relative_to(root) for p in root.rglob("*") if p.is_file()}


def compare(before, after):
    """The differences between the trees, as lines."""
    found = []
    old, new = files(before), files(after)
    found += [f"only in {before}: {p}" for p in sorted(old - new)]
    found += [f"only in {after}: {p}" for p in sorted(new - old)]
    for p in sorted(old & new):
        a, b = (before / p).read_bytes(), (after / p).read_bytes()
        if a == b:
            continue
        if p.suffix == ".json":
            try:
                where = first_difference(results(json.loads(a)), results(json.loads(b)))
            except ValueError as e:
                found.append(f"{p}: not JSON ({e})")
                continue
            if where:
                found.append(f"{p}: differs at {where}")
        else:
            line = next(
                (i + 1 for i, (x, y) in enumerate(zip(a.splitlines(), b.splitlines())) if x != y),
                min(a.count(b"\n"), b.count(b"\n")) + 1,
            )
            found.append(f"{p}: differs from line {line}")
    return found


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().split("\n\n")[2], file=sys.stderr)
        return 2
    before, after = Path(argv[1]), Path(argv[2])
    for root in (before, after):
        if not root.is_dir():
            print(f"{root}: expected a directory of runs", file=sys.stderr)
            return 2
    differences = compare(before, after)
    for d in differences:
        print(d)
    count = len(files(before) | files(after))
    if differences:
        print(f"{len(differences)} of {count} files differ")
        return 1
    print(f"identical: {count} files (timings and memory left out)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
