#!/usr/bin/env bash
# The drum benchmark, quick: builds skid (release); runs the eight idealizations of cases/drum
# and the reference (3d-analytic-fine) in parallel; writes their report out/drum/report.md
# (spin-down of every idealization against the reference, with plots); and benchmarks
# 2d-analytic's cost against its error over a short ladder of time steps with the dynamic
# pad (fixed and adaptive increments), the quasi-static pad and the quasi-static pad with
# adaptive increments
# (out/drum/bench/bench.md), and the eight idealizations as written, each the median of 5 runs
# after a warm-up, with their total (out/drum/suite/bench.md). Exit status 0 only if every run
# completed and every check passed.
# The full validation (hard cases, convergence study, longer bench) is scripts/validate.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p skid-cli
skid=${CARGO_TARGET_DIR:-target}/release/skid

status=0
rm -rf out/drum
"$skid" batch cases/drum --out out/drum/runs || status=1
"$skid" report --runs out/drum/runs --out out/drum/report.md || status=1
"$skid" bench cases/drum/2d-analytic.json --out out/drum/bench --levels 4 --coarser 2 \
    --repeats 3 --methods case,adaptive,quasi-static,quasi-static-adaptive || status=1
eight=()
for c in 2d-analytic 2d-r2d2 3d-analytic 3d-analytic-general 3d-r3d4 3d-m3d4r 3d-s4r 3d-c3d4; do
    eight+=("cases/drum/$c.json")
done
"$skid" bench "${eight[@]}" --out out/drum/suite --levels 1 --coarser 0 --methods case ||
    status=1
echo "report: out/drum/report.md, bench: out/drum/bench/bench.md and out/drum/suite/bench.md"
exit $status
