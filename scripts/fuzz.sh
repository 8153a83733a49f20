#!/usr/bin/env bash
# Fuzz campaign: the property tests of crates/skid-cases/tests/fuzz_inputs.rs (the case-file
# parser and validator, the --set overrides, the model-file parser, the deck keyword reader),
# built in release and run again and again with fresh random seeds until each target has used
# its CPU budget.
#
#   scripts/fuzz.sh [CPU_MINUTES_PER_TARGET [TARGET...]]
#
# CPU_MINUTES_PER_TARGET defaults to 10; the targets default to all five. CASES sets the inputs
# per round (default 2000); PROFILE the cargo profile of the test binary (default release;
# `dev` reuses the binary of `cargo test`). A failing round keeps its minimal input's seed in
# crates/skid-cases/proptest-regressions/fuzz_inputs/<target>.txt (replayed first by every
# later run, so commit it with the fix) and its log in out/fuzz/<target>-<round>.log.
# Prints per target: CPU time, rounds, cases run, inputs tried (shrinking included), failing
# rounds. Exit status 0 only if no round failed.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-10}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(case_files overrides model_files deck_keywords deck_models)
fi
cases=${CASES:-2000}
budget=$(awk -v m="$minutes" 'BEGIN { printf "%d", m * 60 }')
out=out/fuzz
mkdir -p "$out"

profile=${PROFILE:-release}
binary=$(cargo test --profile "$profile" -p skid-cases --test fuzz_inputs --no-run --message-format=json |
    sed -n 's/.*"executable":"\([^"]*fuzz_inputs[^"]*\)".*/\1/p' | tail -n 1)
if [ -z "$binary" ]; then
    echo "fuzz: cannot find the fuzz_inputs test binary" >&2
    exit 2
fi

status=0
summary=()
for target in "${targets[@]}"; do
    cpu=0 rounds=0 run=0 tried=0 failures=0
    while awk -v c="$cpu" -v b="$budget" 'BEGIN { exit !(c < b) }'; do
        rounds=$((rounds + 1))
        log="$out/$target-$rounds.log"
        seed=$(od -An -N8 -tu8 /dev/urandom | tr -d ' ')
        TIMEFORMAT='%U %S'
        set +e
        times=$({ time PROPTEST_CASES=$cases PROPTEST_RNG_SEED=$seed \
            "$binary" "$target" --exact --nocapture >"$log" 2>&1; } 2>&1)
        code=$?
        set -e
        cpu=$(awk -v c="$cpu" -v t="$times" 'BEGIN { split(t, a, " "); print c + a[1] + a[2] }')
        line=$(grep -o "fuzz $target: cases [0-9]*, inputs tried [0-9]*" "$log" | tail -n 1 || true)
        if [ -n "$line" ]; then
            tried=$((tried + $(echo "$line" | sed 's/.*inputs tried //')))
        fi
        if [ $code -eq 0 ]; then
            run=$((run + cases))
            rm -f "$log"
        else
            failures=$((failures + 1))
            status=1
            echo "fuzz: $target round $rounds (PROPTEST_RNG_SEED=$seed) failed; see $log" >&2
        fi
    done
    row=$(printf '%-14s cpu %7.1f s  rounds %4d  cases run %9d  inputs tried %9d  failing rounds %d' \
        "$target" "$cpu" "$rounds" "$run" "$tried" "$failures")
    echo "$row"
    summary+=("$row")
done
echo
echo "fuzz campaign, ${minutes} CPU-minutes per target, ${cases} cases per round:"
printf '%s\n' "${summary[@]}"
exit $status
