#!/usr/bin/env python3
"""Cook's membrane with every element formulation: locking and its cure, on 2 x 2 to 64 x 64
meshes, written to validation/cook.md.

The membrane (SI units, 1 m thick, plane strain): the trapezoid with corners (0, 0), (48, 44),
(48, 60), (0, 44), clamped on the left edge x = 0, a uniform shear load F on the right edge
x = 48 (consistent nodal forces, along y). The measured quantity is the vertical displacement
of the mid-point (48, 52) of the loaded edge per unit load, v / F, in the linear limit: the
material is neo-Hookean (C10 = mu / 2, D1 = 2 / K, linear elasticity with E and nu at small
strain) and F is 1e-4 E, so that strains stay near 1e-4.

Two scenes:
- `plane-stress-equivalent`: the classic linear benchmark is in plane stress, E = 1,
  nu = 1/3, converged v = 23.96 for a unit load. A plane-stress solution with (E, nu) is the
  plane-strain one with E' = E (1 + 2 nu) / (1 + nu)^2, nu' = nu / (1 + nu); skid's elements
  are plane strain, so the scene is run with E' = 15/16, nu' = 1/4 and compared with 23.96.
- `nearly-incompressible`: plane strain, E = 250, nu = 0.4999. Its reference is the
  extrapolation of the hybrid element's three finest meshes at their observed order
  (Aitken: `v3 - (v3 - v2)^2 / ((v3 - v2) - (v2 - v1))`; CPE4H converges monotonically from
  below, as the table shows). The verification report's reference, `v E t / F = 18.51`, is
  this extrapolation from 32 x 32, 64 x 64 and 128 x 128 (`--meshes 32 64 128`).

Every deck asks for the displacement of its node set `tip`, the mid-point (48, 52) of the
loaded edge, in `history.csv` (`*NODE OUTPUT, NSET=tip` under `*OUTPUT, HISTORY`), which is
where the measurement reads it.

Usage: scripts/cook.py [--skid PATH] [--meshes N ...] [--out FILE]
       scripts/cook.py --write [--meshes N ...] [--dir DIR]
  --skid: the skid binary (default target/release/skid, built if absent); --meshes: elements
  per edge (default 2 4 8 16 32 64; with --write 2 4 8 16 32); --out: the markdown table
  (default validation/cook.md).
  --write: write the decks of both scenes, every element and mesh, as verification scenes
  `2d-cook-<scene>-<element>-n<N>.inp` into DIR (default cases/verification), run nothing.
"""

import argparse
import csv
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PLANE_STRESS_REFERENCE = 23.96
ELEMENTS = ["CPE4R", "CPE4", "CPE4H", "CPE4I"]
SCENES = {
    # name: (E, nu)
    "plane-stress-equivalent": (15.0 / 16.0, 0.25),
    "nearly-incompressible": (250.0, 0.4999),
}
# The short names of the scenes in the verification decks' file names.
SHORT = {"plane-stress-equivalent": "linear", "nearly-incompressible": "incompressible"}


def corner(i, j, n):
    """The node (i, j) of the n x n mesh: bilinear map of the unit square onto the trapezoid."""
    s, t = i / n, j / n
    bottom, top = 44.0 * s, 44.0 + 16.0 * s
    return 48.0 * s, bottom + (top - bottom) * t


def deck(n, element, young, poisson):
    """The deck of the n x n membrane of `element` for linear moduli E, nu."""
    mu = young / (2.0 * (1.0 + poisson))
    bulk = young / (3.0 * (1.0 - 2.0 * poisson))
    load = 1e-4 * young

    def label(i, j):
        return j * (n + 1) + i + 1

    lines = ["*HEADING", f"Cook's membrane {n} x {n} {element}", "*NODE"]
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = corner(i, j, n)
            lines.append(f"{label(i, j)}, {x!r}, {y!r}")
    lines.append(f"*ELEMENT, TYPE={element}, ELSET=membrane")
    for j in range(n):
        for i in range(n):
            corners = [label(i, j), label(i + 1, j), label(i + 1, j + 1), label(i, j + 1)]
            lines.append(f"{j * n + i + 1}, " + ", ".join(map(str, corners)))
    lines.append("*NSET, NSET=clamped")
    lines.append(", ".join(str(label(0, j)) for j in range(n + 1)))
    lines.append("*NSET, NSET=tip")
    lines.append(f"{label(n, n // 2)}")
    lines += [
        "*SOLID SECTION, ELSET=membrane, MATERIAL=linear",
        "1.0",
        "*MATERIAL, NAME=linear",
        "*HYPERELASTIC, NEO HOOKE",
        f"{mu / 2.0!r}, {2.0 / bulk!r}",
        "*DENSITY",
        "1.0",
        "*BOUNDARY",
        "clamped, 1, 2",
        "*STEP, NAME=shear, NLGEOM=YES",
        "*STATIC",
        "1.0, 1.0",
        "*CLOAD",
    ]
    # the edge is straight, of length 16, loaded uniformly: half shares at its ends
    for j in range(n + 1):
        share = (0.5 if j in (0, n) else 1.0) / n
        lines.append(f"{label(n, j)}, 2, {load * share!r}")
    lines += ["*OUTPUT, HISTORY", "*NODE OUTPUT, NSET=tip", "U", "*END STEP"]
    return "\n".join(lines) + "\n", load


