#!/usr/bin/env python3
"""The sliding block: frictional sliding that converges as the time step shrinks.

The scene (SI units; plane strain, 0.01 m thick, or 3D, 0.01 m deep): a hyperelastic block
0.02 m wide and 0.005 m high (n x n CPE4R elements, or n x n x n/2 C3D8R, neo-Hookean C10 = 0.552 MPa, C01 = 0.138 MPa, Poisson's
ratio 0; 1 g) on a fixed rigid flat, Coulomb friction mu. Its top face is tied to a massless
plate (rotation held) pressed down by N = 20 N (ramped over 0-10 ms) and pulled sideways by
F = 2 mu N (ramped over 15-25 ms, then held to 40 ms). While every contact slides, momentum
balance fixes the block's acceleration at (F - mu N) / m exactly; it is measured as the slope
of the plate's velocity over 27-40 ms, beside the scatter (standard deviation over mean) of
the contact normal force there.

Written with --write: cases/verification/2d-block-sliding.json (n = 4, mu = 0.3, the contact
nodes' mass moved off them, dt 1e-5 s), which the validation report checks with the other
Coulomb scenes. Run without it: the ladder of time steps 4e-5 to 2.5e-6 s, meshes 4 x 4 and
8 x 8 (2D) and 4 x 4 x 2 (3D), mu 0.1, 0.3, 0.7 and 1, each with the lumped mass, with
massless contact nodes (`part.section.massless_contact_nodes`), and with massless contact
nodes and stiffness damping beta = 1e-5 s (`part.section.stiffness_damping`, about 6 % of
critical on the block's first mode, a rubber's loss), into validation/sliding.md, with its
checks (acceleration within 0.2 % and normal-force scatter under 2 % at every step and mesh:
massless contact nodes for mu <= 0.3, and with the damping for mu <= 0.7); exit status 1 if
one fails. Steady Coulomb sliding of this block is a flutter instability without damping
(crates/skid-integrator/tests/frictional_flutter.rs): the undamped rows hold only where HHT's
numerical damping outweighs the growth.

Usage: scripts/sliding.py [--write] [--skid PATH] [--out FILE]
"""

import argparse
import concurrent.futures
import csv
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
BASE = {d: ROOT / f"cases/verification/{d}d-block-pushed-on-flat.json" for d in (2, 3)}
SCENE = ROOT / "cases/verification/2d-block-sliding.json"
NORMAL = 20.0
MASS = 0.001
WIDTH, HEIGHT = 0.02, 0.005
STEPS = [4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6]
# (dimension, elements along x and y); along z (3D) half as many
MESHES = [(2, 4), (2, 8), (3, 4)]
MUS = [0.1, 0.3, 0.7, 1.0]
WINDOW = (0.027, 0.040)


# the contact nodes' mass and the section's stiffness damping of each row of the ladder
OPTIONS = [("lumped", False, 0.0), ("massless", True, 0.0), ("massless, beta 1e-5 s", True, 1e-5)]


