#!/usr/bin/env bash
# Runs every fuzz target of a HAET_FUZZ build (make fuzz) for FUZZ_SECONDS each, FUZZ_JOBS at a time.
#   tests/fuzz/run.sh [BUILD_DIR]          (default build-fuzz)
#   FUZZ_SECONDS  seconds per target (default: one hour over all targets)
#   FUZZ_JOBS     targets run side by side (default 1)
#   FUZZ_TARGETS  which targets (default: all, as CMakeLists.txt's HAET_FUZZ_TARGETS lists them)
# Each target starts from its seeds, tests/fuzz/corpus/TARGET/ (and examples/*.toml for the scenario target), and grows a working corpus in
# BUILD_DIR/fuzz/corpus/TARGET/; its log is BUILD_DIR/fuzz/TARGET.log. An input that crashes, hangs (over 30 s),
# exhausts memory (2 GB) or draws a sanitizer report is written to BUILD_DIR/fuzz/artifacts/TARGET/: copy it into
# tests/fuzz/corpus/TARGET/ with the fix, so that fuzz_replay_TARGET keeps testing it. Exit status: 0 when no target
# found anything.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "${1:-build-fuzz}" && pwd)"
if [ -n "${FUZZ_TARGETS:-}" ]; then
    read -r -a targets <<<"$FUZZ_TARGETS"
else
    mapfile -t targets <"$build/fuzz_targets.txt"
fi
seconds="${FUZZ_SECONDS:-$((3600 / ${#targets[@]}))}"
jobs="${FUZZ_JOBS:-1}"
out="$build/fuzz"
mkdir -p "$out"

run_one() {
    local t="$1"
    mkdir -p "$out/corpus/$t" "$out/artifacts/$t"
    # The scenario target also starts from every scene of examples/ (CMakeLists.txt, HAET_FUZZ_SEEDS_scenario).
    if [ "$t" = scenario ]; then cp "$here/../../examples/"*.toml "$out/corpus/$t/"; fi
    local status=0
    "$build/fuzz_$t" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$out/artifacts/$t/" "$out/corpus/$t" "$here/corpus/$t" >"$out/$t.log" 2>&1 || status=$?
    local runs
    runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$t.log" | tail -1)"
    if [ "$status" = 0 ]; then
        echo "$t: ${runs:-?} executions in ${seconds} s, no finding"
    else
        echo "$t: ${runs:-?} executions, FOUND (exit $status): $out/artifacts/$t/, log $out/$t.log"
    fi
    return "$status"
}

echo "fuzzing ${targets[*]} for ${seconds} s each, ${jobs} at a time; logs in $out"
failed=0
running=0
for t in "${targets[@]}"; do
    [ -x "$build/fuzz_$t" ] || { echo "$t: no $build/fuzz_$t (make fuzz builds it)"; failed=1; continue; }
    run_one "$t" &
    running=$((running + 1))
    if [ "$running" -ge "$jobs" ]; then
        wait -n || failed=1
        running=$((running - 1))
    fi
done
while [ "$running" -gt 0 ]; do
    wait -n || failed=1
    running=$((running - 1))
done
exit "$failed"
