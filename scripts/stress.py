#!/usr/bin/env python3
"""Stress sweep of the solver: a seeded random sweep of short `skid run`s over the parameters of
the drum cases (cases/drum/*.json, 2D and 3D) and the verification scenes of a block on a
sliding ground (cases/verification/*-block-on-sliding-ground.json, model files).

Each run draws its scene and parameters from its own generator, seeded by (seed, run index), so
any one run can be repeated alone (`--only K`) without the others:

- friction `mu` in [0, 2] (exactly 0 in one run in ten),
- pressure log-uniform in [1e3, 1e7] Pa (the back plate's, or the block's top load),
- time step log-uniform in [1e-6, 1e-2] s, and a short dynamic step of a few such steps,
- initial speed of either sign (drum `omega0`, log-uniform 0.1 to 300 rad/s; the ground's
  velocity, 0.01 to 10 m/s; zero in one run in twenty),
- pad meshes up to 40 x 8 x 8 (circumferential x radial x axial; for the block: along the
  sliding direction x through the thickness x across), big meshes rare and given the fewest
  increments,
- and, for coverage, the HHT alpha, the number of preload increments, the contact solve
  (auto, global, reduced) and, in one run in ten, the conic Coulomb method.

Every run is classified as
- completed: exit status 0; its outputs are then checked (see `check_completed`); a completed
  run that fails a check is *silently wrong*; one that passes them with a warning in its
  summary (the time integration removed much of the energy) is *warned*,
- failed: exit status 1 (the run stopped early; its summary says why) or 2 (input refused),
  with a message on stderr,
- crashed: killed by a signal, a panic ("panicked" on stderr), an exit status other than
  0, 1 or 2, or a failure without a message,
- timeout: stopped after `--timeout` seconds.

Writes validation/stress.json (every run) and validation/stress.md (summary). Exits 1 if any run
crashed or is silently wrong, 0 otherwise.

Usage: scripts/stress.py [--runs N] [--seed S] [--jobs J] [--out DIR] [--keep] [--only K]
                         [--timeout S] [--results DIR]
The binary is target/release/skid (build it with `cargo build --release -p skid-cli`), or $SKID.
"""

import argparse
import concurrent.futures
import csv
import json
import math
import os
import random
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SKID = Path(os.environ.get("SKID", ROOT / "target" / "release" / "skid"))
DRUM_CASES = sorted((ROOT / "cases" / "drum").glob("*.json"))
# The verification scenes of a block on a sliding ground: the sweep varies their pressure
# (loads[0]), ground velocity and second (dynamic) step. The other scenes have neither that
# load nor that step (a block pushed on a flat or an incline: one step; Hertz: no ground
# velocity), so the sweep leaves them out rather than refuse its own overrides.
VERIFICATION = sorted((ROOT / "cases" / "verification").glob("*-block-on-sliding-ground.json"))

# Share of the runs given to the verification scenes (the rest go to the drum cases).
VERIFICATION_SHARE = 0.3

# Mesh tiers: (probability, dynamic increments at most, drum 3D ranges (circ, radial, axial)).
# A big mesh costs up to a few seconds per increment, so it gets few of them.
TIERS = [
    ("small", 0.68, 40, ((1, 12), (1, 2), (1, 2))),
    ("medium", 0.27, 10, ((4, 40), (1, 4), (1, 4))),
    ("large", 0.05, 3, ((20, 40), (4, 8), (4, 8))),
]

# A converged increment has force residual <= the solver's force_tolerance and contact residual
# <= its contact_tolerance (relative to the model size). The sweep does not change them; each
# run's are read from its input as run (case.json or model.json, `solver`), so that the check
# follows the solver's defaults.

# Checks of a completed run. The contact law is exact at convergence up to the Newton contact
# tolerance (1e-8 of the model size by default) and the Coulomb tolerance (1e-8); the
# thresholds leave a margin of 100 above them, so that a flagged run is wrong, not rounded.
PENETRATION_LIMIT = 1e-6      # deepest penetration, relative to the scene's length scale
SEPARATION_LIMIT = 1e-6       # largest gap at a contact at the cone's boundary, same scale
CONE_RELATIVE = 1e-6          # |friction force| <= mu N (1 + this) + CONE_ABSOLUTE max N
CONE_ABSOLUTE = 1e-8          # also: N >= -CONE_ABSOLUTE max N (no adhesion)
ENERGY_LIMIT = 0.05           # energy balance error (relative) at most 5 %
DURATION_RELATIVE = 1e-5      # the dynamic step's increments add up to its duration

# Length scales: the drum radius; the block's size (its diagonal in the plane, 0.02 m).
BLOCK_LENGTH = 0.02


def sig(x, digits=4):
    """`x` rounded to `digits` significant digits (keeps the command lines short)."""
    if x == 0:
        return 0.0
    return float(f"{x:.{digits - 1}e}")


def log_uniform(rng, lo, hi):
    return sig(10 ** rng.uniform(math.log10(lo), math.log10(hi)))


