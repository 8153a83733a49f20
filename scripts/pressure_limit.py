#!/usr/bin/env python3
"""The load at which each element formulation fails: the drum's pad under a ladder of back-plate
pressures, written to validation/pressure-limit.json and validation/pressure-limit.md.

Every run is the hard case cases/hard/<dim>-pressure-x10.json (10 x 1 (x 1) pad, analytical
drum, mu = 0.15, preload then a spin-down at dt = 1e-4 s for max(0.1, 0.15 / factor) s) with its pad's formulation and
its back-plate pressure overridden: pressure factors of the benchmark's 0.35 MPa from 1 to 20, the
four formulations (reduced: CPE4R / C3D8R, full: CPE4 / C3D8, hybrid: CPE4H / C3D8H,
incompatible: CPE4I / C3D8I) and the one-point element with the enhanced hourglass control
(enhanced: pad.hourglass = "enhanced"), 2D and 3D.

For every run: how it ended (completed, or the failure and the time it stopped at), and for a
completed run the physics, read from its history.csv as the hard-case report reads it:
- friction: the largest excess of the friction resultant over mu N (never positive beyond the
  solver's tolerance);
- momentum: the drum's angular momentum balance, max |I (omega - omega0) - sum h T| / (I omega0),
  T the contact torque at the end of each increment;
- energy: the run's energy balance error (summary.json);
- t_stop against the estimate I omega0 / (mu p A R).
A formulation's failure load is the smallest factor of the ladder at which its run fails.

Usage: scripts/pressure_limit.py [--skid PATH] [--factors F ...] [--formulations NAME ...]
  [--dimensions D ...] [--jobs N] [--timeout S]
  --skid: the skid binary (default target/release/skid, built if absent); --factors: pressure
  factors (default 1 2 3 4 5 6 8 10 12 15 20); --formulations: the rows to run (default all:
  reduced enhanced full hybrid incompatible); --dimensions: 2d, 3d or both (default); --jobs:
  parallel runs (default 2); --timeout: s per run (default 120). Only the full default ladder
  writes the validation files; a subset prints its tables. Exits 1 if a completed run breaks
  the friction or momentum law.
"""

import argparse
import concurrent.futures
import csv
import json
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BENCHMARK_PRESSURE = 0.35e6
# each row: the pad's overrides and its elements in 2D and 3D
FORMULATIONS = {
    "reduced": (['pad.formulation="reduced"'], ("CPE4R", "C3D8R")),
    "enhanced": (['pad.formulation="reduced"', 'pad.hourglass="enhanced"'],
                 ("CPE4R enhanced", "C3D8R enhanced")),
    "full": (['pad.formulation="full"'], ("CPE4", "C3D8")),
    "hybrid": (['pad.formulation="hybrid"'], ("CPE4H", "C3D8H")),
    "incompatible": (['pad.formulation="incompatible"'], ("CPE4I", "C3D8I")),
}
DEFAULT_FACTORS = [1, 2, 3, 4, 5, 6, 8, 10, 12, 15, 20]
# the limits of the hard-case report (crates/skid-report/src/hard.rs)
FRICTION_TOLERANCE = 1e-6
MOMENTUM_TOLERANCE = 1e-6


def physics(run_dir, case):
    """Friction excess (N, and relative to mu max N) and momentum residual of a run's history."""
    rows = list(csv.DictReader(open(run_dir / "history.csv")))
    mu = case["contact"]["mu"]
    inertia = case["drum"]["rotary_inertia"]
    omega0 = case["drum"]["omega0"]
    n_max = max(float(r["normal_force"]) for r in rows)
    excess = max(abs(float(r["friction_force"])) - mu * max(float(r["normal_force"]), 0.0)
                 for r in rows)
    # the dynamic part: from the last row before time first advances
    times = [float(r["time"]) for r in rows]
    start = next(k for k in range(len(times) - 1) if times[k + 1] > times[k])
    dynamic = rows[start:]
    impulse, worst = 0.0, 0.0
    w0 = float(dynamic[0]["drum_omega"])
    for a, b in zip(dynamic, dynamic[1:]):
        impulse += (float(b["time"]) - float(a["time"])) * float(b["friction_torque"])
        worst = max(worst, abs(inertia * (float(b["drum_omega"]) - w0) - impulse))
    return excess / (mu * n_max), worst / (inertia * abs(omega0))


