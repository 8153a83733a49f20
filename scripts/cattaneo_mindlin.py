#!/usr/bin/env python3
"""Writes the Cattaneo-Mindlin verification scenes
cases/verification/2d-cattaneo-mindlin-<element>-nN.json: the Hertz scene of scripts/hertz.py
with friction, pressed and then pushed sideways by less than the friction can carry.

The scene (SI units): the rigid cylinder (R = 50 mm) of scripts/hertz.py on an elastic block
(neo-Hookean, E = 10 MPa, nu = 0.49) 2 W wide and D deep, W = D = 100 a, its bottom held,
frictional contact with mu = 0.3 on the top nodes with |x| <= 3 a. Step `press` (static, 10
increments) ramps the normal load P (a = 0.05 R = 2.5 mm) with the cylinder held in x; step
`shift` (static, 10 increments) frees it in x and ramps a tangential load Q = 0.5 mu P with P
held. The cylinder never turns (rz held).

Cattaneo-Mindlin: the pressure stays Hertz's, p(x) = p0 sqrt(1 - x^2 / a^2); the contact
sticks on |x| < c, c = a sqrt(1 - Q / (mu P)) = 0.707 a, and slips outside, where
q = mu p; in the stick zone q(x) = mu p0 [sqrt(1 - x^2 / a^2) - (c / a) sqrt(1 - x^2 / c^2)].

Why these values:
- nu = 0.49: the answer assumes the normal and tangential problems uncoupled, which a rigid
  cylinder on an elastic block is only when Dundurs' beta = (1 - 2 nu) / (2 (1 - nu)) is small
  against mu (beta / mu = 0.065 here). At nu = 0.3 (beta / mu = 0.95) the run sticks on one
  side and slips over the whole other half, as Nowell, Hills and Sackfield's coupled solution
  says, so Mindlin's answer is not the reference there.
- W = D = 100 a: a tangential load on a block held at its bottom tilts its top, which the
  half-space answer does not see; on a block of 10 a (the Hertz scenes' size) the stick-zone
  traction at x = -/+ 0.59 a is 54 % above and 28 % below Mindlin's, on 30 a 1 % above and
  9 % below, on 100 a within 2 % (RMS over the contact: 2.3 % of mu p0 on CPE4R, N = 8). The graded mesh makes the larger block cost little.

Elements: CPE4R (one-point, hourglass control), CPE4H (hybrid) and CPE4I (incompatible
modes); mesh levels N = 8 and 16 (elements of a / (N + 1/2) near the contact). The
displacement element CPE4 locks at this nu and is left out.

Usage: scripts/cattaneo_mindlin.py [--levels N ...] [--elements E ...] [--out DIR]
"""

import argparse
from pathlib import Path

import hertz

ROOT = Path(__file__).resolve().parent.parent

POISSON = 0.49
MU = 0.3
# Q / (mu P).
TANGENTIAL_FRACTION = 0.5
# Block half-width and depth, in a.
SIZE = 100.0
A_OVER_R = 0.05
INCREMENTS = 10


def scene(level, element):
    """The model file (a dict) of mesh level `level` with elements `element`."""
    doc = hertz.scene(level, SIZE, A_OVER_R, poisson=POISSON, element=element)
    load = -doc["loads"][0]["force"][1]
    tangential = TANGENTIAL_FRACTION * MU * load
    doc["name"] = f"2d-cattaneo-mindlin-{element.lower()}-n{level}"
    doc["description"] = (
        f"Verification (2D, plane strain): Cattaneo-Mindlin. A rigid cylinder "
        f"(R = {hertz.RADIUS} m) pressed on an elastic block ({2 * SIZE:g} a wide, {SIZE:g} a "
        f"deep, bottom held; neo-Hookean, E = {hertz.YOUNG:g} Pa, nu = {POISSON}) by "
        f"P = {load:.6g} N per metre (a = {A_OVER_R * hertz.RADIUS:g} m) with friction "
        f"mu = {MU}, then pushed sideways by Q = {TANGENTIAL_FRACTION} mu P = {tangential:.6g} "
        f"N per metre. Mindlin: stick for |x| < c = a sqrt(1 - Q / (mu P)), "
        f"q = mu p0 [sqrt(1 - x^2 / a^2) - (c / a) sqrt(1 - x^2 / c^2)] there and mu p outside. "
        f"{element}, mesh level N = {level}. Written by scripts/cattaneo_mindlin.py; checked "
        f"by skid report --verification."
    )
    doc["boundary"] = [
        {"body": "indenter", "dofs": ["rz"]},
        {"node_set": "bottom", "dofs": ["x", "y"]},
    ]
    doc["loads"] = [
        {"type": "concentrated", "body": "indenter", "force": [0.0, -load],
         "step_factors": [1.0, 1.0]},
        {"type": "concentrated", "body": "indenter", "force": [tangential, 0.0],
         "step_factors": [0.0, 1.0]},
    ]
    doc["contact"][0]["mu"] = MU
    doc["steps"] = [
        {"type": "static", "name": "press", "increments": INCREMENTS,
         "boundary": [{"body": "indenter", "dofs": ["x"]}]},
        {"type": "static", "name": "shift", "increments": INCREMENTS},
    ]
    return doc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[8, 16])
    parser.add_argument("--elements", nargs="+", default=["CPE4R", "CPE4H", "CPE4I"])
    parser.add_argument("--out", type=Path, default=ROOT / "cases" / "verification")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for element in args.elements:
        for level in args.levels:
            doc = scene(level, element)
            path = args.out / f"{doc['name']}.json"
            path.write_text(hertz.dump(doc))
            print(f"{path}: {len(doc['part']['nodes'])} nodes")


if __name__ == "__main__":
    main()
