#!/usr/bin/env python3
"""Writes the Hertz verification scenes cases/verification/2d-hertz-nN.json: a rigid cylinder
pressed on an elastic block in plane strain, frictionless, one file per mesh level.

The scene (SI units): a rigid cylinder of radius R = 50 mm, its axis at height R above the top
face y = 0 of an elastic block, so that it touches the block at x = 0. The block is 2 W wide
(x in [-W, W]) and D deep (y in [-D, 0]), its bottom held in x and y, its sides free; its
material is neo-Hookean (C10 = G / 2, C01 = 0, D1 = 2 / K for E = 10 MPa, nu = 0.3), which at
small strain is linear elasticity with these E and nu. The cylinder may only move along y; a
downward force P per unit thickness (the thickness is 1 m) is ramped over a static step of 10
increments. P is chosen so that the plane-strain Hertz half-width is
a = sqrt(4 P R / (pi E*)) = 0.05 R = 2.5 mm, with E* = E / (1 - nu^2); then the peak pressure
p0 = 2 P / (pi a) = E* a / (2 R) is 2.5 % of E*, and the strains stay of that order.

The mesh is a tensor product of two graded coordinate lists: along x, elements of size
h = a / (N + 1/2) for |x| <= 1.5 a, then growing by a factor of at most 1.2 per element out to
W; along y, size h down to a depth of 1.5 a, then growing likewise down to D. N is the level
(4, 8 and 16 by default): the Hertz edge x = a lies in the middle of the element from N h to
(N + 1) h, so that the outermost node in contact says on which side of it the computed edge
lies. The contact candidates are the top nodes with
|x| <= 3 a (the pair `indenter-block`, mu = 0).

Usage: scripts/hertz.py [--levels N ...] [--size S] [--a-over-r Q] [--out DIR]
  --size S: W = D = S a (default 10); --a-over-r Q: a / R (default 0.05); --out: where the
  files go (default cases/verification).
"""

import argparse
import json
import math
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

RADIUS = 0.05
YOUNG = 10e6
POISSON = 0.3
# Largest growth of the element size from one element to the next outside the fine zone.
GROWTH = 1.2
# Extent of the uniformly fine zone (along x from the centre, along y from the top), in a.
FINE_ZONE = 1.5
# Contact candidates: the top nodes with |x| <= this many a.
CANDIDATES = 3.0
INCREMENTS = 10


def graded(fine, fine_extent, extent):
    """Coordinates 0 = c_0 < c_1 < ... = extent: spacing `fine` up to `fine_extent`, then
    spacings growing geometrically (ratio <= GROWTH) to end exactly at `extent`."""
    n_fine = round(fine_extent / fine)
    coords = [i * fine for i in range(n_fine + 1)]
    rest = extent - coords[-1]
    # The fewest elements whose spacings fine r, fine r^2, ... (r <= GROWTH) fill `rest`.
    n = 1
    while fine * sum(GROWTH ** k for k in range(1, n + 1)) < rest:
        n += 1
    lo, hi = 1.0, GROWTH
    for _ in range(200):  # bisection on the ratio that fills `rest` exactly with n spacings
        r = 0.5 * (lo + hi)
        if fine * sum(r ** k for k in range(1, n + 1)) < rest:
            lo = r
        else:
            hi = r
    r = 0.5 * (lo + hi)
    for k in range(1, n + 1):
        coords.append(coords[-1] + fine * r ** k)
    coords[-1] = extent
    return coords


