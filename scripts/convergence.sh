#!/usr/bin/env bash
# The convergence study of the drum spin-down: runs the 2D and 3D analytical-drum cases at
# several pad meshes and time steps into OUT/<series>/<level>/ (default OUT: out/convergence),
# for `skid report --convergence OUT`. Each series varies one thing; the report reads what from
# the levels' case.json. The spin-down is cut to 0.11 s: every level stops before 0.102 s, and
# the study compares t_stop and omega(t) up to 0.9 t_stop. The coarsest time steps are there
# for the Newton residual history (more iterations per increment). The 3D uniform mesh series
# goes to 40 x 4 x 4 (a few minutes); 3D also has a series refining the circumference alone.
# Runs one case at a time; exit status 0 only if every run completed.
set -euo pipefail
cd "$(dirname "$0")/.."
skid=${SKID:-target/release/skid}
out=${1:-out/convergence}
status=0

level() { # series level case [overrides...]
    local series=$1 level=$2 case=$3
    shift 3
    local sets=(--set 'steps[1].duration=0.11')
    for o in "$@"; do sets+=(--set "$o"); done
    echo "convergence: $series/$level" >&2
    "$skid" run "$case" --out "$out/$series/$level" "${sets[@]}" >/dev/null || status=1
}
mesh() { # series level case circumferential radial [axial]
    local series=$1 level=$2 case=$3
    local sets=("pad.elements.circumferential=$4" "pad.elements.radial=$5")
    [ $# -ge 6 ] && sets+=("pad.elements.axial=$6")
    level "$series" "$level" "$case" "${sets[@]}"
}

series=(2d-time-step 2d-mesh 3d-time-step 3d-mesh 3d-mesh-circumferential)
for s in "${series[@]}"; do rm -rf "${out:?}/$s"; done # stale levels would join a series
d2=cases/drum/2d-analytic.json
d3=cases/drum/3d-analytic.json
for dt in 1.6e-3 8e-4 4e-4 2e-4 1e-4 5e-5 2.5e-5; do
    level 2d-time-step "dt-$dt" "$d2" "steps[1].dt=$dt"
done
for n in 1 2 4 8; do
    mesh 2d-mesh "$((10 * n))x$n" "$d2" $((10 * n)) $n
done
for dt in 1.6e-3 8e-4 4e-4 2e-4 1e-4 5e-5; do
    level 3d-time-step "dt-$dt" "$d3" "steps[1].dt=$dt"
done
for n in 1 2 4; do
    mesh 3d-mesh "$((10 * n))x${n}x$n" "$d3" $((10 * n)) $n $n
done
for n in 1 2 4; do
    mesh 3d-mesh-circumferential "$((10 * n))x1x1" "$d3" $((10 * n)) 1 1
done
exit $status
