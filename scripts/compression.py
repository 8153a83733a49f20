#!/usr/bin/env python3
"""Writes the large-strain compression scenes cases/verification/*-compression-*.inp: a
neo-Hookean block on rollers compressed by 50 %, one deck per element formulation, whose answer
is a closed form (see crates/skid-report/src/verification/compression.rs).

The block (SI units): the unit square (2D, plane strain, 1 m thick) or cube (3D); its bottom
y = 0 held in y (rollers), the corner at the origin held in x (and z in 3D; in 3D the bottom
corner (1, 0, 0) is held in z too, so that the block cannot turn about y); its top y = 1 (node
set `top`) moved down by the compression `c`, ramped over a static step (NLGEOM, automatic
increments from 5 % of the step). The material is neo-Hookean, C10 = 0.5 MPa (G = 1 MPa) and
D1 = 4e-8 /Pa (K = 50 MPa, nu = 0.49 at small strain). The deformation is homogeneous, so every
element formulation represents it exactly: the top's reaction `top.reaction_y` (history) and
the lateral stretch, from the displacements of the node set `corner` (the top corner opposite
the origin, `*NODE OUTPUT` in the history), are those of the closed form at every increment.
Three scenes (`<dimension>-compression-<scene>-<element>.inp`):
- `2d-uniaxial` (one element): the sides free;
- `2d-confined` (4 x 4 elements): the sides x = 0 and x = 1 held in x as well;
- `3d-uniaxial` (one element): the sides free.

The uniaxial scenes are single elements: on a mesh of several elements the homogeneous
solution bifurcates before 50 % in some formulations (`--probe --meshes 4`: CPE4R leaves the
closed form at 48 %, CPE4I at 47 % and C3D8I at 40 %), consistent with short wrinkles of the
free sides meeting Biot's surface instability (an incompressible neo-Hookean solid in plane
strain wrinkles at the stretch 0.544); a single element has no such mode, and every formulation
follows the closed form to 50 % on it.

Usage: scripts/compression.py [--dir DIR]
       scripts/compression.py --probe [--skid PATH] [--meshes N ...]
  --dir: where the decks go (default cases/verification); --probe: run every scene and
  formulation to 50 % compression and print the compression of its last converged increment
  and up to where its reaction is the closed form's, and for those that stop or leave it, the
  largest multiple of 5 % that completes on the closed form; --meshes: probe the
  uniaxial scenes on these elements per edge instead of the scenes' (e.g. 4).
"""

import argparse
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
C10 = 0.5e6
D1 = 4e-8
COMPRESSION = 0.5
# scene: (dimension, elements per edge, sides held in x)
SCENES = {"2d-uniaxial": (2, 1, False), "2d-confined": (2, 4, True), "3d-uniaxial": (3, 1, False)}
ELEMENTS = {2: ["CPE4R", "CPE4", "CPE4H", "CPE4I"], 3: ["C3D8R", "C3D8", "C3D8H", "C3D8I"]}
# Largest relative error of the reaction against the closed form that counts as on it.
ON_CLOSED_FORM = 1e-4


def deck(dim, n, confined, element, compression):
    """The deck of the block of n x n (x n) elements of `element`, its sides held in x if
    `confined`, compressed by `compression` (a fraction of its height)."""
    layers = n + 1 if dim == 3 else 1

    def label(i, j, k=0):
        return 1 + i + (n + 1) * j + (n + 1) ** 2 * k

    lines = ["*HEADING", f"uniaxial compression on rollers, {element}", "*NODE"]
    for k in range(layers):
        for j in range(n + 1):
            for i in range(n + 1):
                x = [i / n, j / n, k / n][:dim]
                lines.append(f"{label(i, j, k)}, " + ", ".join(repr(c) for c in x))
    lines.append(f"*ELEMENT, TYPE={element}, ELSET=block")
    number = 0
    for k in range(layers - 1 if dim == 3 else 1):
        for j in range(n):
            for i in range(n):
                face = [label(i, j, k), label(i + 1, j, k), label(i + 1, j + 1, k), label(i, j + 1, k)]
                corners = face if dim == 2 else face + [m + (n + 1) ** 2 for m in face]
                number += 1
                lines.append(f"{number}, " + ", ".join(map(str, corners)))
    bottom = [label(i, 0, k) for k in range(layers) for i in range(n + 1)]
    top = [label(i, n, k) for k in range(layers) for i in range(n + 1)]
    corner = label(n, n, n if dim == 3 else 0)
    lines += ["*NSET, NSET=bottom", ", ".join(map(str, bottom))]
    lines += ["*NSET, NSET=top", ", ".join(map(str, top))]
    lines += ["*NSET, NSET=corner", str(corner)]
    if confined:
        sides = [label(i, j, k) for k in range(layers) for j in range(n + 1) for i in (0, n)]
        lines += ["*NSET, NSET=sides", ", ".join(map(str, sides))]
    lines += [
        "*SOLID SECTION, ELSET=block, MATERIAL=rubber",
        "1.0",
        "*MATERIAL, NAME=rubber",
        "*HYPERELASTIC, NEO HOOKE",
        f"{C10!r}, {D1!r}",
        "*DENSITY",
        "1000.0",
        "*BOUNDARY",
        "bottom, 2, 2",
        f"{label(0, 0)}, 1, 1",
    ]
    if confined:
        lines.append("sides, 1, 1")
    if dim == 3:
        lines += [f"{label(0, 0)}, 3, 3", f"{label(n, 0)}, 3, 3"]
    lines += [
        "*STEP, NAME=compress, NLGEOM=YES",
        "*STATIC",
        "0.05, 1.0",
        "*BOUNDARY",
        f"top, 2, 2, {-compression!r}",
        "*OUTPUT, HISTORY",
        "*NODE OUTPUT, NSET=corner",
        "U",
        "*END STEP",
    ]
    return "\n".join(lines) + "\n"