def draw_mesh(rng, dimension):
    """A pad mesh (circumferential, radial, axial) and its tier."""
    u = rng.random()
    for name, p, max_dynamic, ranges in TIERS:
        if u < p:
            break
        u -= p
    c, r, a = (rng.randint(lo, hi) for lo, hi in ranges)
    if dimension == 2:
        # 2D is cheap: let the radial count reach 8 in every tier but the smallest.
        if name != "small":
            r = rng.randint(1, 8)
        a = 1
    return name, max_dynamic, (c, r, a)


def common(rng):
    """Parameters every scene shares."""
    mu = 0.0 if rng.random() < 0.1 else sig(rng.uniform(0.0, 2.0))
    speed = 0.0
    if rng.random() >= 0.05:
        speed = rng.choice([-1.0, 1.0])
    return {
        "mu": mu,
        "pressure": log_uniform(rng, 1e3, 1e7),
        "dt": log_uniform(rng, 1e-6, 1e-2),
        "speed_sign": speed,
        "alpha": sig(rng.uniform(-1.0 / 3.0 + 1e-9, 0.0), 3),
        "static_increments": rng.randint(1, 5),
        "contact_solve": rng.choices(["auto", "global", "reduced"], [0.6, 0.2, 0.2])[0],
        "coulomb_method": "conic" if rng.random() < 0.1 else "newton_first",
    }


def draw(seed, index):
    """The scene and parameters of run `index`: independent of every other run."""
    rng = random.Random(f"skid-stress:{seed}:{index}")
    if rng.random() < VERIFICATION_SHARE:
        path = rng.choice(VERIFICATION)
        kind = "verification"
    else:
        path = rng.choice(DRUM_CASES)
        kind = "drum"
    doc = json.loads(path.read_text())
    dimension = doc["dimension"]
    p = common(rng)
    tier, max_dynamic, mesh = draw_mesh(rng, dimension)
    p["tier"] = tier
    p["dynamic_increments"] = rng.randint(1, max_dynamic)
    p["duration"] = p["dt"] * p["dynamic_increments"]
    if kind == "drum":
        p["speed"] = p.pop("speed_sign") * log_uniform(rng, 0.1, 300.0)
        p["mesh"] = list(mesh[:dimension])
    else:
        p["speed"] = p.pop("speed_sign") * log_uniform(rng, 0.01, 10.0)
        if tier == "small" and rng.random() < 0.5:
            p["mesh"] = None  # the file's own mesh
        else:
            p["mesh"] = list(mesh[:dimension])
    return {
        "index": index,
        "scene": path.stem,
        "kind": kind,
        "dimension": dimension,
        "file": str(path.relative_to(ROOT)),
        "params": p,
    }


def overrides(run):
    """The `--set` overrides of a run."""
    p = run["params"]
    sets = []
    solver = [f'solver.contact_solve="{p["contact_solve"]}"',
              f'solver.coulomb_method="{p["coulomb_method"]}"']
    steps = [f"steps[0].increments={p['static_increments']}",
             f"steps[1].dt={p['dt']!r}",
             f"steps[1].duration={p['duration']!r}",
             f"steps[1].alpha={p['alpha']!r}"]
    if run["kind"] == "drum":
        sets += [f"contact.mu={p['mu']!r}",
                 f"back_plate.pressure={p['pressure']!r}",
                 f"drum.omega0={p['speed']!r}"]
        names = ["circumferential", "radial", "axial"]
        sets += [f"pad.elements.{n}={k}" for n, k in zip(names, p["mesh"])]
    else:
        # The ground moves along x only (its other translations are fixed).
        velocity = [p["speed"]] + [0.0] * (run["dimension"] - 1)
        sets += [f"contact[0].mu={p['mu']!r}",
                 f"loads[0].pressure={p['pressure']!r}",
                 "rigid_bodies[0].initial_velocity=" + json.dumps(velocity)]
    return sets + steps + solver