def run(skid, dim, formulation, factor, work, timeout):
    base = ROOT / f"cases/hard/{dim}-pressure-x10.json"
    name = f"{dim}-{formulation}-x{factor:g}"
    out = work / name
    pad, elements = FORMULATIONS[formulation]
    sets = pad + [f"back_plate.pressure={factor * BENCHMARK_PRESSURE!r}",
            # to half the estimated stop time past it: 0.1 s from x 10, 0.15 s at x 1
            f"steps[1].duration={max(0.1, 0.15 / factor)!r}"]
    command = [skid, "run", str(base), "--out", str(out)]
    for s in sets:
        command += ["--set", s]
    record = {"dimension": dim, "formulation": formulation, "factor": factor,
              "element": elements[0 if dim == "2d" else 1]}
    try:
        proc = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        record.update(status="timeout")
        return record
    summary_file = out / "summary.json"
    if not summary_file.is_file():
        record.update(status="crashed", error=proc.stderr.strip()[-300:])
        return record
    summary = json.load(open(summary_file))
    record.update(status=summary["status"], error=summary.get("error"),
                  failure=summary.get("failure"), final_time=summary.get("final_time"),
                  t_stop=summary.get("t_stop"), increments=summary.get("increments"),
                  energy_balance_error=summary.get("energy_balance_error"),
                  wall_time_s=summary.get("wall_time_s"))
    if summary["status"] == "completed":
        case = json.load(open(out / "case.json"))
        area = case["pad"]["length"] * case["pad"]["width"]
        torque = case["contact"]["mu"] * case["back_plate"]["pressure"] * area * case["drum"]["radius"]
        t_est = case["drum"]["rotary_inertia"] * abs(case["drum"]["omega0"]) / torque
        friction, momentum = physics(out, case)
        record.update(friction_excess=friction, momentum_residual=momentum, t_stop_estimate=t_est)
    return record


def cell(r):
    if r["status"] == "completed":
        dev = "" if r.get("t_stop") is None else f", t_stop {100 * (r['t_stop'] / r['t_stop_estimate'] - 1):+.0f} %"
        return f"ok{dev}"
    if r["status"] == "failed":
        what = (r.get("failure") or "failed").replace("inverted element", "folds")
        time = r.get("final_time") or 0.0
        return f"{what} at {1e3 * time:.1f} ms" if time > 0.0 else f"{what} in the preload"
    return r["status"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skid", default=str(ROOT / "target/release/skid"))
    parser.add_argument("--factors", type=float, nargs="+", default=DEFAULT_FACTORS)
    parser.add_argument("--formulations", nargs="+", choices=list(FORMULATIONS),
                        default=list(FORMULATIONS))
    parser.add_argument("--dimensions", nargs="+", choices=["2d", "3d"], default=["2d", "3d"])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    if not Path(args.skid).exists():
        subprocess.run(["cargo", "build", "--release", "-p", "skid-cli"], cwd=ROOT, check=True)
    jobs = [(d, f, x) for d in args.dimensions for f in args.formulations for x in args.factors]
    with tempfile.TemporaryDirectory() as tmp, \
            concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        records = list(pool.map(
            lambda j: run(args.skid, *j, Path(tmp), args.timeout), jobs))
    broken = [r for r in records if r["status"] == "completed"
              and (r["friction_excess"] > FRICTION_TOLERANCE
                   or r["momentum_residual"] > MOMENTUM_TOLERANCE)]
    complete = (args.factors == DEFAULT_FACTORS and args.formulations == list(FORMULATIONS)
                and args.dimensions == ["2d", "3d"])
    if complete:
        (ROOT / "validation/pressure-limit.json").write_text(json.dumps(
            {"command": "scripts/pressure_limit.py", "factors": args.factors,
             "benchmark_pressure_pa": BENCHMARK_PRESSURE, "runs": records}, indent=1) + "\n")

    lines = ["# The load at which each element formulation fails", "",
             "Written by `scripts/pressure_limit.py` (see its header): the hard case "
             "`<dim>-pressure-x10` (10 x 1 (x 1) pad, mu = 0.15) with the back-plate pressure at "
             "the factor of the benchmark's 0.35 MPa in the column head, for each pad formulation. "
             "`ok`: completed, with its stop time against the instantaneous-sliding estimate "
             "I omega0 / (mu p A R); otherwise how and when the run stopped.", ""]
    for dim in args.dimensions:
        lines += [f"## {dim.upper()}", "",
                  "| element | fails from | " + " | ".join(f"x {x:g}" for x in args.factors) + " |",
                  "|---|---|" + "---|" * len(args.factors)]
        for formulation in args.formulations:
            row = [r for r in records if r["dimension"] == dim and r["formulation"] == formulation]
            first = next((r["factor"] for r in row if r["status"] != "completed"), None)
            limit = "none up to x {:g}".format(args.factors[-1]) if first is None else f"x {first:g}"
            lines.append(f"| {row[0]['element']} | {limit} | " + " | ".join(map(cell, row)) + " |")
        lines.append("")
    done = [r for r in records if r["status"] == "completed"]
    lines += ["## Physics of the completed runs", "",
              f"{len(done)} runs completed. Largest friction excess (|F_t| - mu N) / (mu max N): "
              f"{max((r['friction_excess'] for r in done), default=0.0):.2e} (limit {FRICTION_TOLERANCE:g}); "
              f"largest momentum residual |I (omega - omega0) - sum h T| / (I omega0): "
              f"{max((r['momentum_residual'] for r in done), default=0.0):.2e} (limit {MOMENTUM_TOLERANCE:g}); "
              f"largest energy balance error: "
              f"{100 * max((r['energy_balance_error'] or 0.0 for r in done), default=0.0):.3f} %.", ""]
    if broken:
        lines += ["**Broken:** " + ", ".join(f"{r['dimension']} {r['element']} x {r['factor']:g}"
                                             for r in broken), ""]
    if complete:
        (ROOT / "validation/pressure-limit.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 1 if broken else 0


if __name__ == "__main__":
    raise SystemExit(main())
