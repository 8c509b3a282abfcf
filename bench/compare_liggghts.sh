#!/usr/bin/env bash
# HAET against LIGGGHTS 3.8 on the 3D silo of examples/silo3d.toml (its two STL meshes and its floor), one core each,
# from the same flowing state, in alternating rounds.
#
#   bench/compare_liggghts.sh BUILD_DIR
#
# 1. Preparation (once): bench/data/silo3d.lattice.data, 6 000 spheres at rest in the silo, none touching
#    (bench/make_silo_data.py); LIGGGHTS lets them fall and flow out of the orifice for PREP_STEPS steps and writes
#    the state to bench/data/silo3d.flowing.data (both kept, git-ignored, made again when missing).
# 2. ROUNDS rounds, LIGGGHTS then HAET in each (L, H, L, H, ...), so that a busy machine slows both alike: each
#    code reads the flowing state, steps SETTLE steps (untimed: its own contact history builds up), then STEPS
#    steps, timed. LIGGGHTS: bench/liggghts/in.silo3d, the "Loop time" of its second run; HAET:
#    examples/silo3d_liggghts.toml stepped by BUILD_DIR/haet_scene_steps (bench/tools/scene_steps.cpp), --threads 1,
#    the time of its one window; by wall clock and by the process's CPU time (LIGGGHTS: bench/liggghts/cpu_mark.sh
#    around its timed run), which stops while it waits for a core. Both under /usr/bin/time -v: the CPU time of the
#    whole process and the peak memory.
# 3. Idle baselines: both codes on a data file of 1 sphere in the same box, 10 steps (memory per particle).
# Prints the time per particle-step of each round, the fastest and the median of each code and their ratios, the
# CPU time per particle-step (whole processes), the peak memory and the bytes per particle, and what both simulated: the spheres that
# left through the orifice during the window (they agree within the spread of two counts of a random outflow,
# 2 sqrt(a + b)), the pair contacts and the spheres touching a wall at the end, the neighbour-list builds. Appends
# one row to bench/results/MACHINE/liggghts_silo.csv (columns: bench/results/README.md).
#
# Environment: ROUNDS (3), SETTLE (2000), STEPS (10000), PREP_STEPS (40000), LIGGGHTS (liggghts), MACHINE, NOTE.
# Exit status: 0 both measured; 1 a code failed or is missing; 2 usage.
set -euo pipefail