def block_mesh(doc, counts):
    """Replaces the block of a verification model by an nx x ny (x nz) mesh of the same box,
    with the node sets `bottom`, `top` and the surface `top` the file's own mesh has."""
    part = doc["part"]
    nodes = part["nodes"]
    lo = [min(n[k] for n in nodes) for k in range(len(nodes[0]))]
    hi = [max(n[k] for n in nodes) for k in range(len(nodes[0]))]
    dim = doc["dimension"]
    nx, ny = counts[0], counts[1]
    nz = counts[2] if dim == 3 else 0

    def coord(k, i, n):
        return lo[k] + (hi[k] - lo[k]) * i / n

    if dim == 2:
        def nid(i, j):
            return j * (nx + 1) + i
        part["nodes"] = [[coord(0, i, nx), coord(1, j, ny)]
                         for j in range(ny + 1) for i in range(nx + 1)]
        part["elements"] = [{"type": "CPE4R", "connectivity": [
            [nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)]
            for j in range(ny) for i in range(nx)]}]
        part["node_sets"] = {"bottom": [nid(i, 0) for i in range(nx + 1)],
                             "top": [nid(i, ny) for i in range(nx + 1)]}
        part["surfaces"] = {"top": [[nid(i + 1, ny), nid(i, ny)] for i in range(nx)]}
    else:
        def nid(i, j, k):
            return k * (ny + 1) * (nx + 1) + j * (nx + 1) + i
        part["nodes"] = [[coord(0, i, nx), coord(1, j, ny), coord(2, k, nz)]
                         for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
        part["elements"] = [{"type": "C3D8R", "connectivity": [
            [nid(i, j, k), nid(i + 1, j, k), nid(i + 1, j + 1, k), nid(i, j + 1, k),
             nid(i, j, k + 1), nid(i + 1, j, k + 1), nid(i + 1, j + 1, k + 1),
             nid(i, j + 1, k + 1)]
            for k in range(nz) for j in range(ny) for i in range(nx)]}]
        part["node_sets"] = {
            "bottom": [nid(i, 0, k) for k in range(nz + 1) for i in range(nx + 1)],
            "top": [nid(i, ny, k) for k in range(nz + 1) for i in range(nx + 1)]}
        part["surfaces"] = {"top": [
            [nid(i + 1, ny, k), nid(i, ny, k), nid(i, ny, k + 1), nid(i + 1, ny, k + 1)]
            for k in range(nz) for i in range(nx)]}
    return doc


def input_file(run, run_dir):
    """The file a run reads: the scene's own, or (a verification scene with its own mesh) one
    written into the run directory."""
    if run["kind"] == "verification" and run["params"]["mesh"] is not None:
        doc = json.loads((ROOT / run["file"]).read_text())
        path = run_dir / "model.json"
        path.write_text(json.dumps(block_mesh(doc, run["params"]["mesh"])))
        return path
    return ROOT / run["file"]


def reproduce(run, args):
    """The commands that repeat a run: the sweep's own (always), and plain `skid run` when the
    run reads a file of the repository."""
    commands = [f"scripts/stress.py --seed {args.seed} --only {run['index']} --keep"]
    if run["kind"] == "drum" or run["params"]["mesh"] is None:
        cmd = ["target/release/skid", "run", run["file"], "--out", "out/stress-repro"]
        for s in overrides(run):
            cmd += ["--set", s]
        commands.append(" ".join(shlex.quote(c) for c in cmd))
    return commands


# ---------------------------------------------------------------------------------------------
# Checks of a completed run


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise ValueError(f"{path.name} is empty")
    return rows[0], rows[1:]


def numbers(header, rows, name, problems, text_columns=("step", "status")):
    """The numeric columns of a CSV as floats; non-finite or unreadable cells are problems."""
    out = []
    bad = 0
    for r, row in enumerate(rows):
        if len(row) != len(header):
            problems.append(f"{name}: row {r + 2} has {len(row)} cells, header {len(header)}")
            return None
        values = {}
        for h, cell in zip(header, row):
            if h in text_columns:
                values[h] = cell
                continue
            try:
                v = float(cell)
            except ValueError:
                v = float("nan")
            if not math.isfinite(v):
                bad += 1
                if bad <= 3:
                    problems.append(f"{name}: row {r + 2} column {h}: {cell!r} (not finite)")
            values[h] = v
        out.append(values)
    return out


def non_finite_in_json(value, where, problems):
    if isinstance(value, float) and not math.isfinite(value):
        problems.append(f"summary.json: {where}: {value} (not finite)")
    elif isinstance(value, dict):
        for k, v in value.items():
            non_finite_in_json(v, f"{where}.{k}" if where else k, problems)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            non_finite_in_json(v, f"{where}[{i}]", problems)


def cone_check(rows, pairs, problems, measures):
    """|tangential force| <= mu N and N >= 0 on every row, per contact pair (sums over the
    pair's contacts, a necessary condition of the pointwise law)."""
    worst = 0.0
    for name, mu, normal, tangential in pairs:
        n_max = max([abs(r[normal]) for r in rows] + [0.0])
        for r in rows:
            n = r[normal]
            t = math.sqrt(sum(r[c] ** 2 for c in tangential))
            if n < -CONE_ABSOLUTE * n_max:
                problems.append(f"contact law: {name}: normal force {n:.4g} N < 0 at t = "
                                f"{r['time']:.6g}")
                return
            if n_max > 0:
                worst = max(worst, (t - mu * n) / n_max)
            if t > mu * n * (1 + CONE_RELATIVE) + CONE_ABSOLUTE * n_max + 1e-300:
                problems.append(f"contact law: {name}: friction {t:.6g} N > mu N = {mu * n:.6g}"
                                f" N at t = {r['time']:.6g}")
                return
    measures["cone_excess"] = worst


def solver_tolerances(run_dir):
    """(force, contact) tolerances of the run's input as run (case.json or model.json)."""
    for name in ("case.json", "model.json"):
        path = run_dir / name
        if path.is_file():
            solver = json.loads(path.read_text()).get("solver", {})
            return solver["force_tolerance"], solver["contact_tolerance"]
    raise ValueError("no case.json or model.json (the input as run) in the run's directory")


def newton_check(rows, tolerances, problems, measures):
    """The last convergence check of every increment meets the Newton tolerances
    `(force, contact)`."""
    force_tolerance, contact_tolerance = tolerances
    worst_f = worst_c = 0.0
    # the checks of failed attempts (status "rejected: ...") precede their cutback
    rows = [r for r in rows if r.get("status", "converged") == "converged"]
    for k, r in enumerate(rows):
        last = k + 1 == len(rows) or rows[k + 1]["iteration"] <= r["iteration"]
        if not last:
            continue
        worst_f = max(worst_f, r["force_residual"])
        worst_c = max(worst_c, r["contact_residual"])
        if r["force_residual"] > force_tolerance or r["contact_residual"] > contact_tolerance:
            problems.append(
                f"newton.csv: step {r['step']} increment {r['increment']:.0f} accepted with "
                f"force residual {r['force_residual']:.3g}, contact residual "
                f"{r['contact_residual']:.3g} (tolerances {force_tolerance}, "
                f"{contact_tolerance})")
            break
    measures["newton_force_residual"] = worst_f
    measures["newton_contact_residual"] = worst_c


def check_completed(run, run_dir):
    """Problems with a completed run's outputs (empty if none) and what was measured."""
    problems, measures = [], {}
    p = run["params"]

    def reject(token):
        raise ValueError(token)

    try:
        summary = json.loads((run_dir / "summary.json").read_text(), parse_constant=reject)
    except (OSError, ValueError) as e:
        return [f"summary.json unreadable or not finite: {e}"], measures
    non_finite_in_json(summary, "", problems)
    if summary.get("status") != "completed" or summary.get("error") is not None:
        problems.append(f"summary.json: status {summary.get('status')!r} after exit status 0")
    for key in ("final_time", "max_gap_violation_m", "max_sliding_separation_m", "wall_time_s"):
        if not isinstance(summary.get(key), (int, float)):
            problems.append(f"summary.json: {key} is {summary.get(key)!r}, expected a number")
    measures["increments"] = summary.get("increments")
    measures["newton_iterations"] = summary.get("newton_iterations")
    measures["cutbacks"] = summary.get("cutbacks")
    measures["equations"] = summary.get("equations")
    measures["solver_wall_s"] = summary.get("wall_time_s")

    history = newton = None
    for name in ("history.csv", "newton.csv"):
        try:
            header, rows = read_csv(run_dir / name)
        except (OSError, ValueError) as e:
            problems.append(f"{name}: {e}")
            continue
        parsed = numbers(header, rows, name, problems)
        if name == "history.csv":
            history = parsed
        else:
            newton = parsed
    if problems:
        return problems, measures

    # Complete: the dynamic step's increments add up to its duration.
    dynamic_step = json.loads((ROOT / run["file"]).read_text())["steps"][1]["name"]
    covered = sum(r["dt"] for r in history if r["step"] == dynamic_step)
    if abs(covered - p["duration"]) > DURATION_RELATIVE * p["duration"]:
        problems.append(f"history.csv: the dynamic step covers {covered:.7g} s of "
                        f"{p['duration']:.7g} s")

    try:
        tolerances = solver_tolerances(run_dir)
    except (OSError, ValueError, KeyError) as e:
        problems.append(f"input as run: {e}")
        return problems, measures
    newton_check(newton, tolerances, problems, measures)

    length = 0.2 if run["kind"] == "drum" else BLOCK_LENGTH
    if run["kind"] == "drum":
        length = json.loads((ROOT / run["file"]).read_text())["drum"]["radius"]
    pen = summary["max_gap_violation_m"]
    sep = summary["max_sliding_separation_m"]
    measures["penetration_rel"] = pen / length
    measures["sliding_separation_rel"] = sep / length
    if pen > PENETRATION_LIMIT * length:
        problems.append(f"contact law: penetration {pen:.3g} m > {PENETRATION_LIMIT:g} x "
                        f"{length} m")
    if sep > SEPARATION_LIMIT * length:
        problems.append(f"contact law: a sliding contact is open by {sep:.3g} m > "
                        f"{SEPARATION_LIMIT:g} x {length} m")
    if run["kind"] == "drum":
        pairs = [("pad-drum", p["mu"], "normal_force", ["friction_force"])]
    else:
        doc = json.loads((ROOT / run["file"]).read_text())
        pairs = []
        for pair in doc["contact"]:
            name = pair["name"]
            tangential = [c for c in (f"{name}.tangential_force_1", f"{name}.tangential_force_2")
                          if c in history[0]] if history else []
            pairs.append((name, p["mu"], f"{name}.normal_force", tangential))
    if history:
        cone_check(history, pairs, problems, measures)

    # Energy balance: the residual of the ledger (with the time integration's own dissipation
    # counted) against all the energy in play: the largest mechanical energy, work or
    # dissipation in the ledger, or the initial kinetic energy. The drum summary's
    # `energy_balance_error` divides by the drum's energy loss instead, which is small when the
    # drum barely slows (little friction, a short run, a sticking pad); it is kept as a measure.
    residual = summary.get("energy_balance_residual_j")
    measures["drum_energy_balance_error"] = summary.get("energy_balance_error")
    measures["algorithmic_dissipation_j"] = summary.get("algorithmic_dissipation_j")
    measures["energy_error"] = None
    measures["energy_measure"] = "not recorded"
    if residual is not None and history:
        keys = ("external_work", "normal_work", "friction_dissipation",
                "algorithmic_dissipation")
        scale = max([r.get("kinetic_energy", 0.0) + r.get("strain_energy", 0.0)
                     + r.get("hourglass_energy", 0.0) for r in history]
                    + [abs(r[k]) for r in history for k in keys if k in r] + [0.0])
        if run["kind"] == "drum":
            inertia = json.loads((ROOT / run["file"]).read_text())["drum"]["rotary_inertia"]
            scale = max(scale, 0.5 * inertia * p["speed"] ** 2)
        measures["energy_residual_j"] = residual
        measures["energy_vs_in_play"] = abs(residual) / scale if scale > 0 else None
        measures["energy_error"] = measures["energy_vs_in_play"]
        measures["energy_measure"] = ("residual / energy in play" if scale > 0
                                      else "no energy in play")
    e = measures.get("energy_error")
    if e is not None and e > ENERGY_LIMIT:
        problems.append(f"energy balance: {measures['energy_measure']} = {e:.3g} > "
                        f"{ENERGY_LIMIT:g}")
    return problems, measures


# ---------------------------------------------------------------------------------------------
# Running


def invoke(run, path, results, timeout):
    """Runs `skid run` on `path` with the run's overrides: (exit status or None on timeout,
    stderr, wall time)."""
    cmd = [str(SKID), "run", str(path), "--out", str(results)]
    for s in overrides(run):
        cmd += ["--set", s]
    start = time.monotonic()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        rc, stderr = proc.returncode, proc.stderr
    except subprocess.TimeoutExpired as e:
        rc = None
        stderr = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (
            e.stderr or "")
    return rc, stderr, time.monotonic() - start


def summary_warnings(results):
    """The warnings of a completed run's summary.json (what a user must know before trusting
    it, e.g. that the time integration removed much of the energy)."""
    try:
        return json.loads((results / "summary.json").read_text()).get("warnings", [])
    except (OSError, ValueError):
        return []


def energy_only(problems):
    return bool(problems) and all(p.startswith("energy balance") for p in problems)


def execute(run, args, out_root):
    run_dir = out_root / f"run-{run['index']:04d}"
    if run_dir.exists():
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    path = input_file(run, run_dir)
    results = run_dir / "results"
    rc, stderr, wall = invoke(run, path, results, args.timeout)
    record = dict(run)
    record["overrides"] = overrides(run)
    record["reproduce"] = reproduce(run, args)
    record["exit_status"] = rc
    record["wall_s"] = round(wall, 4)
    message = stderr.strip()
    record["message"] = clean(message[-2000:])
    record["problems"] = []
    if rc is None:
        record["outcome"] = "timeout"
    elif rc < 0:
        record["outcome"] = "crashed"
        record["problems"].append(f"killed by signal {-rc}")
    elif "panicked" in stderr:
        record["outcome"] = "crashed"
        record["problems"].append("panic")
    elif rc == 0:
        problems, measures = check_completed(run, results)
        record["measures"] = measures
        record["problems"] = problems
        record["warnings"] = summary_warnings(results)
        if problems:
            record["outcome"] = "silently wrong"
        elif record["warnings"]:
            record["outcome"] = "warned"
        else:
            record["outcome"] = "completed"
        if energy_only(problems) and run["params"]["alpha"] != 0.0:
            # Diagnosis: the same run with alpha = 0 (no numerical dissipation of HHT, which
            # the energy ledger does not count).
            again = json.loads(json.dumps(run))
            again["params"]["alpha"] = 0.0
            rc0, _, _ = invoke(again, path, run_dir / "alpha0", args.timeout)
            check = {"exit_status": rc0}
            if rc0 == 0:
                p0, m0 = check_completed(again, run_dir / "alpha0")
                check.update(problems=p0, energy_error=m0.get("energy_error"),
                             energy_vs_in_play=m0.get("energy_vs_in_play"))
            record["alpha0_check"] = check
    elif rc in (1, 2):
        if not message:
            record["outcome"] = "crashed"
            record["problems"].append(f"exit status {rc} without a message")
        else:
            record["outcome"] = "failed"
            record["diagnosis"] = diagnosis(rc, message, results)
    else:
        record["outcome"] = "crashed"
        record["problems"].append(f"exit status {rc}")
    if not args.keep:
        shutil.rmtree(run_dir, ignore_errors=True)
    return record


def diagnosis(rc, message, results):
    """The kind of failure: the summary's `failure` (exit 1) or the refused field (exit 2)."""
    if rc == 1:
        try:
            summary = json.loads((results / "summary.json").read_text())
            return f"stopped: {summary.get('failure')}"
        except (OSError, ValueError):
            return "stopped: no summary.json"
    line = message.splitlines()[-1] if message else ""
    parts = line.split(": ")
    # "skid: FILE: FIELD: what" -> the field
    return f"refused: {parts[2]}" if len(parts) > 3 else f"refused: {line[:120]}"


# ---------------------------------------------------------------------------------------------
# Report


# What the energy checks of earlier sweeps were traced to (by hand, rerunning the runs).
LEDGER_NOTE = (
    "Earlier sweeps flagged 42 completed runs on the energy balance alone. They traced to the "
    "ledger, not the solutions: (1) the time integration's own dissipation was not counted, "
    "neither HHT's numerical damping at alpha < 0 nor the end-point equilibrium of a "
    "quasi-static solid, which loses k dx^2 / 2 per increment like backward Euler (seed 1 run "
    "188, a 2D block at mu 1.8 sticking and swinging the ground back at 2.5 ms steps: 58 % of "
    "the energy in play, at alpha = 0 as at alpha < 0); the ledger now counts it "
    "(`algorithmic_dissipation`, exact for linear forces whenever the increments are in "
    "equilibrium), and run 188's residual falls from 0.588 to 0.0019 of the energy in play; "
    "(2) the drum summary's ratio divides by the drum's energy loss, small when the drum "
    "barely slows; the check now takes the residual against all the energy in play; (3) the "
    "static steps took the contact work at the end of each increment, first order in the load "
    "increment; it is the trapezoidal rule now, and the balance is taken over the dynamic steps "
    "only, since a static step's ledger is a quadrature of the work of loads ramped over few "
    "increments (seed 1 run 229: one increment to 8.5 MPa, 0.33 of the energy in play), while "
    "its states are equilibria that Newton checks.")


CONTACT_NOTE = (
    "An earlier sweep flagged 11 verification runs whose closed contacts "
    "penetrated the ground by up to 1e-3 of the block size while every Newton check passed "
    "(seed 1 run 2: mu 0, 3.042e5 Pa, dt 8.356e-4 s, reduced contact solve: 1.1e-5 m, the "
    "tied plate zig-zagging at up to 1e-2 m/s). The quasi-static block is held vertically "
    "only by its contacts, so the Delassus operator holds the compliance of that free mode, "
    "far above the others, and the Coulomb solver's relative tolerance 1e-8 left micrometres "
    "of penetration, which the reduced path's Newton check (linearised against actual gaps) "
    "did not see. The reduced path now tightens the Coulomb solve until its gaps and slips "
    "are exact as lengths and judges the law at the new kinematics in lengths, as the global "
    "path does: run 2 penetrates 2.3e-11 m and its plate moves at most 5.4e-7 m/s.")


def clean(text):
    """A message without the machine's paths: the case file relative to the repository, a
    run directory as OUT/run-NNNN."""
    text = re.sub(r"/\S*?/(cases/)", r"\1", text)
    return re.sub(r"/\S*/(run-\d{4}/)", r"OUT/\1", text)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return out


def describe(record):
    p = record["params"]
    mesh = "file" if p["mesh"] is None else " x ".join(str(k) for k in p["mesh"])
    speed = f"{p['speed']:.4g}"
    return (f"mu {p['mu']:g}, p {p['pressure']:.4g} Pa, dt {p['dt']:.4g} s x "
            f"{p['dynamic_increments']}, speed {speed}, mesh {mesh}, alpha {p['alpha']:g}, "
            f"{p['static_increments']} preload increments, {p['contact_solve']}, "
            f"{p['coulomb_method']}")


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}g}"


