#!/usr/bin/env python3
"""Cost against problem size: the 3D analytical-drum case at a ladder of pad meshes, with each
contact solve, each level run once (the static preload, then a few dynamic increments); the
cost of a dynamic increment is the dynamic step's own wall time (summary.json, `steps`) over its
increments, so the preload is not counted.

For every level it records the equations and contact candidates (summary.json), the wall time,
the dynamic increment's cost in time, Newton iterations and factorizations, and the peak
resident memory of the run's process (from wait4); it writes validation/scaling.json,
then `skid report --scaling` renders validation/scaling.md with the fitted exponents and the
plots scaling.svg and scaling-memory.svg.

Usage: scripts/scaling.py [--min-equations N] [--max-equations N] [--reduced-max-equations N]
                          [--timeout S] [--methods reduced,global] [--threads N] [--out DIR]
                          [--update]
With --update, the levels run replace those of the same mesh and contact solve in the existing
scaling.json, and the others are kept.
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
DYNAMIC_INCREMENTS = 4
DT = 1e-4


def equations(mesh):
    """Unknowns of the pad (3 per node) plus the drum's and the plate's rigid motions, an
    estimate used to skip levels before running them."""
    c, r, a = mesh
    return 3 * (c + 1) * (r + 1) * (a + 1)


def parse_mesh(text):
    """The (circumferential, radial, axial) element counts of a record's "c x r x a"."""
    return tuple(int(n) for n in text.split(" x "))


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
                "assembly_s", "linear_solve_s", "contact_solve_s", "steps"):
        record[key] = summary.get(key)
    return record


def run(mesh, method, threads, timeout):
    """Runs one level; returns its record with the cost of a dynamic increment taken from the
    dynamic step's own record."""
    record = run_once(mesh, method, DYNAMIC_INCREMENTS, threads, timeout)
    if record.get("status") != "completed":
        return record
    step = record.pop("steps", [])[-1:]
    if not step or step[0]["increments"] <= 0:
        record["status"] = "no dynamic increments in the run"
        return record
    step = step[0]
    increments = step["increments"]
    record["dynamic_increment_s"] = step["wall_time_s"] / increments
    record["dynamic_iteration_s"] = step["wall_time_s"] / max(step["newton_iterations"], 1)
    record["dynamic_newton_per_increment"] = step["newton_iterations"] / increments
    record["dynamic_factorizations_per_increment"] = step["factorizations"] / increments
    record["dynamic_krylov_per_increment"] = step["krylov_iterations"] / increments
    return record


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--min-equations", type=int, default=0)
    parser.add_argument("--max-equations", type=int, default=120_000)
    parser.add_argument("--reduced-max-equations", type=int, default=25_000,
                        help="the reduced path's dense Delassus operator beyond this is slow")
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--methods", default="reduced,global")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--out", default=str(ROOT / "validation"))
    parser.add_argument("--update", action="store_true",
                        help="keep the records of scaling.json for the levels not run")
    args = parser.parse_args()
    if not SKID.is_file():
        sys.exit(f"scaling: {SKID} not found; run cargo build --release first")
    records = []
    for method in args.methods.split(","):
        limit = args.reduced_max_equations if method == "reduced" else args.max_equations
        for mesh in MESHES:
            if not args.min_equations <= equations(mesh) <= min(limit, args.max_equations):
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
    if args.update and (out / "scaling.json").is_file():
        earlier = json.loads((out / "scaling.json").read_text())
        if (earlier.get("threads"), earlier.get("dynamic_increments")) != (
                args.threads, DYNAMIC_INCREMENTS):
            sys.exit(f"scaling: --update at --threads {args.threads} with {DYNAMIC_INCREMENTS} "
                     f"dynamic increments, but the existing records were measured at "
                     f"{earlier.get('threads')} threads with "
                     f"{earlier.get('dynamic_increments')}")
        run_now = {(r["mesh"], r["method"]) for r in records}
        kept = [r for r in earlier["records"] if (r["mesh"], r["method"]) not in run_now]
        records = sorted(kept + records, key=lambda r: (r["method"] != "reduced",
                                                        equations(parse_mesh(r["mesh"]))))
    study = {"case": str(CASE.relative_to(ROOT)), "dt": DT, "threads": args.threads,
             "dynamic_increments": DYNAMIC_INCREMENTS, "records": records}
    (out / "scaling.json").write_text(json.dumps(study, indent=2) + "\n")
    # the report names the paths it is given: relative to the repository where they lie in it
    full = out.resolve()
    shown = Path(os.path.relpath(full, ROOT)) if full.is_relative_to(ROOT) else full
    report = subprocess.run([str(SKID.resolve()), "report", "--scaling",
                             str(shown / "scaling.json"), "--out", str(shown / "scaling.md")],
                            cwd=ROOT)
    if report.returncode != 0:
        return report.returncode
    return 0 if all(r.get("status") == "completed" for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