def scene(level, size, a_over_r, poisson=POISSON, element="CPE4R"):
    """The model file (a dict) of mesh level `level` for a block of half-width and depth `size`
    times a, a = `a_over_r` R, of Poisson's ratio `poisson` and element type `element`."""
    e_star = YOUNG / (1.0 - poisson ** 2)
    a = a_over_r * RADIUS
    load = math.pi * e_star * a * a / (4.0 * RADIUS)
    shear = YOUNG / (2.0 * (1.0 + poisson))
    bulk = YOUNG / (3.0 * (1.0 - 2.0 * poisson))
    h = a / (level + 0.5)
    half = graded(h, FINE_ZONE * a, size * a)
    xs = [-x for x in reversed(half[1:])] + half
    ys = [-y for y in reversed(graded(h, FINE_ZONE * a, size * a))]
    nx, ny = len(xs) - 1, len(ys) - 1

    def nid(i, j):
        return j * (nx + 1) + i

    nodes = [[xs[i], ys[j]] for j in range(ny + 1) for i in range(nx + 1)]
    connectivity = [[nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)]
                    for j in range(ny) for i in range(nx)]
    top = [nid(i, ny) for i in range(nx + 1) if abs(xs[i]) <= CANDIDATES * a * (1 + 1e-9)]
    bottom = [nid(i, 0) for i in range(nx + 1)]
    name = f"2d-hertz-n{level}"
    description = (
        f"Verification (2D, plane strain): Hertz contact of a rigid cylinder (R = {RADIUS} m) "
        f"pressed frictionlessly on an elastic block ({2 * size:g} a wide, {size:g} a deep, "
        f"bottom held; neo-Hookean, E = {YOUNG:g} Pa, nu = {poisson}) by P = {load:.6g} N per "
        f"metre of thickness, ramped over a static step. Hertz: E* = E / (1 - nu^2), "
        f"a = sqrt(4 P R / (pi E*)) = {a:g} m, p0 = 2 P / (pi a) = {2 * load / (math.pi * a):.6g} "
        f"Pa, p(x) = p0 sqrt(1 - x^2 / a^2). Mesh level N = {level}: elements of "
        f"a / {level + 0.5} within 1.5 a of the contact, graded outward ({nx} x {ny} elements). Written by "
        f"scripts/hertz.py; checked by skid report --verification."
    )
    return {
        "skid_model": 1,
        "name": name,
        "description": description,
        "dimension": 2,
        "part": {
            "name": "block",
            "nodes": nodes,
            "elements": [{"type": element, "connectivity": connectivity}],
            "node_sets": {"bottom": bottom, "top": top},
            "section": {
                "material": {"type": "polynomial_n1", "c10": shear / 2.0, "c01": 0.0,
                             "d1": 2.0 / bulk},
                "density": 1000.0,
                "thickness": 1.0,
            },
        },
        "rigid_bodies": [{
            "name": "indenter",
            "reference_point": [0.0, RADIUS],
            "mass": 1e-3,
            "surface": {"type": "cylinder", "axis": [0.0, 0.0, 1.0], "radius": RADIUS},
        }],
        "boundary": [
            {"body": "indenter", "dofs": ["x", "rz"]},
            {"node_set": "bottom", "dofs": ["x", "y"]},
        ],
        "loads": [{"type": "concentrated", "body": "indenter", "force": [0.0, -load]}],
        "contact": [{
            "name": "indenter-block",
            "slave": {"type": "node_set", "name": "top"},
            "master": "indenter",
            "mu": 0.0,
        }],
        "steps": [{"type": "static", "name": "press", "increments": INCREMENTS}],
    }


def dump(doc):
    """JSON with one-space indentation and every innermost array of numbers on one line."""
    text = json.dumps(doc, indent=1)
    return re.sub(r"\[\s*([-+0-9.eE,\s]+?)\s*\]",
                  lambda m: "[" + ", ".join(m.group(1).split()).replace(",,", ",") + "]",
                  text) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[4, 8, 16])
    parser.add_argument("--size", type=float, default=10.0)
    parser.add_argument("--a-over-r", type=float, default=0.05)
    parser.add_argument("--out", type=Path, default=ROOT / "cases" / "verification")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for level in args.levels:
        doc = scene(level, args.size, args.a_over_r)
        path = args.out / f"{doc['name']}.json"
        path.write_text(dump(doc))
        print(f"{path}: {len(doc['part']['nodes'])} nodes, "
              f"{len(doc['part']['elements'][0]['connectivity'])} elements")


if __name__ == "__main__":
    main()
