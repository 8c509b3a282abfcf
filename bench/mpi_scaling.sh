#!/usr/bin/env bash
# Strong scaling of the granular chute across MPI ranks (docs/parallel.md), HAET beside LAMMPS.
#
#   bench/mpi_scaling.sh BUILD_DIR [3d|2d]
#
# The chute of bench/compare_lammps.sh from its flowing state (bench/data/chute<case>.flowing.data, which
# compare_lammps.sh prepares once with LAMMPS); without it, from the lattice of bench/make_chute_data.sh (the column
# "start" says which). ROUNDS rounds, each running, in alternating order, HAET on 1 and 2 ranks
# (`mpirun -np R haet run --threads 1`) and LAMMPS on 1 and 2 ranks (`mpirun -np R lmp`), STEPS steps each. Times:
# HAET's run.json wall_time (set-up included: reading the file, the first pair list), LAMMPS's "Loop time"; the
# fastest of the rounds of each is kept. Prints the speed-ups (1 rank / 2 ranks) and the HAET / LAMMPS time ratios,
# and appends rows to bench/results/MACHINE/mpi_scaling.csv (MACHINE: bench/lib.sh machine_name, or $MACHINE):
#   date,machine,commit,case,start,particles,steps,code,ranks,seconds,ns_per_particle_step,speedup,load_before,
#   load_after
# Environment: STEPS (5000), ROUNDS (3), LMP (lmp), MPIRUN (mpirun), MACHINE. Exit status: 0 all measured,
# 1 a run failed, 2 usage.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
chute_args "$0" "$@"
STEPS=${STEPS:-5000}
ROUNDS=${ROUNDS:-3}
LMP=${LMP:-lmp}
MPIRUN=${MPIRUN:-mpirun}
machine=${MACHINE:-$(machine_name)}
csv=$here/results/$machine/mpi_scaling.csv
name=chute$case
data=$here/data
runs=$data/runs/mpi_$name
haet=$build/haet
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
command -v "$LMP" >/dev/null || { echo "$0: LAMMPS ($LMP) not found (Debian: apt-get install lammps)" >&2; exit 1; }
command -v "$MPIRUN" >/dev/null || { echo "$0: $MPIRUN not found (Debian: apt-get install openmpi-bin)" >&2; exit 1; }
[ -x "$haet" ] || { echo "$0: $haet not found (build first: make build)" >&2; exit 1; }
mkdir -p "$runs" "$(dirname "$csv")"
log() { printf '%s\n' "$*" >&2; }
calc() { awk "BEGIN { $1 }"; }

start=flowing
datain=$data/$name.flowing.data
if [ ! -s "$datain" ]; then
    start=lattice
    datain=$data/$name.lattice.data
    [ -s "$datain" ] || "$here/make_chute_data.sh" "$case" "$datain" >&2
    log "no $data/$name.flowing.data (bench/compare_lammps.sh prepares it): from the lattice"
fi
particles=$(awk '/ atoms$/ { print $1; exit }' "$datain")
sets=(--set "insert[1].file=\"$datain\"" --set "duration=$(calc "print $STEPS * 1e-4")"
      --set "output.series_period=$(calc "print $STEPS * 1e-4")" --set output.stress=false)
scenario=$root/examples/lammps_$name.toml

commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo NA)
[ -z "$(git -C "$root" status --porcelain --untracked-files=no -- src 2>/dev/null)" ] || commit="$commit+dirty"

# haet_time R: seconds of one HAET run on R ranks (run.json wall_time), or empty.
haet_time() {
    local dir=$runs/haet$1
    rm -rf "$dir"
    "$MPIRUN" -np "$1" --oversubscribe "$haet" run "$scenario" "${sets[@]}" --out "$dir" --threads 1 --quiet \
        > "$dir.log" 2>&1 || { log "HAET on $1 ranks failed: $dir.log"; return 0; }
    python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["wall_time"])' "$dir/run.json"
}
# lmp_time R: LAMMPS's loop time on R ranks, or empty.
lmp_time() {
    local dir=$runs/lammps$1
    rm -rf "$dir"; mkdir -p "$dir"
    (cd "$dir" && "$MPIRUN" -np "$1" --oversubscribe "$LMP" -in "$here/lammps/in.$name.time" -var datain "$datain" \
        -var steps "$STEPS" -var thermo "$STEPS" -log log.lammps -screen none > run.log 2>&1) ||
        { log "LAMMPS on $1 ranks failed: $dir/run.log"; return 0; }
    awk '/^Loop time of/ { t = $4 } END { print t }' "$dir/log.lammps"
}
best() { if [ -z "$1" ] || { [ -n "$2" ] && awk "BEGIN { exit !($2 < $1) }"; }; then echo "$2"; else echo "$1"; fi; }

load_before=$(cut -d' ' -f1 /proc/loadavg)
declare -A t
for key in haet1 haet2 lmp1 lmp2; do t[$key]=""; done
for r in $(seq 1 "$ROUNDS"); do
    if [ $((r % 2)) = 1 ]; then order="haet1 haet2 lmp1 lmp2"; else order="lmp2 lmp1 haet2 haet1"; fi
    for key in $order; do
        code=${key%?} ranks=${key#"$code"}
        if [ "$code" = haet ]; then v=$(haet_time "$ranks"); else v=$(lmp_time "$ranks"); fi
        log "round $r: $code on $ranks ranks: ${v:-failed} s"
        t[$key]=$(best "${t[$key]}" "$v")
    done
done
load_after=$(cut -d' ' -f1 /proc/loadavg)

status=0
[ -s "$csv" ] || echo "date,machine,commit,case,start,particles,steps,code,ranks,seconds,ns_per_particle_step,speedup,load_before,load_after" > "$csv"
now=$(date -u +%Y-%m-%dT%H:%M:%SZ)
printf '%-7s %5s %10s %12s %8s\n' code ranks seconds 'ns/(p*step)' speedup
for code in haet lmp; do
    for ranks in 1 2; do
        s=${t[$code$ranks]}
        if [ -z "$s" ]; then status=1; continue; fi
        ns=$(calc "printf \"%.2f\", $s / ($particles * $STEPS) * 1e9")
        up=NA
        [ -n "${t[${code}1]}" ] && up=$(calc "printf \"%.3f\", ${t[${code}1]} / $s")
        label=$([ "$code" = lmp ] && echo lammps || echo haet)
        printf '%-7s %5s %10s %12s %8s\n' "$label" "$ranks" "$s" "$ns" "$up"
        echo "$now,$machine,$commit,$case,$start,$particles,$STEPS,$label,$ranks,$s,$ns,$up,$load_before,$load_after" >> "$csv"
    done
done
for ranks in 1 2; do
    if [ -n "${t[haet$ranks]}" ] && [ -n "${t[lmp$ranks]}" ]; then
        printf 'HAET / LAMMPS time on %s rank(s): %s\n' "$ranks" "$(calc "printf \"%.3f\", ${t[haet$ranks]} / ${t[lmp$ranks]}")"
    fi
done
echo "load average: $load_before before, $load_after after; rows appended to $csv"
exit $status
