#!/usr/bin/env bash
# The drum validation: builds skid (release), runs the drum cases and checks them against the
# acceptance figures of ../shared/DRUM.md and the open issues. Results go to out/validation/.
#
# Runs: 2d-analytic at the benchmark settings, with the time step halved, and with the pad
# density doubled. Exit status 0 only if every check passes.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p skid-cli
skid=target/release/skid
out=out/validation
mkdir -p "$out"

run() { # name case [overrides...]
    local name=$1 case=$2; shift 2
    local sets=()
    for o in "$@"; do sets+=(--set "$o"); done
    "$skid" run "$case" --out "$out/$name" "${sets[@]}" >/dev/null
}
run 2d-analytic cases/drum/2d-analytic.json
run 2d-analytic-dt-half cases/drum/2d-analytic.json 'steps[1].dt=5e-5'
run 2d-analytic-density-x2 cases/drum/2d-analytic.json 'pad.density=2000'

python3 scripts/check_drum.py "$out"
