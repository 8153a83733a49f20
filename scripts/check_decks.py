"""Checks the deck runs of scripts/validate.sh against the case-file runs and prints a table.

Each deck of cases/inp written from a case file must stop within 1e-6 relative of its case
file's run (issue acceptance; they run to the same history, bit for bit). The hand-written 2D
deck states its coordinates as decimals, 1e-17 m from the generator's: the stop time moves by
such a perturbation by about 4e-5 relative (the pad's stick-slip vibration, DRUM.md 2.2), so it
must agree to 1e-3, the benchmark's tolerance between idealisations.

usage: check_decks.py DECK_RUNS CASE_RUNS
"""
import csv
import json
import sys
from pathlib import Path


def t_stop(history):
    """First zero crossing of the drum's omega, linearly interpolated (as summary.json)."""
    with open(history, newline="") as f:
        rows = list(csv.DictReader(f))
    column = next(c for c in rows[0] if c.endswith(".omega") and c.split(".")[0] in ("drum", "drum_ref"))
    w0 = float(rows[0][column]) or float(rows[-1][column])
    sign = 1.0 if w0 >= 0 else -1.0
    for a, b in zip(rows, rows[1:]):
        wa, wb = float(a[column]) * sign, float(b[column]) * sign
        if wa > 0 >= wb:
            ta, tb = float(a["time"]), float(b["time"])
            return ta + wa / (wa - wb) * (tb - ta)
    return None


def main(decks, cases):
    rows, ok = [], True
    for deck in sorted(Path(decks).iterdir()):
        if not (deck / "history.csv").exists():
            continue
        twin = "2d-analytic" if deck.name == "2d-analytic-by-hand" else deck.name
        tolerance = 1e-3 if deck.name == "2d-analytic-by-hand" else 1e-6
        reference = json.loads((Path(cases) / twin / "summary.json").read_text())["t_stop"]
        t = t_stop(deck / "history.csv")
        rel = abs(t - reference) / reference if t is not None and reference else None
        passed = rel is not None and rel <= tolerance
        ok &= passed
        rows.append((deck.name, twin, t, reference, rel, tolerance, passed))
    print("| deck | case file | t_stop deck, s | t_stop case, s | relative difference | tolerance | pass |")
    print("|---|---|---|---|---|---|---|")
    for name, twin, t, ref, rel, tol, passed in rows:
        print(f"| {name} | {twin} | {t} | {ref} | {rel:.2e} | {tol:g} | {'yes' if passed else 'NO'} |")
    if len(rows) < 9:
        print(f"expected 9 deck runs, found {len(rows)}")
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out/inp", sys.argv[2] if len(sys.argv) > 2 else "out/drum/runs"))