def scene(dim, n, mu, dt, massless, beta=0.0):
    """The sliding block of n x n (x n/2 along z in 3D, 0.01 m deep) elements as a model file
    (a dict)."""
    s = json.loads(BASE[dim].read_text())
    nz = max(1, n // 2) if dim == 3 else 0
    row, layer = n + 1, (n + 1) * (n + 1)

    def label(i, j, k):
        return i + row * j + layer * k

    nodes = []
    for k in range(nz + 1):
        for j in range(n + 1):
            for i in range(n + 1):
                x = [-WIDTH / 2 + WIDTH * i / n, HEIGHT * j / n]
                nodes.append(x + [-0.005 + 0.01 * k / nz] if dim == 3 else x)
    connectivity = []
    for k in range(max(nz, 1)):
        for j in range(n):
            for i in range(n):
                quad = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                corners = [label(a, b, k) for a, b in quad]
                if dim == 3:
                    corners += [label(a, b, k + 1) for a, b in quad]
                connectivity.append(corners)
    layers = range(nz + 1) if dim == 3 else [0]
    part = s["part"]
    part["nodes"] = nodes
    kind = "C3D8R" if dim == 3 else "CPE4R"
    part["elements"] = [{"type": kind, "connectivity": connectivity}]
    part["node_sets"] = {
        "bottom": [label(i, 0, k) for k in layers for i in range(n + 1)],
        "top": [label(i, n, k) for k in layers for i in range(n + 1)],
    }
    if massless:
        part["section"]["massless_contact_nodes"] = True
    if beta:
        part["section"]["stiffness_damping"] = beta
    s["loads"][1]["force"] = [2.0 * mu * NORMAL] + [0.0] * (dim - 1)
    s["contact"][0]["mu"] = mu
    s["steps"][0]["dt"] = dt
    s["name"] = f"{dim}d-block-sliding"
    s["description"] = (
        f"Verification ({dim}D): the pushed block's scene with {n} x {n} elements, mu = {mu}, "
        f"pulled by F = 2 mu N = {2 * mu * NORMAL:g} N once pressed by N = {NORMAL:g} N, its "
        "contact nodes without mass (part.section.massless_contact_nodes, their lumped mass "
        "moved to the nodes above them). While every contact slides the block accelerates at "
        f"(F - mu N) / m = {(mu * NORMAL) / MASS:g} m/s^2 and the friction resultant is mu N; "
        "the contact normal force stays steady at any time step (scripts/sliding.py measures "
        "the ladder 4e-5 to 2.5e-6 s)."
    )
    return s


def measure(run, mu):
    """(acceleration error, normal-force scatter) of a run directory over the window."""
    rows = list(csv.DictReader(open(run / "history.csv")))
    t = [float(r["time"]) for r in rows]
    sel = [i for i, ti in enumerate(t) if WINDOW[0] <= ti <= WINDOW[1]]
    ts = [t[i] for i in sel]
    vs = [float(rows[i]["plate.v_x"]) for i in sel]
    ns = [float(rows[i]["block-ground.normal_force"]) for i in sel]
    tm, vm = statistics.mean(ts), statistics.mean(vs)
    slope = sum((a - tm) * (b - vm) for a, b in zip(ts, vs)) / sum((a - tm) ** 2 for a in ts)
    exact = mu * NORMAL / MASS
    return slope / exact - 1.0, statistics.pstdev(ns) / statistics.mean(ns)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true")
    parser.add_argument("--skid", default=str(ROOT / "target/release/skid"))
    parser.add_argument("--out", default=str(ROOT / "validation/sliding.md"))
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    if args.write:
        SCENE.write_text(json.dumps(scene(2, 4, 0.3, 1e-5, True), indent=2) + "\n")
        print(f"wrote {SCENE}")
        return
    if not Path(args.skid).exists():
        subprocess.run(["cargo", "build", "--release", "-p", "skid-cli"], cwd=ROOT, check=True)
    lines = [
        "# The sliding block: acceleration and normal force against the time step",
        "",
        "Written by `scripts/sliding.py` (see its header for the scene). Each cell: error of the",
        "acceleration against momentum balance, and the scatter of the contact normal force,",
        f"over {WINDOW[0] * 1e3:g}-{WINDOW[1] * 1e3:g} ms.",
        "",
        "Steady Coulomb sliding of this block flutters without damping: linearised about the",
        "sliding state, friction couples the contact nodes' normal reactions into their",
        "tangential rows, and mode pairs turn complex and grow (mode-coupling flutter, the",
        "mechanism of brake squeal; crates/skid-integrator/tests/frictional_flutter.rs). With",
        "the lumped mass on the contact nodes the 4 x 4 block grows from mu below 0.3; massless",
        "contact nodes raise that to about 0.62 on 4 x 4, but on 8 x 8 it grows at mu = 0.3",
        "already, and faster on finer meshes: without damping the continuum problem is",
        "ill-posed. Undamped rows hold only where HHT's numerical damping (which fades as dt",
        "shrinks) outweighs the growth. Stiffness damping of a rubber's loss (beta = 1e-5 s, 6 %",
        "of critical on the first mode) makes the linearised sliding stable to mu = 1 on every",
        "mesh; the damped rows then converge at every dt. At mu = 1 on 8 x 8 the leading",
        "bottom corner element folds during the pull ramp (23-31 ms) for every element",
        "formulation and beta from 1e-5 to 1e-4 s: the corner's frictional stress singularity,",
        "static and resolved only by the finer mesh, not the flutter.",
        "",
        "| mesh | mu | contact nodes | " + " | ".join(f"dt {dt:g} s" for dt in STEPS) + " |",
        "|---|---|---|" + "---|" * len(STEPS),
    ]
    checks = []

    def one(work, dim, n, mu, dt, massless, beta):
        path = work / f"scene-{dim}-{n}-{mu}-{dt}-{massless}-{beta}.json"
        path.write_text(json.dumps(scene(dim, n, mu, dt, massless, beta)))
        out = work / path.stem
        run = subprocess.run(
            [args.skid, "run", str(path), "--out", str(out)], capture_output=True, text=True
        )
        if run.returncode != 0:
            return "failed", False
        error, scatter = measure(out, mu)
        return f"{100 * error:+.3f} %, {100 * scatter:.2f} %", abs(error) < 0.002 and scatter < 0.02

    with tempfile.TemporaryDirectory() as tmp, \
            concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        work = Path(tmp)
        rows = [(dim, n, mu, option) for dim, n in MESHES for mu in MUS for option in OPTIONS]
        futures = {
            (dim, n, mu, option[0], dt): pool.submit(one, work, dim, n, mu, dt, *option[1:])
            for dim, n, mu, option in rows
            for dt in STEPS
        }
        for dim, n, mu, (kind, massless, beta) in rows:
            mesh = f"{n} x {n}" + (f" x {n // 2}" if dim == 3 else "")
            cells = []
            for dt in STEPS:
                cell, ok = futures[(dim, n, mu, kind, dt)].result()
                cells.append(cell)
                if (beta > 0.0 and mu <= 0.7) or (massless and mu <= 0.3):
                    checks.append((f"{mesh}, mu {mu}, dt {dt:g}: {kind}", ok))
                print(f"{mesh} mu {mu} {kind} dt {dt:g}: {cell}", file=sys.stderr)
            lines.append(f"| {mesh} | {mu} | {kind} | " + " | ".join(cells) + " |")
    lines += ["", "## Checks", ""]
    lines += [f"- {'pass' if ok else 'FAIL'}: {what}" for what, ok in checks]
    lines.append("")
    Path(args.out).write_text("\n".join(lines))
    print(f"wrote {args.out}")
    sys.exit(0 if all(ok for _, ok in checks) else 1)


if __name__ == "__main__":
    main()