def closed_form_reaction(dim, confined, l2):
    """The top's reaction at the vertical stretch l2 (the report's closed form): the Kirchhoff
    stress tau_ii = 2 C10 J^(-2/3) (li^2 - I1 / 3) + 2 J (J - 1) / D1, the free lateral
    stretch from tau_11 = 0 (by bisection), R = tau_22 / l2 on the unit area."""

    def tau(l, i):
        j = l[0] * l[1] * l[2]
        i1 = sum(s * s for s in l)
        return 2 * C10 * j ** (-2 / 3) * (l[i] ** 2 - i1 / 3) + 2 * j * (j - 1) / D1

    def stretches(s):
        return [s, l2, s if dim == 3 else 1.0]

    s = 1.0
    if not confined:
        lo, hi = 1e-6, 1e6
        for _ in range(200):
            mid = (lo * hi) ** 0.5
            lo, hi = (mid, hi) if tau(stretches(mid), 0) < 0 else (lo, mid)
        s = (lo * hi) ** 0.5
    return tau(stretches(s), 1) / l2


def reached(skid, scene, element, compression, work, n=None):
    """The compression of the last converged increment of a run of `scene` to `compression`
    (on n elements per edge, if given), whether the run completed, and the largest compression
    up to which the reaction is the closed form's (to ON_CLOSED_FORM)."""
    dim, own, confined = SCENES[scene]
    path = work / f"{scene}-{element}-{compression}.inp"
    path.write_text(deck(dim, n or own, confined, element, compression))
    out = work / path.stem
    run = subprocess.run([skid, "run", str(path), "--out", str(out)], capture_output=True)
    with open(out / "history.csv", newline="") as f:
        rows = list(csv.DictReader(f))[1:]
    followed = 0.0
    for row in rows:
        c = compression * float(row["load_factor"])
        expected = closed_form_reaction(dim, confined, 1.0 - c)
        if abs(float(row["top.reaction_y"]) / expected - 1.0) > ON_CLOSED_FORM:
            break
        followed = c
    last = compression * float(rows[-1]["load_factor"]) if rows else 0.0
    return last, run.returncode == 0, followed


def probe(skid, meshes):
    """Prints how far every scene and formulation gets towards 50 %, and up to where its
    reaction is the closed form's; for those that stop or leave it, the largest multiple of 5 %
    that completes on the closed form."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for scene, (dim, own, confined) in SCENES.items():
            for n in [own] if confined else meshes or [own]:
                for element in ELEMENTS[dim]:
                    c, done, followed = reached(skid, scene, element, COMPRESSION, work, n)
                    what = "completed" if done else "stopped"
                    print(
                        f"{scene} {n} per edge {element}: to 50 %: {what} at {100 * c:.1f} %, "
                        f"on the closed form up to {100 * followed:.1f} %"
                    )
                    if not done or followed < c:
                        carried = 0.0
                        for k in range(1, 10):
                            c, done, followed = reached(skid, scene, element, k * 0.05, work, n)
                            if done and followed >= c - 1e-12:
                                carried = k * 0.05
                        print(f"  completes on the closed form up to {100 * carried:.0f} %")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("--dir", default=str(ROOT / "cases/verification"))
    parser.add_argument("--probe", action="store_true")
    parser.add_argument("--skid", default=str(ROOT / "target/release/skid"))
    parser.add_argument("--meshes", type=int, nargs="+")
    args = parser.parse_args()
    if args.probe:
        if not Path(args.skid).exists():
            sys.exit(f"compression.py: no skid binary at {args.skid} (cargo build --release -p skid-cli)")
        probe(args.skid, args.meshes)
        return
    directory = Path(args.dir)
    directory.mkdir(parents=True, exist_ok=True)
    for scene, (dim, n, confined) in SCENES.items():
        for element in ELEMENTS[dim]:
            name = scene.replace("-", "-compression-", 1)
            path = directory / f"{name}-{element.lower()}.inp"
            path.write_text(deck(dim, n, confined, element, COMPRESSION))
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
