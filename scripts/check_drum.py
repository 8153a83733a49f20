"""Checks the drum validation runs written by scripts/validate.sh and prints a table.

Acceptance (DRUM.md sections 2.2 and 3):
- t_stop in [0.0990, 0.1015] s; deceleration within 1.5 % of 600 rad/s^2;
- after the stop (to t = 0.15 s): |omega| < 5 rad/s, angle within 0.03 rad of its value at the stop;
- energy balance error < 0.5 %; penetration and sliding separation < 1e-6 m;
- halving the time step changes t_stop by < 0.2 %; doubling the pad density by < 0.5 %;
- the conic (clarabel-led) Coulomb solve gives the same run as the Newton-first default: t_stop
  within 1e-4 relative (both solve the same discrete problem to the natural-map tolerance; the
  margin allows the pad vibration to amplify round-off over 1500 increments), and it did call
  clarabel;
- halving or doubling the hourglass stabilisation (pad.hourglass_scale) of the 2D and 3D
  benchmark pads changes the deceleration by < 0.1 % and t_stop by < 1 % (the benchmark's
  tolerance between idealisations): on the single-layer pads the hourglass modes carry part of
  the pad's bending (hourglass energy 3-16 % of the strain energy, in proportion to the scale),
  and this shows that their stiffness does not drive the spin-down.
"""
import json
import sys
from pathlib import Path


def load(out, name):
    return json.loads((Path(out) / name / "summary.json").read_text())


def main(out):
    base = load(out, "2d-analytic")
    half = load(out, "2d-analytic-dt-half")
    heavy = load(out, "2d-analytic-density-x2")
    conic = load(out, "2d-analytic-conic")
    checks = []

    def check(label, value, ok, fmt="{:.6g}"):
        checks.append((label, fmt.format(value) if value is not None else "none", bool(ok)))


    for label, run in (("benchmark", base), ("dt / 2", half), ("density x 2", heavy), ("conic", conic)):
        checks.append((f"{label}: {run['case']} completed ({run['increments']} increments, {run['wall_time_s']:.2f} s)", run["status"], run["status"] == "completed"))
    ts = base["t_stop"]
    check("t_stop [s] in [0.0990, 0.1015]", ts, ts is not None and 0.0990 <= ts <= 0.1015)
    dec = base["deceleration"]
    check("deceleration [rad/s^2] within 1.5 % of 600", dec, dec is not None and abs(dec - 600) <= 9)
    po = base["post_stop_max_abs_omega"]
    check("post-stop max |omega| [rad/s] < 5", po, po is not None and po < 5)
    pa = base["post_stop_max_angle_change"]
    check("post-stop max angle change [rad] < 0.03", pa, pa is not None and pa < 0.03)
    eb = base["energy_balance_error"]
    check("energy balance error < 0.5 %", eb, eb is not None and eb < 0.005, "{:.3e}")
    check("max penetration [m] < 1e-6", base["max_gap_violation_m"], base["max_gap_violation_m"] < 1e-6, "{:.3e}")
    check("max sliding separation [m] < 1e-6", base["max_sliding_separation_m"], base["max_sliding_separation_m"] < 1e-6, "{:.3e}")
    for label, other, tol in (("dt/2", half, 0.002), ("density x2", heavy, 0.005), ("the conic Coulomb solve", conic, 1e-4)):
        t = other["t_stop"]
        rel = abs(t - ts) / ts if (t is not None and ts is not None) else None
        check(f"t_stop change with {label} < {tol:.2%}", rel, rel is not None and rel < tol, "{:.3e}")

    check("conic Coulomb solve: clarabel solves", conic["contact_solves"], conic["contact_solves"] > 0, "{}")

    for dim in ("2d", "3d"):
        ref = load(out, f"{dim}-analytic")
        for scale in ("0.5", "2"):
            run = load(out, f"{dim}-analytic-hourglass-x{scale}")
            label = f"{dim} hourglass_scale x {scale}"
            checks.append((f"{label}: completed (max hourglass / strain energy {run['max_hourglass_ratio']:.2%}, at x 1 {ref['max_hourglass_ratio']:.2%})", run["status"], run["status"] == "completed"))
            for key, tol in (("deceleration", 0.001), ("t_stop", 0.01)):
                a, b = run[key], ref[key]
                rel = abs(a - b) / abs(b) if (a is not None and b) else None
                check(f"{label}: {key} change < {tol:.1%}", rel, rel is not None and rel < tol, "{:.3e}")

    width = max(len(c[0]) for c in checks)
    for label, value, ok in checks:
        print(f"{'PASS' if ok else 'FAIL'}  {label:<{width}}  {value}")
    failed = [c for c in checks if not c[2]]
    print(f"{len(checks) - len(failed)} passed, {len(failed)} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "out/validation"))
