#!/usr/bin/env bash
# What each pad element costs for the drum's accuracy: runs `skid bench` on the benchmark's
# analytical-drum cases (2D and 3D) at the case's own time step and three pad meshes (the
# case's, then twice and four times its elements in every direction), the case as written,
# with each pad element formulation (full first: every element's levels are measured against
# the finest full-integration pad), then copies bench.md, bench.json and the work-precision
# plots into validation/elements/. The runs stay in out/bench-elements/runs/. Exit status:
# that of skid bench (1 if some run stopped early).
#
# BENCH_CASES: the case files to run instead (words, globs allowed).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p skid-cli
skid=${CARGO_TARGET_DIR:-target}/release/skid
# shellcheck disable=SC2206 # split into words and expand globs on purpose
cases=(${BENCH_CASES:-cases/drum/2d-analytic.json cases/drum/3d-analytic.json})
out=out/bench-elements
rm -rf "$out"
status=0
"$skid" bench "${cases[@]}" --out "$out" --levels 1 --coarser 0 --meshes 3 --repeats 1 \
    --methods case --elements full,reduced,hybrid,incompatible || status=$?
mkdir -p validation/elements
for f in bench.md bench.json work-precision.svg work-precision-mesh.svg; do
    [[ -f $out/$f ]] && cp "$out/$f" "validation/elements/$f"
done
exit $status
