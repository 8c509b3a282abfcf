#!/usr/bin/env bash
# What the measurements cost a chute step (docs/physics.md L): instruction counts under callgrind, one thread, of
# the chute of examples/chute3d_profiles.toml once its grains have landed on the base (a prepared checkpoint at
# t = 12, resumed). Four cases, each with its output every 100 steps: none (only the particles' snapshots and the
# series rows, which every case has), the [[fields]] block (a sample and a file every 100 steps), the series' stress
# tensors (domain + region), the contact network at the snapshots. Each case runs 100 and 400 steps from the
# checkpoint; the difference of the totals removes the set-up and the reading of the checkpoint, leaving 300 steps
# with 3 outputs, and the difference to the first case is the cost of one output of that kind. From those the share
# of a step at the example's own schedule: a field sample every sample_interval (counted as a whole output, sample
# and file: an upper bound), a stress row every series_period, a contact network every snapshot_period. Results
# are appended to bench/results/callgrind-x86-64-v3/fields_cost.csv (instruction counts depend on the build, not
# the machine).
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
# The example's schedule [sqrt(d/g)].
key() { awk -F'= *' -v k="$1" '$1 ~ "^"k" *$" { split($2, a, " "); print a[1]; exit }' "$scene"; }
sample=$(key sample_interval)
series=$(key series_period)
snapshot=$(key snapshot_period)
t0=12
base=(--set output.stress=false --set output.contacts=false --set 'fields[1].period=1e9'
      --set "output.series_period=$period")
none=("${base[@]}")
fields=("${base[@]}" --set "fields[1].period=$period" --set "fields[1].window=$period"
        --set "fields[1].sample_interval=$period")
stress=("${base[@]}" --set output.stress=true)
contacts=("${base[@]}" --set output.contacts=true)

# The landed state, once per case (the checkpoint must hold what the case measures).
for c in none fields stress contacts; do
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

declare -A n100 n400
for c in none fields stress contacts; do
    n100[$c]=$(count $c 100)
    n400[$c]=$(count $c 400)
done
step=$(awk -v a="${n100[none]}" -v b="${n400[none]}" 'BEGIN { printf "%.0f", (b - a) / 300 }')
# per CASE: the instructions of one output of that kind.
per() { awk -v a="${n100[none]}" -v b="${n400[none]}" -v c="${n100[$1]}" -v d="${n400[$1]}" \
        'BEGIN { printf "%.0f", ((d - c) - (b - a)) / 3 }'; }
cf=$(per fields)
cs=$(per stress)
cc=$(per contacts)
last=$(ls "$out/contacts_400"/contacts_*.csv | tail -1)
n=$(($(wc -l <"$last") - 1))
every100=$(awk -v s="$step" -v a="$cf" -v b="$cs" -v c="$cc" 'BEGIN { printf "%.4f", (a + b + c) / (100 * s) }')
example=$(awk -v s="$step" -v a="$cf" -v b="$cs" -v c="$cc" -v dt="$dt" -v f="$sample" -v r="$series" \
    -v p="$snapshot" 'BEGIN { printf "%.5f", (a / (f / dt) + b / (r / dt) + c / (p / dt)) / s }')
echo "a chute step: $step instructions; one output: fields $cf, series stress $cs, contact network ($n contacts) $cc"
echo "share of a step: $every100 with all three every 100 steps; $example at the example's schedule" \
     "(a sample every $sample, a row every $series, a snapshot every $snapshot; dt = $dt)"
csv="$root/bench/results/callgrind-x86-64-v3/fields_cost.csv"
[ -f "$csv" ] || echo "benchmark,case,threads,haet_commit,haet_arch,step_instructions,output_instructions,share,steps_per_output,date,note" >"$csv"
commit=$(git -C "$root" rev-parse --short HEAD)
note="1760 spheres at t = 12"
echo "fields_cost,chute3d_profiles,1,$commit,x86-64-v3,$step,$((cf + cs + cc)),$every100,100,$(date +%F),$note; fields z (80 cells; a sample and a file) $cf + series stress (domain + 1 region) $cs + contact network ($n contacts) $cc every 100 steps" >>"$csv"
steps_sample=$(awk -v f="$sample" -v dt="$dt" 'BEGIN { printf "%.0f", f / dt }')
echo "fields_cost,chute3d_profiles_schedule,1,$commit,x86-64-v3,$step,$((cf + cs + cc)),$example,$steps_sample,$(date +%F),$note; the example's schedule: a field sample every $sample (counted as a whole output) + a stress row every $series + a contact network every $snapshot sqrt(d/g)" >>"$csv"
