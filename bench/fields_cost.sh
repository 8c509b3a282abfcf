#!/usr/bin/env bash
# What the measurements cost a chute step (docs/physics.md L): instruction counts under callgrind, one thread, of
# the chute of examples/chute3d_profiles.toml once its grains have landed on the base (a prepared checkpoint at
# t = 12, resumed), without and with the [[fields]] block, the series' stress tensors and the contact network, all
# written every 100 steps (far more often than a run writes them: the cost at any snapshot period of 100 steps or
# more is at most this). Each case runs 100 and 400 steps from the checkpoint; the difference of the totals
# removes the set-up and the reading of the checkpoint, leaving 300 steps with 3 outputs. The result is appended to
# bench/results/callgrind-x86-64-v3/fields_cost.csv (instruction counts depend on the build, not the machine).
#
#   bench/fields_cost.sh BUILD_V3_DIR [OUT_DIR]    # BUILD_V3_DIR configured with -DHAET_ARCH=x86-64-v3
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 BUILD_V3_DIR [OUT_DIR]" >&2; exit 2; }
build=$(cd "$1" && pwd)
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${2:-$root/runs/bench}/fields_cost
rm -rf "$out"
mkdir -p "$out"
haet="$build/haet"
scene="$root/examples/chute3d_profiles.toml"
command -v valgrind >/dev/null || { echo "$0: needs valgrind" >&2; exit 1; }

# The step (dt = "auto") from a short run; the outputs every 100 steps.
"$haet" run "$scene" --set duration=0.001 --set output.snapshot_period=-1 --threads 1 -q --out "$out/dt"
dt=$(awk -F': *' '/"dt"/ { gsub(/[ ,]/, "", $2); print $2; exit }' "$out/dt/run.json")
period=$(awk -v dt="$dt" 'BEGIN { printf "%.17g", 100 * dt }')
t0=12
off=(--set output.stress=false --set output.contacts=false --set 'fields[1].period=1e9'
     --set "output.series_period=$period")
on=(--set output.stress=true --set output.contacts=true --set "fields[1].period=$period" --set "fields[1].window=$period"
    --set "fields[1].sample_interval=$period" --set "output.series_period=$period")

# The landed state, once per case (the checkpoint must hold what the case measures).
for c in off on; do
    declare -n sets=$c
    "$haet" run "$scene" --set "duration=$t0" --set output.snapshot_period=6 "${sets[@]}" --threads 1 -q \
        --out "$out/prep_$c"
done

# count CASE STEPS: the instructions of the case resumed for STEPS steps.
count() {
    local c=$1 steps=$2
    declare -n sets=$c
    cp -r "$out/prep_$c" "$out/${c}_$steps"
    local duration
    duration=$(awk -v t="$t0" -v n="$steps" -v dt="$dt" 'BEGIN { printf "%.17g", t + (n + 0.5) * dt }')
    OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive valgrind --tool=callgrind --callgrind-out-file="$out/${c}_$steps.cg" \
        "$haet" run "$scene" --resume "$out/${c}_$steps" --set "duration=$duration" "${sets[@]}" \
        --set output.snapshot_period="$period" --threads 1 -q 2>"$out/${c}_$steps.log"
    awk '/^summary:/ { print $2 }' "$out/${c}_$steps.cg"
}

a100=$(count off 100)
a400=$(count off 400)
b100=$(count on 100)
b400=$(count on 400)
step=$(awk -v a="$a100" -v b="$a400" 'BEGIN { printf "%.0f", (b - a) / 300 }')
extra=$(awk -v a="$a100" -v b="$a400" -v c="$b100" -v d="$b400" 'BEGIN { printf "%.0f", ((d - c) - (b - a)) / 3 }')
share=$(awk -v a="$a100" -v b="$a400" -v c="$b100" -v d="$b400" 'BEGIN { printf "%.4f", ((d - c) - (b - a)) / (b - a) }')
last=$(ls "$out/on_400"/contacts_*.csv | tail -1)
n=$(($(wc -l <"$last") - 1))
echo "a chute step: $step instructions; one output of fields + series stress + contacts ($n contacts): $extra"
echo "instructions; their share of 300 steps with 3 outputs (every 100 steps): $share"
csv="$root/bench/results/callgrind-x86-64-v3/fields_cost.csv"
[ -f "$csv" ] || echo "benchmark,case,threads,haet_commit,haet_arch,step_instructions,output_instructions,share,steps_per_output,date,note" >"$csv"
commit=$(git -C "$root" rev-parse --short HEAD)
echo "fields_cost,chute3d_profiles,1,$commit,x86-64-v3,$step,$extra,$share,100,$(date +%F),1760 spheres at t = 12; fields z (80 cells; 1 sample a window) + series stress (domain + 1 region) + contact network ($n contacts) every 100 steps" >>"$csv"
