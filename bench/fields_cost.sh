#!/usr/bin/env bash
# What the measurements cost a chute step (docs/physics.md L): instruction counts under callgrind of the chute of
# examples/chute3d_profiles.toml, its grains started on a lattice so that the bed is dense from the first step, one
# thread, without and with the [[fields]] block, the series' stress tensors and the contact network, all written
# at every snapshot, the snapshots every 100 steps (far more often than a run writes them: an upper bound on the
# cost at any snapshot period of 100 steps or more). Each case runs 100 and 400 steps; the difference of the totals
# removes the set-up, leaving 300 steps with 3 outputs. The result is appended to
# bench/results/callgrind-x86-64-v3/fields_cost.csv (instruction counts depend on the build, not the machine).
#
#   bench/fields_cost.sh BUILD_V3_DIR [OUT_DIR]    # BUILD_V3_DIR configured with -DHAET_ARCH=x86-64-v3
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
[ $# -ge 1 ] || { echo "usage: $0 BUILD_V3_DIR [OUT_DIR]" >&2; exit 2; }
build=$(cd "$1" && pwd)
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=${2:-$root/runs/bench}
mkdir -p "$out"
haet="$build/haet"
command -v valgrind >/dev/null || { echo "$0: needs valgrind" >&2; exit 1; }

dt=2.5e-4
common=(--set "tdm.dt=$dt" --set 'insert[2].arrangement="lattice"' --set 'insert[2].spacing=1.1'
        --set 'insert[2].radius=0.5' --set 'insert[1].radius=0.5'
        --set "output.snapshot_period=0.025" --set "output.series_period=0.025")
off=(--set output.stress=false --set output.contacts=false --set 'fields[1].period=1e9')
on=(--set output.stress=true --set output.contacts=true --set 'fields[1].period=0.025' --set 'fields[1].window=0')

# count NAME STEPS ARGS...: the instructions of a run of STEPS steps.
count() {
    local name=$1 steps=$2
    shift 2
    local duration
    duration=$(awk -v n="$steps" -v dt="$dt" 'BEGIN { printf "%.6g", n * dt }')
    OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive valgrind --tool=callgrind --callgrind-out-file="$out/$name.cg" \
        "$haet" run "$root/examples/chute3d_profiles.toml" --set "duration=$duration" "${common[@]}" "$@" \
        --threads 1 --quiet --out "$out/$name" 2>"$out/$name.log"
    awk '/^summary:/ { print $2 }' "$out/$name.cg"
}

a100=$(count off100 100 "${off[@]}")
a400=$(count off400 400 "${off[@]}")
b100=$(count on100 100 "${on[@]}")
b400=$(count on400 400 "${on[@]}")
step=$(awk -v a="$a100" -v b="$a400" 'BEGIN { printf "%.0f", (b - a) / 300 }')
extra=$(awk -v a="$a100" -v b="$a400" -v c="$b100" -v d="$b400" 'BEGIN { printf "%.0f", ((d - c) - (b - a)) / 3 }')
share=$(awk -v a="$a100" -v b="$a400" -v c="$b100" -v d="$b400" 'BEGIN { printf "%.4f", ((d - c) - (b - a)) / (b - a) }')
n=$(awk -F, 'NR > 1 && $NF != "" { n++ } END { print n + 0 }' "$out/on400/contacts_000001.csv")
echo "a chute step: $step instructions; one output of fields + stress + contacts ($n contacts): $extra instructions;"
echo "their share of 300 steps with 3 outputs: $share (outputs every 100 steps)"
csv="$root/bench/results/callgrind-x86-64-v3/fields_cost.csv"
[ -f "$csv" ] || echo "benchmark,case,threads,haet_commit,haet_arch,step_instructions,output_instructions,share,steps_per_output,note" >"$csv"
commit=$(git -C "$root" rev-parse --short HEAD)
echo "fields_cost,chute3d_profiles_lattice,1,$commit,x86-64-v3,$step,$extra,$share,100,$(date +%F) 1760 spheres; fields z (80 cells; 1 sample) + series stress + contact network ($n contacts) at every output" >>"$csv"
