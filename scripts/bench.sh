#!/usr/bin/env bash
# Cost against error: runs `skid bench` on the benchmark's analytical-drum cases (2D and 3D) at
# seven time steps (16x the case's down to a quarter of it) and at three pad meshes (the case's,
# then twice and four times its elements in every direction) with both contact solves, the
# quasi-static pad and the quasi-static pad with adaptive increments, then
# copies bench.md, bench.json and the work-precision plots into validation/. The runs stay in
# out/bench/runs/. Exit status: that of skid bench.
#
# BENCH_CASES: the case files to run instead (words, globs allowed).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p skid-cli
skid=${CARGO_TARGET_DIR:-target}/release/skid
# shellcheck disable=SC2206 # split into words and expand globs on purpose
cases=(${BENCH_CASES:-cases/drum/2d-analytic.json cases/drum/3d-analytic.json})
rm -rf out/bench
status=0
"$skid" bench "${cases[@]}" --out out/bench --levels 7 --coarser 4 --meshes 3 \
    --methods reduced,global,quasi-static,quasi-static-adaptive || status=$?
for f in bench.md bench.json work-precision.svg work-precision-mesh.svg; do
    [[ -f out/bench/$f ]] && cp "out/bench/$f" "validation/$f"
done
exit $status
