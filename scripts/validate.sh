#!/usr/bin/env bash
# The drum validation: builds skid (release); runs every drum idealization of cases/drum and
# every hard case of cases/hard in parallel, and the convergence study (scripts/convergence.sh);
# runs the verification scenes of cases/verification (blocks on a flat and an incline, Hertz,
# Cattaneo-Mindlin, Cook's membrane, compression);
# writes the report validation/report.md (benchmark, hard cases, convergence, verification, and
# the last measured scaling study, stress sweep and pad failure loads of validation/) with its
# plots;
# checks that the input decks of cases/inp stop where their case files do (scripts/check_decks.py);
# and checks the 2D benchmark's convergence in time step, its insensitivity to the pad density,
# that the conic (clarabel) Coulomb solve gives the run of the default Newton-first one, and
# that the 2D and 3D spin-downs do not depend on the hourglass stabilisation's stiffness.
# Results go to out/ (the drum runs to out/drum/runs, where scripts/drum.sh puts them too).
# Exit status 0 only if every run completed and every check passed.
#
# HARD_CASES: the hard case files or directories to run instead of cases/hard (words, globs
# allowed), e.g. HARD_CASES='cases/hard/2d-*.json'.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p skid-cli
skid=${CARGO_TARGET_DIR:-target}/release/skid

status=0
"$skid" batch cases/drum --out out/drum/runs || status=1
# shellcheck disable=SC2206 # split into words and expand globs on purpose
hard=(${HARD_CASES:-cases/hard})
rm -rf out/hard # runs of cases left out must not stay in the report
"$skid" batch "${hard[@]}" --out out/hard || status=1
SKID="$skid" scripts/convergence.sh out/convergence || status=1
# the verification scenes, model files and decks
rm -rf out/verification
"$skid" batch cases/verification --out out/verification >/dev/null || status=1
# the cost against problem size, the stress sweep and the pad formulations' failure loads, as
# last measured (scripts/scaling.py, scripts/stress.py and scripts/pressure_limit.py take too
# long to run here)
measured=()
[ -f validation/scaling.json ] && measured+=(--scaling validation/scaling.json)
[ -f validation/stress.json ] && measured+=(--stress validation/stress.json)
[ -f validation/pressure-limit.json ] && measured+=(--pressure-limit validation/pressure-limit.json)
"$skid" report --runs out/drum/runs --hard out/hard --convergence out/convergence \
    --verification out/verification "${measured[@]}" --out validation/report.md || status=1

out=out/validation
mkdir -p "$out"
run() { # name case [overrides...]
    local name=$1 case=$2; shift 2
    local sets=()
    for o in "$@"; do sets+=(--set "$o"); done
    "$skid" run "$case" --out "$out/$name" "${sets[@]}" >/dev/null || status=1
}
run 2d-analytic cases/drum/2d-analytic.json
run 2d-analytic-dt-half cases/drum/2d-analytic.json 'steps[1].dt=5e-5'
run 2d-analytic-density-x2 cases/drum/2d-analytic.json 'pad.density=2000'
run 2d-analytic-conic cases/drum/2d-analytic.json 'solver.coulomb_method="conic"'
run 3d-analytic cases/drum/3d-analytic.json
for d in 2d 3d; do
    for scale in 0.5 2; do
        run "$d-analytic-hourglass-x$scale" "cases/drum/$d-analytic.json" "pad.hourglass_scale=$scale"
    done
done
python3 scripts/check_drum.py "$out" || status=1
# the input decks of cases/inp against the case files' runs
rm -rf out/inp
"$skid" batch cases/inp --out out/inp >/dev/null || status=1
python3 scripts/check_decks.py out/inp out/drum/runs || status=1
exit $status