def write_report(records, args, total_wall, results):
    outcomes = ["completed", "warned", "failed", "timeout", "crashed", "silently wrong"]
    counts = {o: sum(r["outcome"] == o for r in records) for o in outcomes}
    bad = [r for r in records if r["outcome"] in ("crashed", "silently wrong")]
    doc = {
        "command": f"scripts/stress.py --runs {args.runs} --seed {args.seed} --jobs {args.jobs}",
        "seed": args.seed,
        "runs": len(records),
        "jobs": args.jobs,
        "timeout_s": args.timeout,
        "total_wall_s": round(total_wall, 1),
        "counts": counts,
        "thresholds": {
            "newton_tolerances": "each run's solver.force_tolerance and "
                                 "solver.contact_tolerance, as run",
            "penetration_relative": PENETRATION_LIMIT,
            "sliding_separation_relative": SEPARATION_LIMIT,
            "cone_relative": CONE_RELATIVE,
            "cone_absolute": CONE_ABSOLUTE,
            "energy_relative": ENERGY_LIMIT,
            "duration_relative": DURATION_RELATIVE,
        },
        "records": records,
    }
    for r in records:
        r["message"] = clean(r["message"])
    results.mkdir(parents=True, exist_ok=True)
    (results / "stress.json").write_text(json.dumps(doc, indent=1) + "\n")

    md = ["# Stress sweep (`scripts/stress.py`)", ""]
    md += [f"`{doc['command']}`: {len(records)} short runs of `skid run` (release build) over "
           "the drum cases (cases/drum, 2D and 3D) and the verification scenes of a block on a "
           f"sliding ground (cases/verification), drawn from seed {args.seed}; {total_wall / 60:.1f} min of "
           f"wall time in all ({args.jobs} job{'s' if args.jobs > 1 else ''}), "
           f"{args.timeout:g} s timeout per run.", ""]
    md += ["**Result: " + (f"{counts['crashed']} crashed and {counts['silently wrong']} "
                           "silently wrong runs (listed below).**" if bad else
                           "no crash and no silently wrong completed run.**"), ""]
    md += ["Parameters: friction mu in [0, 2] (0 in one run in ten), pressure log-uniform in "
           "[1e3, 1e7] Pa, time step log-uniform in [1e-6, 1e-2] s with 1 to 40 dynamic "
           "increments (fewer on bigger meshes), initial speed of either sign (drum omega0 "
           "0.1 to 300 rad/s, ground velocity 0.01 to 10 m/s, zero in one run in twenty), pad "
           "or block meshes up to 40 x 8 x 8, HHT alpha in [-1/3, 0], 1 to 5 preload "
           "increments, contact solve auto/global/reduced, the conic Coulomb method in one run "
           "in ten.", ""]
    md += ["Checks of a completed run (a run failing one is *silently wrong*):",
           "- every number in summary.json, history.csv and newton.csv is finite, and the "
           "dynamic step's increments add up to its duration (relative 1e-5);",
           "- every accepted increment's last Newton check (newton.csv) is within the solver's "
           "tolerances as run (case.json or model.json: `solver.force_tolerance`, "
           "`solver.contact_tolerance` of the model size; by default 1e-6 and 1e-8);",
           f"- contact law: deepest penetration and largest gap of a sliding contact at most "
           f"{PENETRATION_LIMIT:g} of the length scale (drum radius; block size 0.02 m), i.e. "
           "100 times the default Newton contact tolerance; on every history row and pair, "
           f"|friction| <= mu N (1 + {CONE_RELATIVE:g}) + {CONE_ABSOLUTE:g} max N and "
           f"N >= -{CONE_ABSOLUTE:g} max N (100 times the Coulomb tolerance 1e-8);",
           f"- energy: `energy_balance_residual_j` (summary.json: the ledger's residual with "
           "the time integration's own dissipation counted) at most "
           f"{ENERGY_LIMIT:.0%} of the energy in play (the largest mechanical energy, work or "
           "dissipation in the ledger, or the initial kinetic energy).", "",
           "A completed run whose summary carries a warning (the time integration removed more "
           "than 5 % of the energy in play: HHT's damping or the end-point equilibrium of a "
           "quasi-static solid at a coarse time step) passes these checks but is counted as "
           "*warned*, not *completed*: its answer depends on the time step and skid says so "
           "on stderr and in summary.json.", ""]

    md += ["## Outcomes", ""]
    md += table(["outcome", "runs"], [[o, counts[o]] for o in outcomes])
    md += [""]
    scenes = sorted({r["scene"] for r in records})
    rows = []
    for s in scenes:
        rs = [r for r in records if r["scene"] == s]
        rows.append([s, len(rs)] + [sum(r["outcome"] == o for r in rs) for o in outcomes]
                    + [f"{sum(r['wall_s'] for r in rs):.0f}"])
    md += ["## Per scene", ""]
    md += table(["scene", "runs"] + outcomes + ["wall [s]"], rows)
    md += [""]

    failed = [r for r in records if r["outcome"] == "failed"]
    kinds = {}
    for r in failed:
        kinds.setdefault(r["diagnosis"], []).append(r)
    md += ["## Failures with a diagnosis", ""]
    if failed:
        md += table(["diagnosis", "runs", "example run", "example message"],
                    [[k, len(v), v[0]["index"],
                      v[0]["message"].splitlines()[-1][:200].replace("|", "\\|")]
                     for k, v in sorted(kinds.items(), key=lambda kv: -len(kv[1]))])
    else:
        md += ["None."]
    md += [""]

    with_energy = [r for r in records if r.get("measures", {}).get("energy_error") is not None]
    with_energy.sort(key=lambda r: -r["measures"]["energy_error"])
    md += ["## Worst energy balance (completed runs)", ""]
    md += table(["run", "scene", "error", "measure", "parameters"],
                [[r["index"], r["scene"], fmt(r["measures"]["energy_error"]),
                  r["measures"]["energy_measure"], describe(r)] for r in with_energy[:8]])
    md += [""]
    completed = [r for r in records if "measures" in r]
    if completed:
        def worst(key):
            vals = [r["measures"].get(key) for r in completed]
            vals = [v for v in vals if v is not None]
            return fmt(max(vals)) if vals else "-"
        md += ["Worst over the completed runs: penetration "
               f"{worst('penetration_rel')} and sliding gap {worst('sliding_separation_rel')} "
               "of the length scale, friction beyond the cone "
               f"{worst('cone_excess')} of the largest normal force, last Newton check "
               f"force {worst('newton_force_residual')}, contact "
               f"{worst('newton_contact_residual')}.", ""]

    slow = sorted(records, key=lambda r: -r["wall_s"])[:10]
    md += ["## Slowest runs", ""]
    md += table(["run", "scene", "outcome", "wall [s]", "increments", "parameters"],
                [[r["index"], r["scene"], r["outcome"], f"{r['wall_s']:.2f}",
                  r.get("measures", {}).get("increments", "-"), describe(r)] for r in slow])
    md += [""]

    md += ["## Crashes and silently wrong runs", ""]
    if not bad:
        md += ["None."]
    energy = [r for r in bad if r["outcome"] == "silently wrong" and energy_only(r["problems"])]
    other = [r for r in bad if r not in energy]
    if energy:
        def alpha0_ok(r):
            c = r.get("alpha0_check", {})
            return c.get("exit_status") == 0 and not c.get("problems")

        md += [f"### {len(energy)} completed runs whose only failed check is the energy "
               "balance", "", LEDGER_NOTE, ""]
        md += table(["run", "scene", "residual / energy in play", "drum ratio",
                     "algorithmic dissipation [J]", "alpha", "alpha = 0: error", "parameters",
                     "reproduce"],
                    [[r["index"], r["scene"], fmt(r["measures"]["energy_error"]),
                      fmt(r["measures"].get("drum_energy_balance_error")),
                      fmt(r["measures"].get("algorithmic_dissipation_j")), r["params"]["alpha"],
                      fmt(r.get("alpha0_check", {}).get("energy_error"))
                      + ("" if alpha0_ok(r) or "alpha0_check" not in r else " (fails)"),
                      describe(r), f"`{r['reproduce'][0]}`"] for r in energy])
        md += [""]
    else:
        md += ["", "### Energy balance", "", "No completed run fails the energy balance. "
               + LEDGER_NOTE, ""]
    warned = [r for r in records if r["outcome"] == "warned"]
    if warned:
        most = sorted(warned, key=lambda r: -(r["measures"].get("algorithmic_dissipation_j")
                                                or 0.0))[:10]
        md += [f"### {len(warned)} runs completed with a warning", "",
               "Each passes every check and its summary warns (the time integration removed "
               "more than 5 % of the energy in play); the ten that lost the most joules:", ""]
        md += table(["run", "scene", "warning", "parameters"],
                    [[r["index"], r["scene"], "; ".join(r.get("warnings", [])),
                      describe(r)] for r in most])
        md += [""]
    if any(p.startswith("contact law") for r in other for p in r["problems"]):
        md += ["### Runs breaking the contact law", "", CONTACT_NOTE, ""]
    else:
        md += ["### Contact law", "", "No completed run breaks the contact law. "
               + CONTACT_NOTE, ""]
    for r in other:
        md += [f"### run {r['index']}: {r['scene']}, {r['outcome']}", "",
               f"- parameters: {describe(r)}",
               f"- exit status {r['exit_status']}, {r['wall_s']:.2f} s"]
        md += [f"- {p}" for p in r["problems"]]
        if r["message"]:
            md += [f"- message: `{r['message'].splitlines()[-1][:300]}`"]
        md += ["- reproduce:"] + [f"  - `{c}`" for c in r["reproduce"]]
        md += [""]
    timeouts = [r for r in records if r["outcome"] == "timeout"]
    if timeouts:
        md += ["## Timeouts", ""]
        for r in timeouts:
            md += [f"- run {r['index']} ({r['scene']}, {describe(r)}): "
                   f"`{r['reproduce'][0]}`"]
        md += [""]
    (results / "stress.md").write_text("\n".join(md))
    return bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None,
                    help="scratch directory of the runs (default: a temporary directory)")
    ap.add_argument("--keep", action="store_true", help="keep each run's directory")
    ap.add_argument("--only", type=int, default=None,
                    help="repeat run K of the sweep alone (with --keep: its files stay)")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per run")
    ap.add_argument("--results", type=Path, default=ROOT / "validation",
                    help="where stress.json and stress.md go")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite stress.md from the stress.json in --results, running nothing")
    args = ap.parse_args()
    if args.report_only:
        doc = json.loads((args.results / "stress.json").read_text())
        args.runs, args.seed, args.jobs = doc["runs"], doc["seed"], doc["jobs"]
        args.timeout = doc["timeout_s"]
        bad = write_report(doc["records"], args, doc["total_wall_s"], args.results)
        return 1 if bad else 0
    if not SKID.exists():
        sys.exit(f"{SKID} not found: build it with `cargo build --release -p skid-cli`")
    out_root = args.out or Path(tempfile.mkdtemp(prefix="skid-stress-"))
    out_root.mkdir(parents=True, exist_ok=True)

    if args.only is not None:
        record = execute(draw(args.seed, args.only), args, out_root)
        print(json.dumps(record, indent=1))
        if args.keep:
            print(f"kept in {out_root / f'run-{args.only:04d}'}", file=sys.stderr)
        return 1 if record["outcome"] in ("crashed", "silently wrong") else 0

    runs = [draw(args.seed, k) for k in range(args.runs)]
    records = [None] * len(runs)
    lock = threading.Lock()
    done = [0]
    start = time.monotonic()

    def one(run):
        record = execute(run, args, out_root)
        with lock:
            records[run["index"]] = record
            done[0] += 1
            flag = "" if record["outcome"] in ("completed", "warned", "failed") else "  <--"
            print(f"[{done[0]:4d}/{len(runs)}] run {run['index']:4d} {run['scene']:<28} "
                  f"{record['outcome']:<15} {record['wall_s']:7.2f} s "
                  f"{record.get('diagnosis', '')}{flag}", flush=True)

    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        list(pool.map(one, runs))
    total = time.monotonic() - start
    bad = write_report(records, args, total, args.results)
    if not args.keep and args.out is None:
        shutil.rmtree(out_root, ignore_errors=True)
    counts = {}
    for r in records:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    print(f"{len(records)} runs in {total:.0f} s: {counts}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
