#!/usr/bin/env python3
"""Cost against problem size: the 3D analytical-drum case at a ladder of pad meshes, with each
contact solve, a short run each (the static preload and a few dynamic increments).

For every level it records the equations and contact candidates (summary.json), the wall time
of the solver, its split into assembly, linear solves and contact solves, the Newton iterations
and increments, and the peak resident memory of the `skid run` process (from wait4). It fits
the exponent p of (time per Newton iteration) ~ n^p by least squares over the levels that
completed, per contact solve, and writes validation/scaling.md and validation/scaling.json.

Usage: scripts/scaling.py [--max-equations N] [--timeout S] [--methods reduced,global]
A run that takes longer than the timeout is stopped and recorded as such; larger levels of
that contact solve are then skipped.
"""

import argparse
import json
import math
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
DYNAMIC_INCREMENTS = 3
DT = 1e-4


def equations(mesh):
    """Unknowns of the pad (3 per node) plus the drum's and the plate's rigid motions, an
    estimate used to skip levels before running them."""
    c, r, a = mesh
    return 3 * (c + 1) * (r + 1) * (a + 1)


def run(mesh, method, timeout):
    """Runs one level; returns its record."""
    c, r, a = mesh
    out = Path(tempfile.mkdtemp(prefix="skid-scaling-"))
    sets = [f"pad.elements.circumferential={c}", f"pad.elements.radial={r}",
            f"pad.elements.axial={a}", f"steps[1].duration={DYNAMIC_INCREMENTS * DT}",
            f"steps[1].dt={DT}", f'solver.contact_solve="{method}"']
    cmd = [str(SKID), "run", str(CASE), "--out", str(out)]
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
                "contact_fallbacks", "wall_time_s", "assembly_s", "linear_solve_s",
                "contact_solve_s"):
        record[key] = summary.get(key)
    if record["newton_iterations"]:
        record["time_per_iteration_s"] = record["wall_time_s"] / record["newton_iterations"]
        record["time_per_increment_s"] = record["wall_time_s"] / record["increments"]
    return record


def fit(records):
    """Least-squares exponent of time per iteration against equations."""
    points = [(math.log(r["equations"]), math.log(r["time_per_iteration_s"]))
              for r in records if r.get("status") == "completed"
              and r.get("time_per_iteration_s")]
    if len(points) < 2:
        return None
    mx = sum(p[0] for p in points) / len(points)
    my = sum(p[1] for p in points) / len(points)
    sxx = sum((p[0] - mx) ** 2 for p in points)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in points)
    return sxy / sxx if sxx > 0 else None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max-equations", type=int, default=120_000)
    parser.add_argument("--timeout", type=float, default=600.0)
    parser.add_argument("--methods", default="reduced,global")
    parser.add_argument("--out", default=str(ROOT / "validation"))
    args = parser.parse_args()
    if not SKID.is_file():
        sys.exit(f"scaling: {SKID} not found; run cargo build --release first")
    records = []
    for method in args.methods.split(","):
        for mesh in MESHES:
            if equations(mesh) > args.max_equations:
                continue
            record = run(mesh, method, args.timeout)
            records.append(record)
            print(f"scaling: {method} {record['mesh']}: {record.get('status')}, "
                  f"{record.get('equations')} equations, {record.get('wall_time_s')} s, "
                  f"{record['peak_memory_mb']:.0f} MB", file=sys.stderr)
            if record.get("status") != "completed":
                break
    exponents = {m: fit([r for r in records if r["method"] == m])
                 for m in args.methods.split(",")}
    out = Path(args.out)
    (out / "scaling.json").write_text(json.dumps(
        {"records": records, "exponents": exponents}, indent=2) + "\n")
    lines = [
        "# Cost against problem size (`scripts/scaling.py`)", "",
        f"The 3D analytical-drum case (`{CASE.relative_to(ROOT)}`) at a ladder of pad meshes "
        f"(circumferential x radial x axial), each run with its 5-increment static preload and "
        f"{DYNAMIC_INCREMENTS} dynamic increments of {DT} s. Wall time: the solver's "
        "(summary.json); peak memory: the largest resident set of the `skid run` process.", "",
        "| contact solve | mesh | equations | contact candidates | status | increments | "
        "Newton iterations | wall [s] | per iteration [s] | per increment [s] | "
        "assembly / linear / contact [s] | peak memory [MB] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in records:
        def num(key, fmt="{:.4g}"):
            value = r.get(key)
            return fmt.format(value) if isinstance(value, (int, float)) else "n/a"
        split = " / ".join(num(k, "{:.3g}") for k in ("assembly_s", "linear_solve_s",
                                                       "contact_solve_s"))
        lines.append(
            f"| {r['method']} | {r['mesh']} | {num('equations', '{}')} | "
            f"{num('contact_candidates', '{}')} | {r.get('status')} | "
            f"{num('increments', '{}')} | {num('newton_iterations', '{}')} | "
            f"{num('wall_time_s')} | {num('time_per_iteration_s')} | "
            f"{num('time_per_increment_s')} | {split} | {num('peak_memory_mb', '{:.0f}')} |")
    lines.append("")
    for method, p in exponents.items():
        shown = "n/a (fewer than two completed levels)" if p is None else f"{p:.2f}"
        lines.append(f"- {method}: time per Newton iteration ~ n^p with p = {shown} "
                     "(least squares over the completed levels)")
    (out / "scaling.md").write_text("\n".join(lines) + "\n")
    return 0 if all(r.get("status") == "completed" for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