def tip_deflection(skid, n, element, young, poisson, work):
    """v / F at (48, 52) of a run, or None with the run's error if it failed."""
    text, load = deck(n, element, young, poisson)
    name = f"cook-{element}-{n}-{poisson}"
    path = work / f"{name}.inp"
    path.write_text(text)
    out = work / name
    run = subprocess.run(
        [skid, "run", str(path), "--out", str(out)], capture_output=True, text=True
    )
    if run.returncode != 0:
        return None, run.stderr.strip().splitlines()[-1] if run.stderr else "failed"
    with open(out / "history.csv", newline="") as f:
        last = list(csv.DictReader(f))[-1]
    # the mid-point (48, 52) is node (n, n / 2): label n / 2 (n + 1) + n + 1, numbered from 0
    node = (n // 2) * (n + 1) + n
    return float(last[f"tip.{node}.u_y"]) / load, None


def write_scenes(meshes, directory):
    """Writes the deck of every scene, element and mesh of `meshes` into `directory`."""
    directory.mkdir(parents=True, exist_ok=True)
    for scene, (young, poisson) in SCENES.items():
        for element in ELEMENTS:
            for n in meshes:
                path = directory / f"2d-cook-{SHORT[scene]}-{element.lower()}-n{n}.inp"
                path.write_text(deck(n, element, young, poisson)[0])
                print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skid", default=str(ROOT / "target/release/skid"))
    parser.add_argument("--meshes", type=int, nargs="+")
    parser.add_argument("--out", default=str(ROOT / "validation/cook.md"))
    parser.add_argument("--write", action="store_true")
    parser.add_argument("--dir", default=str(ROOT / "cases/verification"))
    args = parser.parse_args()
    meshes = args.meshes or ([2, 4, 8, 16, 32] if args.write else [2, 4, 8, 16, 32, 64])
    if any(n % 2 for n in meshes):
        sys.exit("cook.py: meshes must have an even number of elements per edge (a node at 52)")
    if args.write:
        write_scenes(meshes, Path(args.dir))
        return
    if not Path(args.skid).exists():
        subprocess.run(["cargo", "build", "--release", "-p", "skid-cli"], cwd=ROOT, check=True)

    lines = [
        "# Cook's membrane: locking and its cure",
        "",
        "Written by `scripts/cook.py` (see its header for the scene). Vertical displacement of",
        "the loaded edge's mid-point (48, 52) per unit shear load, linear limit, plane strain.",
        "",
    ]
    failures = 0
    checks = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for scene, (young, poisson) in SCENES.items():
            rows = {}
            for element in ELEMENTS:
                rows[element] = []
                for n in meshes:
                    v, error = tip_deflection(args.skid, n, element, young, poisson, work)
                    if error:
                        failures += 1
                        print(f"cook.py: {scene} {element} {n}x{n}: {error}", file=sys.stderr)
                    rows[element].append(v)
                    print(f"{scene} {element} {n}x{n}: {v}", file=sys.stderr)
            if scene == "plane-stress-equivalent":
                reference, what = PLANE_STRESS_REFERENCE, "23.96 (plane stress, E = 1, nu = 1/3)"
            else:
                v1, v2, v3 = rows["CPE4H"][-3:]
                reference = None
                if None not in (v1, v2, v3) and (v3 - v2) != (v2 - v1):
                    reference = v3 - (v3 - v2) ** 2 / ((v3 - v2) - (v2 - v1))
                what = "none" if reference is None else (
                    f"{reference:.4g} (CPE4H extrapolated from its three finest meshes)"
                )
            lines += [
                f"## {scene}: E = {young:g}, nu = {poisson:g}; reference {what}",
                "",
                "| element | " + " | ".join(f"{n} x {n}" for n in meshes) + " |",
                "|---|" + "---|" * len(meshes),
            ]
            for element in ELEMENTS:
                cells = []
                for v in rows[element]:
                    if v is None:
                        cells.append("failed")
                    elif reference:
                        cells.append(f"{v:.4g} ({100.0 * (v / reference - 1.0):+.1f} %)")
                    else:
                        cells.append(f"{v:.4g}")
                lines.append(f"| {element} | " + " | ".join(cells) + " |")
            lines.append("")
            # the finest mesh of every locking-free element within 0.5 % of the reference;
            # the displacement element locks in the nearly incompressible scene
            for element in ["CPE4R", "CPE4H", "CPE4I"]:
                v = rows[element][-1]
                ok = v is not None and reference and abs(v / reference - 1.0) < 0.005
                checks.append((f"{scene}: {element} finest mesh within 0.5 % of the reference", ok))
            if scene == "nearly-incompressible":
                v = rows["CPE4"][-1]
                ok = v is not None and reference and v < 0.8 * reference
                checks.append((f"{scene}: CPE4 locks (finest mesh over 20 % too stiff)", ok))
    lines += ["## Checks", ""]
    lines += [f"- {'pass' if ok else 'FAIL'}: {what}" for what, ok in checks]
    lines.append("")
    failures += sum(1 for _, ok in checks if not ok)
    Path(args.out).write_text("\n".join(lines))
    print(f"wrote {args.out}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
