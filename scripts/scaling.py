#!/usr/bin/env python3
"""Cost against problem size: the 3D analytical-drum case at a ladder of pad meshes, with each
contact solve, each level run twice (the static preload and a few dynamic increments, then
the same with more), so that the cost of a dynamic increment is the difference of the two wall
times over the difference of their increments and the preload is not counted.

For every level it records the equations and contact candidates (summary.json), the wall time,
the dynamic increment's cost in time, Newton iterations and factorizations, and the peak
resident memory of the longer run's process (from wait4); it writes validation/scaling.json,
then `skid report --scaling` renders validation/scaling.md with the fitted exponents and the
plots scaling.svg and scaling-memory.svg.

Usage: scripts/scaling.py [--max-equations N] [--reduced-max-equations N] [--timeout S]
                          [--methods reduced,global] [--threads N] [--out DIR]
A run that takes longer than the timeout is stopped and recorded as such; larger levels of
that contact solve are then skipped.
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SKID = Path(os.environ.get("SKID", ROOT / "target" / "release" / "skid"))
CASE = ROOT / "cases" / "drum" / "3d-analytic.json"
# circumferential x radial x axial elements: from the benchmark pad to about 1e5 equations
MESHES = [(10, 1, 1), (20, 2, 2), (20, 4, 4), (40, 4, 4), (40, 8, 8), (60, 8, 12),
          (80, 12, 16), (100, 16, 20)]
DYNAMIC_INCREMENTS = (2, 6)
DT = 1e-4


def equations(mesh):
    """Unknowns of the pad (3 per node) plus the drum's and the plate's rigid motions, an
    estimate used to skip levels before running them."""
    c, r, a = mesh
    return 3 * (c + 1) * (r + 1) * (a + 1)


def run_once(mesh, method, increments, threads, timeout):
    """Runs one level with `increments` dynamic increments; returns its record."""
    c, r, a = mesh
    out = Path(tempfile.mkdtemp(prefix="skid-scaling-"))
    sets = [f"pad.elements.circumferential={c}", f"pad.elements.radial={r}",
            f"pad.elements.axial={a}", f"steps[1].duration={increments * DT}",
            f"steps[1].dt={DT}", f'solver.contact_solve="{method}"']
    cmd = [str(SKID), "--threads", str(threads), "run", str(CASE), "--out", str(out),
           "--restart-every", "0"]
    for s in sets:
        cmd += ["--set", s]
    record = {"mesh": f"{c} x {r} x {a}", "method": method}
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    deadline = start + timeout
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid != 0:
            break
        if time.monotonic() > deadline:
            proc.send_signal(signal.SIGKILL)
            pid, status, usage = os.wait4(proc.pid, 0)
            record["status"] = f"stopped after {timeout:.0f} s"
            record["peak_memory_mb"] = usage.ru_maxrss / 1024.0
            return record
        time.sleep(0.05)
    record["process_wall_s"] = time.monotonic() - start
    record["peak_memory_mb"] = usage.ru_maxrss / 1024.0
    line = proc.stdout.read().decode().strip() if proc.stdout else ""
    try:
        summary = json.loads(line)
    except json.JSONDecodeError:
        record["status"] = f"no summary (exit status {os.waitstatus_to_exitcode(status)})"
        return record
    for key in ("status", "equations", "contact_candidates", "increments", "newton_iterations",
                "contact_fallbacks", "tangent_factorizations", "lu_factorizations",
                "preconditioner_factorizations", "krylov_iterations", "wall_time_s",
                "assembly_s", "linear_solve_s", "contact_solve_s"):
        record[key] = summary.get(key)
    return record


FACTORIZATIONS = ("tangent_factorizations", "lu_factorizations", "preconditioner_factorizations")


def run(mesh, method, threads, timeout):
    """Runs one level twice (DYNAMIC_INCREMENTS); returns the longer run's record with the
    cost of a dynamic increment from the difference of the two."""
    short = run_once(mesh, method, DYNAMIC_INCREMENTS[0], threads, timeout)
    if short.get("status") != "completed":
        return short
    record = run_once(mesh, method, DYNAMIC_INCREMENTS[1], threads, timeout)
    if record.get("status") != "completed":
        return record
    steps = record["increments"] - short["increments"]
    if steps <= 0:
        record["status"] = "no dynamic increments between the two runs"
        return record
    difference = lambda key: record[key] - short[key]
    iterations = difference("newton_iterations")
    record["dynamic_increment_s"] = difference("wall_time_s") / steps
    record["dynamic_iteration_s"] = difference("wall_time_s") / max(iterations, 1)
    record["dynamic_newton_per_increment"] = iterations / steps
    record["dynamic_factorizations_per_increment"] = sum(
        difference(k) for k in FACTORIZATIONS) / steps
    return record


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max-equations", type=int, default=120_000)
    parser.add_argument("--reduced-max-equations", type=int, default=25_000,
                        help="the reduced path's dense Delassus operator beyond this is slow")
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--methods", default="reduced,global")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--out", default=str(ROOT / "validation"))
    args = parser.parse_args()
    if not SKID.is_file():
        sys.exit(f"scaling: {SKID} not found; run cargo build --release first")
    records = []
    for method in args.methods.split(","):
        limit = args.reduced_max_equations if method == "reduced" else args.max_equations
        for mesh in MESHES:
            if equations(mesh) > min(limit, args.max_equations):
                continue
            record = run(mesh, method, args.threads, args.timeout)
            records.append(record)
            print(f"scaling: {method} {record['mesh']}: {record.get('status')}, "
                  f"{record.get('equations')} equations, "
                  f"{record.get('dynamic_increment_s')} s per dynamic increment, "
                  f"{record['peak_memory_mb']:.0f} MB", file=sys.stderr)
            if record.get("status") != "completed":
                break
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    study = {"case": str(CASE.relative_to(ROOT)), "dt": DT, "threads": args.threads,
             "dynamic_increments": list(DYNAMIC_INCREMENTS), "records": records}
    (out / "scaling.json").write_text(json.dumps(study, indent=2) + "\n")
    report = subprocess.run([str(SKID), "report", "--scaling", str(out / "scaling.json"),
                             "--out", str(out / "scaling.md")])
    if report.returncode != 0:
        return report.returncode
    return 0 if all(r.get("status") == "completed" for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