[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
[ -d "$1" ] || { echo "$0: build directory not found: $1" >&2; exit 2; }
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
ROUNDS=${ROUNDS:-3}
SETTLE=${SETTLE:-2000}
STEPS=${STEPS:-10000}
PREP_STEPS=${PREP_STEPS:-40000}
LIGGGHTS=${LIGGGHTS:-liggghts}
IDLE_STEPS=10
data=$here/data
runs=$data/runs/silo3d
machine=${MACHINE:-$(machine_name)}
csv=$here/results/$machine/liggghts_silo.csv
scene=$root/examples/silo3d_liggghts.toml
input=$here/liggghts/in.silo3d
meshes=$root/examples/meshes
tool=$build/haet_scene_steps

command -v "$LIGGGHTS" >/dev/null || { echo "$0: LIGGGHTS ($LIGGGHTS) not found (Debian: apt-get install liggghts)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "$0: /usr/bin/time not found (Debian: apt-get install time)" >&2; exit 1; }
[ -x "$tool" ] || { echo "$0: $tool not found (cmake --build $build --target haet_scene_steps)" >&2; exit 1; }
mkdir -p "$data" "$runs" "$(dirname "$csv")"
log() { printf '%s\n' "$*" >&2; }
calc() { awk "BEGIN { $1 }"; }
peak_bytes() { awk -F': *' '/Maximum resident set size/ { printf "%.0f\n", $2 * 1024 }' "$1"; }
cpu_s() { awk -F': *' '/User time|System time/ { c += $2 } END { printf "%.3f\n", c }' "$1"; }
# The value of KEY in a line of KEY=VALUE words (haet_scene_steps).
kv() { tr ' ' '\n' < "$1" | sed -n "s/^$2=//p"; }

# LIGGGHTS: liggghts_run DIR DATA SETTLE STEPS [DATAOUT]; the log is DIR/log.liggghts, the screen DIR/screen.out.
liggghts_run() {
    local dir=$1 datain=$2 settle=$3 steps=$4 out=${5:-}
    mkdir -p "$dir"
    (cd "$dir" && /usr/bin/time -v -o run.time "$LIGGGHTS" -in "$input" -var datain "$datain" -var meshdir "$meshes" \
        -var settle "$settle" -var steps "$steps" -var thermo "$steps" -var write "$([ -n "$out" ] && echo 1 || echo 0)" \
        -var dataout "${out:-none}" -var cpu 1 -var cpumark "$here/liggghts/cpu_mark.sh" -log log.liggghts \
        > screen.out 2>&1)
}
# From a LIGGGHTS log: the last run's loop time, steps, atoms and neighbour builds, and the thermo rows (step atoms
# ke nbelow npair nwall) at the start and the end of that run.
liggghts_parse() {
    awk '/^ *Step +Atoms/ { row = 0; next }
         /^Loop time of/ { t = $4; s = $9; n = $12; on = 0; next }
         /^Neighbor list builds/ { nb = $5 }
         $1 ~ /^[0-9]+$/ && NF == 6 { if (row == 0) first = $0; last = $0; row++ }
         END { split(first, a); split(last, b); print t, s, n, nb, a[4], b[4], b[5], b[6], b[3] }' "$1"
}

# --- 1. Preparation ---------------------------------------------------------------------------------
lattice=$data/silo3d.lattice.data
flowing=$data/silo3d.flowing.data
if [ ! -s "$flowing" ]; then
    [ -s "$lattice" ] || python3 "$here/make_silo_data.py" silo "$lattice"
    log "preparing $flowing: LIGGGHTS lets the lattice flow for $PREP_STEPS steps (one-off, a few minutes)"
    rm -rf "$data/prep/silo3d"
    if ! liggghts_run "$data/prep/silo3d" "$lattice" 0 "$PREP_STEPS" "$flowing.tmp" || [ ! -s "$flowing.tmp" ]; then
        log "LIGGGHTS preparation failed; the end of $data/prep/silo3d/log.liggghts:"
        tail -n 20 "$data/prep/silo3d/log.liggghts" >&2 || true
        rm -f "$flowing.tmp"
        exit 1
    fi
    mv "$flowing.tmp" "$flowing"
fi
idle=$data/silo3d.idle.data
[ -s "$idle" ] || python3 "$here/make_silo_data.py" idle "$idle"
n_file=$(awk '/ atoms$/ { print $1; exit }' "$flowing")
below_file=$(awk '/^Atoms/ { a = 1; next } /^Velocities/ { a = 0 } a && NF >= 7 && $7 < 0 { n++ } END { print n + 0 }' "$flowing")

haet_commit=${HAET_COMMIT:-}
if [ -z "$haet_commit" ]; then
    src_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
    if [ -n "$src_dir" ] && haet_commit=$(git -C "$src_dir" rev-parse --short HEAD 2>/dev/null); then
        [ -z "$(git -C "$src_dir" status --porcelain --untracked-files=no -- src 2>/dev/null)" ] ||
            haet_commit="$haet_commit+dirty"
    else
        haet_commit=NA
    fi
fi
haet_arch=$(sed -n 's/^HAET_ARCH:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
haet_arch=${haet_arch:-NA}
load_before=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo NA)
haet_sets=(--set "insert[1].file=\"$flowing\"")

# --- 2. Rounds --------------------------------------------------------------------------------------
status=0
l_ns=() h_ns=() l_cpu=() h_cpu=() l_wcpu=() h_wcpu=()
tick=$(getconf CLK_TCK)
l_peak="" h_peak=""
for r in $(seq "$ROUNDS"); do
    ldir=$runs/liggghts_$r
    rm -rf "$ldir"
    if liggghts_run "$ldir" "$flowing" "$SETTLE" "$STEPS"; then
        read -r l_loop l_steps l_n l_builds l_below0 l_below l_pairs l_wall l_ke < <(liggghts_parse "$ldir/log.liggghts")
        l_ns+=("$(calc "printf \"%.2f\", $l_loop / ($l_n * $l_steps) * 1e9")")
        l_cpu+=("$(calc "printf \"%.2f\", $(cpu_s "$ldir/run.time") / ($n_file * ($SETTLE + $STEPS)) * 1e9")")
        l_peak=$(peak_bytes "$ldir/run.time")
        # The timed run's CPU time: the two marks of bench/liggghts/cpu_mark.sh around it, in clock ticks.
        l_wcpu+=("$(awk -v n="$l_n" -v s="$l_steps" -v hz="$tick" 'NR == 1 { a = $1 } NR == 2 { b = $1 }
            END { if (NR == 2) printf "%.2f\n", (b - a) / hz / (n * s) * 1e9; else print "NA" }' "$ldir/cpu.ticks")")
    else
        log "LIGGGHTS failed in round $r; see $ldir/log.liggghts"
        status=1
        break
    fi
    hout=$runs/haet_$r.out
    if /usr/bin/time -v -o "$runs/haet_$r.time" "$tool" "$scene" "${haet_sets[@]}" --settle "$SETTLE" --steps "$STEPS" \
            --threads 1 > "$hout" 2> "$runs/haet_$r.err"; then
        h_ns+=("$(kv "$hout" ns_per_particle_step)")
        h_wcpu+=("$(kv "$hout" min_cpu_ns_per_particle_step)")
        h_cpu+=("$(calc "printf \"%.2f\", $(cpu_s "$runs/haet_$r.time") / ($n_file * ($SETTLE + $STEPS)) * 1e9")")
        h_peak=$(peak_bytes "$runs/haet_$r.time")
    else
        log "HAET failed in round $r; see $runs/haet_$r.err"
        status=1
        break
    fi
    log "round $r: LIGGGHTS ${l_ns[-1]}, HAET ${h_ns[-1]} ns/particle-step (CPU time: ${l_wcpu[-1]}, ${h_wcpu[-1]})"
done
[ "${#h_ns[@]}" -gt 0 ] || { log "no round completed"; exit 1; }

# --- 3. Idle baselines --------------------------------------------------------------------------------
liggghts_run "$runs/liggghts_idle" "$idle" 0 "$IDLE_STEPS" >/dev/null 2>&1 || true
/usr/bin/time -v -o "$runs/haet_idle.time" "$tool" "$scene" --set "insert[1].file=\"$idle\"" --steps "$IDLE_STEPS" \
    > /dev/null 2>&1 || true
l_idle=$(peak_bytes "$runs/liggghts_idle/run.time" 2>/dev/null || true)
h_idle=$(peak_bytes "$runs/haet_idle.time" 2>/dev/null || true)
bpp() { [ -n "$1" ] && [ -n "$2" ] && calc "printf \"%.0f\", ($1 - $2) / $n_file" || echo NA; }
l_bpp=$(bpp "$l_peak" "$l_idle")
h_bpp=$(bpp "$h_peak" "$h_idle")

# --- 4. Report ----------------------------------------------------------------------------------------
fastest() { printf '%s\n' "$@" | sort -g | head -n 1; }
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
ratio() { calc "printf \"%.3f\", $1 / $2"; }
lf=$(fastest "${l_ns[@]}") hf=$(fastest "${h_ns[@]}")
lm=$(median "${l_ns[@]}") hm=$(median "${h_ns[@]}")
lc=$(median "${l_cpu[@]}") hc=$(median "${h_cpu[@]}")
lwf=$(fastest "${l_wcpu[@]}") hwf=$(fastest "${h_wcpu[@]}")
lwm=$(median "${l_wcpu[@]}") hwm=$(median "${h_wcpu[@]}")
h_below0=$(kv "$hout" below_before) h_below=$(kv "$hout" below) h_pairs=$(kv "$hout" pair_contacts)
h_wall=$(kv "$hout" on_wall) h_builds=$(kv "$hout" rebuilds) h_ke=$(kv "$hout" kinetic_energy)
l_out=$((l_below - l_below0)) h_out=$((h_below - h_below0))
load_after=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo NA)

echo
echo "silo3d: $n_file spheres ($below_file below the orifice in bench/data/silo3d.flowing.data), $SETTLE steps, then $STEPS timed, one core each"
printf '%-10s %-36s %s\n' "round" "LIGGGHTS / HAET ns per particle-step" "the same by CPU time"
for k in "${!h_ns[@]}"; do printf '%-10s %-36s %s\n' "$((k + 1))" "${l_ns[$k]} / ${h_ns[$k]}" "${l_wcpu[$k]} / ${h_wcpu[$k]}"; done
echo "fastest: LIGGGHTS $lf, HAET $hf ns/particle-step: HAET / LIGGGHTS $(ratio "$hf" "$lf") (HAET $(ratio "$lf" "$hf")x faster; goal at least 3x)"
echo "median:  LIGGGHTS $lm, HAET $hm ns/particle-step: HAET / LIGGGHTS $(ratio "$hm" "$lm")"
echo "by CPU time in the window (it stops while a process waits for a core): fastest LIGGGHTS $lwf, HAET $hwf: HAET / LIGGGHTS $(ratio "$hwf" "$lwf") (HAET $(ratio "$lwf" "$hwf")x faster); median $lwm, $hwm: $(ratio "$hwm" "$lwm")"
echo "CPU time of the whole processes (median): LIGGGHTS $lc, HAET $hc ns/particle-step: HAET / LIGGGHTS $(ratio "$hc" "$lc")"
mib() { [ -n "$1" ] && calc "printf \"%.1f\", $1 / 1048576" || echo NA; }
echo "peak RSS: LIGGGHTS $(mib "$l_peak") MiB (idle $(mib "$l_idle")), HAET $(mib "$h_peak") MiB (idle $(mib "$h_idle")); bytes per particle (peak - idle): LIGGGHTS $l_bpp, HAET $h_bpp"
echo "  (LIGGGHTS allocates its per-atom arrays and neighbour pages in large chunks, which its 1-sphere run holds already: its figure per particle is a lower bound)"
spread=$(calc "printf \"%.1f\", 2 * sqrt($l_out + $h_out)")
agree=$(calc "print ($l_out - $h_out < 0 ? $h_out - $l_out : $l_out - $h_out) <= $spread ? \"agree\" : \"DIFFER\"")
echo "left through the orifice during the window: LIGGGHTS $l_out, HAET $h_out (below it at the end: $l_below, $h_below): $agree within 2 sqrt(a + b) = $spread"
echo "at the end: pair contacts LIGGGHTS $l_pairs, HAET $h_pairs ($(ratio "$h_pairs" "$l_pairs")); spheres on a wall $l_wall, $h_wall; kinetic energy $l_ke, $h_ke J"
echo "neighbour-list builds in the window: LIGGGHTS $l_builds, HAET $h_builds"
echo "load average (1 min) before / after: $load_before / $load_after"
if awk -v a="$load_before" 'BEGIN { exit !(a + 0 >= 1.5) }'; then
    echo "warning: the machine was busy (load $load_before on $(nproc) cores): read the fastest rounds and the CPU times"
fi

header="case,n_particles,settle_steps,steps,rounds,liggghts_fastest_ns,haet_fastest_ns,ratio_haet_over_liggghts,liggghts_median_ns,haet_median_ns,ratio_median,liggghts_window_cpu_fastest_ns,haet_window_cpu_fastest_ns,ratio_window_cpu_fastest,liggghts_window_cpu_median_ns,haet_window_cpu_median_ns,ratio_window_cpu_median,liggghts_cpu_ns,haet_cpu_ns,ratio_cpu,liggghts_bytes_per_particle,haet_bytes_per_particle,liggghts_peak_rss_mib,haet_peak_rss_mib,liggghts_discharged,haet_discharged,liggghts_pair_contacts,haet_pair_contacts,liggghts_on_wall,haet_on_wall,liggghts_neighbor_builds,haet_neighbor_builds,date,haet_commit,haet_arch,load_before,load_after,note"
note=$(printf '%s' "${NOTE:-}" | tr ',\n' ';;')
row="silo3d,$n_file,$SETTLE,$STEPS,${#h_ns[@]},$lf,$hf,$(ratio "$hf" "$lf"),$lm,$hm,$(ratio "$hm" "$lm"),$lwf,$hwf,$(ratio "$hwf" "$lwf"),$lwm,$hwm,$(ratio "$hwm" "$lwm"),$lc,$hc,$(ratio "$hc" "$lc"),$l_bpp,$h_bpp,$(mib "$l_peak"),$(mib "$h_peak"),$l_out,$h_out,$l_pairs,$h_pairs,$l_wall,$h_wall,$l_builds,$h_builds,$(date -u +%Y-%m-%dT%H:%M:%SZ),$haet_commit,$haet_arch,$load_before,$load_after,$note"
if [ -s "$csv" ] && [ "$(head -n 1 "$csv")" != "$header" ]; then
    log "warning: $csv has other columns; the row goes to $csv.new"
    csv=$csv.new
fi
[ -s "$csv" ] || echo "$header" > "$csv"
echo "$row" >> "$csv"
echo "appended to bench/${csv#"$here"/} (commit the rows that record a standing)"
exit $status
