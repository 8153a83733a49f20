#!/usr/bin/env python3
"""Kill and resume, the long version of crates/skid-cli/tests/commands/kill_resume.rs.

For each case: an uninterrupted reference run, then KILLS runs killed with SIGKILL at random
moments over the run (start-up and output phase included), each resumed with
`skid run --resume` (the resumed runs killed again at random until one finishes), and every
output compared with the reference: history.csv, newton.csv and the field frames byte for
byte, summary.json with its wall times removed. A killed directory must hold no history.csv
that is not complete, and a summary.json only with the complete run.

usage: scripts/kill-resume.py [--kills N] [--restart-every N] [--seed S] [--out DIR]
                              [--set FIELD=VALUE ...] [CASE ...]
(default: the 2D and 3D analytical drums, 20 kills each, a restart every 10 increments; the
skid binary is target/release/skid, built first)
"""

import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKID = os.path.join(ROOT, "target", "release", "skid")
TIMING_KEYS = ("wall_time_s", "assembly_s", "linear_solve_s", "factorization_s",
               "contact_solve_s", "output_s", "peak_memory_mb")


def without_timings(value):
    """`value` without its TIMING_KEYS at any depth (the per-step costs hold wall times too)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def results(directory):
    """Every output file of a finished run by name; summary.json without its wall times."""
    out = {}
    for sub in ("", "fields"):
        folder = os.path.join(directory, sub)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            path = os.path.join(folder, name)
            key = os.path.join(sub, name) if sub else name
            if not os.path.isfile(path) or key == "restart.json":
                continue
            with open(path, "rb") as f:
                data = f.read()
            if key == "summary.json":
                data = json.dumps(without_timings(json.loads(data)), sort_keys=True).encode()
            out[key] = data
    return out


def check_killed(directory, rows):
    """What a killed run leaves: no incomplete history.csv and a whole restart file, or, if the
    kill landed after summary.json (written last) while the process exited, the complete run,
    which the comparison with the reference then checks. True if killed in the output phase."""
    if os.path.exists(os.path.join(directory, "summary.json")):
        return False
    restart = os.path.join(directory, "restart.json")
    if os.path.exists(restart):
        with open(restart) as f:
            json.load(f)
    history = os.path.join(directory, "history.csv")
    if os.path.exists(history):
        with open(history) as f:
            assert sum(1 for _ in f) == rows, f"{history} is not complete"
        return True
    return False


def run_until(command, delay):
    """Runs command, killed after delay seconds if still running; True if it was killed."""
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        _, err = child.communicate(timeout=delay)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        return True
    if child.returncode not in (0, 1):
        sys.exit(f"skid failed ({child.returncode}): {err.decode()}")
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("cases", nargs="*", default=["cases/drum/2d-analytic.json",
                                                     "cases/drum/3d-analytic.json"])
    parser.add_argument("--kills", type=int, default=20)
    parser.add_argument("--restart-every", type=int, default=10)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", default="out/kill-resume")
    parser.add_argument("--set", action="append", default=[], dest="overrides")
    args = parser.parse_args()
    subprocess.run(["cargo", "build", "--release", "-p", "skid-cli"], cwd=ROOT, check=True)
    rng = random.Random(args.seed)
    failures = 0
    for case in args.cases:
        name = os.path.splitext(os.path.basename(case))[0]
        base = os.path.join(args.out, name)
        shutil.rmtree(base, ignore_errors=True)
        command = [SKID, "run", case, "--restart-every", str(args.restart_every)]
        for s in args.overrides:
            command += ["--set", s]
        reference = os.path.join(base, "reference")
        started = time.monotonic()
        run_until(command + ["--out", reference], None)
        span = time.monotonic() - started
        expected = results(reference)
        rows = expected["history.csv"].count(b"\n")
        kills = in_output = trial = 0
        while kills < args.kills:
            directory = os.path.join(base, f"killed-{trial}")
            trial += 1
            if not run_until(command + ["--out", directory], 1.05 * span * rng.random()):
                continue
            kills += 1
            in_output += check_killed(directory, rows)
            if not os.path.exists(os.path.join(directory, "restart.json")):
                continue  # killed before its first restart point: nothing to resume
            while run_until([SKID, "run", "--resume", directory],
                            span * rng.random() if rng.random() < 0.5 else None):
                kills += 1
                in_output += check_killed(directory, rows)
            got = results(directory)
            if got != expected:
                failures += 1
                differ = sorted(k for k in set(got) | set(expected) if got.get(k) != expected.get(k))
                print(f"{name}: {directory}: differs from the reference in {differ}")
        print(f"{name}: {kills} kills ({in_output} in the output phase) over {trial} runs "
              f"of {span:.2f} s; {failures} resumed runs differ")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
