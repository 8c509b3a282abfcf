#!/usr/bin/env bash
# HAET against LAMMPS on the granular chute (after LAMMPS's bench/in.chute), side by side in one run.
#
#   bench/compare_lammps.sh BUILD_DIR [3d|2d]
#
# 1. Preparation (once): when bench/data/chute<case>.flowing.data is missing, writes the lattice with
#    bench/make_chute_data.sh and lets LAMMPS flow it for PREP_STEPS steps (bench/lammps/in.chute<case>.prep).
# (5. below: both codes timed again in short windows, the fastest of each compared.)
# 2. LAMMPS times STEPS steps from that state (bench/lammps/in.chute<case>.time), under /usr/bin/time -v.
# 3. HAET runs examples/lammps_chute<case>.toml from the same file with --threads 1 and --threads 2, under
#    /usr/bin/time -v (other step counts by `haet run --set duration=...`).
# 4. Idle baselines: both codes run the same input on a data file with 1 particle in the same box, 10 steps.
# Prints a table, and appends its rows to bench/results/MACHINE/lammps_chute.csv (MACHINE: the processor, from
# /proc/cpuinfo, or $MACHINE; columns: bench/results/README.md).
# Time per particle-step = wall time of the stepping loop / (particles x steps), particles counting the
# frozen base; bytes per particle = (peak RSS - idle peak RSS) / particles.
#
# Environment: STEPS (5000), PREP_STEPS (80000), HAET_THREADS ("1 2"), HAET_SKIP=1 (LAMMPS half only),
#              WINDOW_ROUNDS (8; 0: no windows),
#              HAET_TIMEOUT (s; default 20 x LAMMPS's loop time + 60), LMP (lmp), MACHINE, NOTE (a note for the
#              CSV rows). Exit status: 0 all measured; 1 a half failed (the other is still reported); 2 usage.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
chute_args "$0" "$@"
data=$here/data
name=chute$case
runs=$data/runs/$name
STEPS=${STEPS:-5000}
PREP_STEPS=${PREP_STEPS:-80000}
HAET_THREADS=${HAET_THREADS:-1 2}
LMP=${LMP:-lmp}
IDLE_STEPS=10
haet=$build/haet
machine=${MACHINE:-$(machine_name)}
csv=$here/results/$machine/lammps_chute.csv
status=0

command -v "$LMP" >/dev/null || { echo "$0: LAMMPS ($LMP) not found (Debian: apt-get install lammps)" >&2; exit 1; }
[ -x /usr/bin/time ] || { echo "$0: /usr/bin/time not found (Debian: apt-get install time)" >&2; exit 1; }
mkdir -p "$data" "$runs" "$(dirname "$csv")"

log() { printf '%s\n' "$*" >&2; }

# Peak resident set size in bytes from a `/usr/bin/time -v -o FILE` report.
peak_bytes() { awk -F': *' '/Maximum resident set size/ {printf "%.0f\n", $2 * 1024}' "$1"; }

# CPU time (user + system) of the whole process over particles x steps, in ns: a second clock, which other
# processes on the machine disturb less than the wall clock (it also counts reading the file and the setup).
cpu_ns() { awk -v n="$2" -v s="$3" -F': *' '/User time|System time/ { c += $2 } END { printf "%.2f\n", c / (n * s) * 1e9 }' "$1"; }

# Top-level number KEY of a JSON file, or empty.
json_num() {
    if command -v python3 >/dev/null; then
        python3 - "$1" "$2" <<'EOF' 2>/dev/null || true
import json, sys
v = json.load(open(sys.argv[1])).get(sys.argv[2])
if isinstance(v, (int, float)) and not isinstance(v, bool): print(repr(v))
EOF
    else
        tr -d '\n' < "$1" | sed -n "s/.*\"$2\"[[:space:]]*:[[:space:]]*\\([-+0-9.eE]*\\).*/\\1/p"
    fi
}

# calc PROGRAM: runs an awk BEGIN block (the callers check that no operand is empty).
calc() { awk "BEGIN { $1 }" ; }

# Runs "$@" under /usr/bin/time -v, output in PREFIX.{out,time}; returns the command's status.
timed() {
    local prefix=$1; shift
    /usr/bin/time -v -o "$prefix.time" "$@" > "$prefix.out" 2>&1
}

# --- 1. Preparation ---------------------------------------------------------------------------------
flowing=$data/$name.flowing.data
if [ ! -s "$flowing" ]; then
    lattice=$data/$name.lattice.data
    [ -s "$lattice" ] || "$here/make_chute_data.sh" "$case" "$lattice" >&2
    mkdir -p "$data/prep"
    log "preparing $flowing: LAMMPS flows the lattice for $PREP_STEPS steps (one-off; 3D takes 10-15 min)"
    t0=$(date +%s)
    if ! (cd "$data/prep" && "$LMP" -in "$here/lammps/in.$name.prep" -var datain "$lattice" \
              -var dataout "$flowing.tmp" -var steps "$PREP_STEPS" -log "$name.prep.log" -screen none); then
        log "LAMMPS preparation failed; the end of $data/prep/$name.prep.log:"
        tail -n 20 "$data/prep/$name.prep.log" >&2
        rm -f "$flowing.tmp"
        exit 1
    fi
    mv "$flowing.tmp" "$flowing"
    log "prepared in $(( $(date +%s) - t0 )) s"
fi

# The HAET scenario's domain must be the data file's box (periodic axes exactly; the open axis at least as
# high as the box, which LAMMPS's "fm" may have grown) and hold every particle.
check_domain() {
    local toml=$1 file=$2
    awk -v dim="${case%d}" '
        FNR == 1 { nfile++ }
        nfile == 1 && /^hi *=/ { s = $0; gsub(/.*\[|\].*/, "", s); nh = split(s, hi, /, */) }
        nfile == 2 && / xlo xhi$/ { bhi[1] = $2 } nfile == 2 && / ylo yhi$/ { bhi[2] = $2 } nfile == 2 && / zlo zhi$/ { bhi[3] = $2 }
        nfile == 2 && /^Atoms/ { atoms = 1; next } nfile == 2 && /^Velocities/ { atoms = 0 }
        nfile == 2 && atoms && NF >= 7 { for (a = 1; a <= dim; a++) if (!(a in top) || $(4 + a) > top[a]) top[a] = $(4 + a) }
        END {
            if (nh != dim) { print "cannot read [domain] hi of the scenario"; exit 1 }
            open = dim  # the open (non-periodic) axis is the last one
            for (a = 1; a <= dim; a++) {
                d = hi[a] - bhi[a]; if (d < 0) d = -d
                if (a < open && d > 1e-9) { printf "axis %d: scenario hi %s, data file box hi %s\n", a, hi[a], bhi[a]; exit 1 }
                if (a == open && (bhi[a] > hi[a] + 1e-9 || top[a] >= hi[a])) {
                    printf "open axis: scenario hi %s, data file box hi %s, highest centre %s\n", hi[a], bhi[a], top[a]; exit 1 }
            }
        }' "$toml" "$file"
}

# The scenario HAET runs: examples/lammps_<name>.toml as it stands for the default STEPS, else with the duration
# and the series period overridden (dt = 1e-4).
scenario=$root/examples/lammps_$name.toml
thermo=$(( STEPS >= 5 ? STEPS / 5 : 1 ))   # LAMMPS thermo and HAET series rows, 1 000 steps for the default
sets=()
if [ "$STEPS" != 5000 ]; then
    sets=(--set "duration=$(calc "print $STEPS * 1e-4")" --set "output.series_period=$(calc "print $thermo * 1e-4")")
fi
# Idle baseline: the same scenario on the file with 1 particle in the same box.
idle_data=$data/idle$case.data
"$here/make_chute_data.sh" "idle$case" "$idle_data" >/dev/null
idle_sets=(--set "duration=$(calc "print $IDLE_STEPS * 1e-4")" --set "insert[1].file=\"$idle_data\"")

# The HAET source the build came from: git HEAD of the tree BUILD_DIR was configured from, "+dirty" when its
# src/ has uncommitted changes; HAET_COMMIT overrides (e.g. for a build from an exported tree).
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

# Other processes on the machine spoil the timings (and a 2-thread run most, its threads waiting on each other).
load_before=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo NA)

# --- 2. LAMMPS ----------------------------------------------------------------------------------------
lrun=$runs/lammps
rm -rf "$lrun"; mkdir -p "$lrun"
log "LAMMPS: $STEPS steps of $name ..."
l_ns="" l_bpp="" l_n="" l_peak="" l_idle="" l_loop="" l_cpu=""
if (cd "$lrun" && timed run "$LMP" -in "$here/lammps/in.$name.time" -var datain "$flowing" -var steps "$STEPS" \
        -var thermo "$thermo" -log log.lammps -screen none) &&
   (cd "$lrun" && timed idle "$LMP" -in "$here/lammps/in.$name.time" -var datain "$idle_data" \
        -var steps "$IDLE_STEPS" -log idle.log.lammps -screen none); then
    # "Loop time of T on P procs for N steps with M atoms"
    read -r l_loop l_steps l_n < <(awk '/^Loop time of/ { t = $4; s = $9; n = $12 } END { print t, s, n }' "$lrun/log.lammps")
    l_peak=$(peak_bytes "$lrun/run.time")
    l_idle=$(peak_bytes "$lrun/idle.time")
    l_ns=$(calc "printf \"%.2f\", $l_loop / ($l_n * $l_steps) * 1e9")
    l_bpp=$(calc "printf \"%.0f\", ($l_peak - $l_idle) / $l_n")
    l_cpu=$(cpu_ns "$lrun/run.time" "$l_n" "$l_steps")
else
    log "LAMMPS run failed; see $lrun (log.lammps, idle.log.lammps)"
    tail -n 5 "$lrun"/*.lammps >&2 || true
    status=1
fi

# --- 3. HAET ------------------------------------------------------------------------------------------
declare -A h_ns h_bpp h_peak h_wall h_cpu
h_idle="" h_n="" h_idle_how=""
haet_ok=0
if [ "${HAET_SKIP:-0}" = 1 ]; then
    log "HAET: skipped (HAET_SKIP=1)"
elif [ ! -x "$haet" ]; then
    log "HAET: $haet not found (build first: make build)"
    status=1
else
    if ! domain_msg=$(check_domain "$scenario" "$flowing"); then
        log "HAET: $scenario does not match $flowing: $domain_msg"
        status=1
    else
        haet_ok=1
        # A run that hangs is stopped: after HAET_TIMEOUT s, default 20 x LAMMPS's loop time + 60 s (30 min
        # without it); the 1-particle run after 60 s.
        limit=${HAET_TIMEOUT:-$( [ -n "$l_loop" ] && calc "printf \"%d\", 20 * $l_loop + 60" || echo 1800)}
        # Idle: the 1-particle run; `haet --version` when that fails.
        rm -rf "$runs/haet_idle.run"
        if timed "$runs/haet_idle" timeout 60 "$haet" run "$scenario" "${idle_sets[@]}" --out "$runs/haet_idle.run" --quiet --threads 1 &&
           [ -s "$runs/haet_idle.run/run.json" ]; then
            h_idle_how="1-particle run"
        else
            log "HAET: the 1-particle idle run failed ($runs/haet_idle.out); idle baseline from haet --version"
            timed "$runs/haet_idle" "$haet" --version || true
            h_idle_how="haet --version"
        fi
        h_idle=$(peak_bytes "$runs/haet_idle.time")
        for t in $HAET_THREADS; do
            rdir=$runs/haet_t$t
            rm -rf "$rdir"
            log "HAET: $STEPS steps of $name, --threads $t ..."
            rc=0
            timed "$runs/haet_t$t" timeout "$limit" "$haet" run "$scenario" ${sets[@]+"${sets[@]}"} --out "$rdir" --quiet \
                --threads "$t" || rc=$?
            if [ "$rc" = 124 ]; then
                log "HAET --threads $t did not finish in $limit s (HAET_TIMEOUT); stopped"
                haet_ok=0; break
            elif [ "$rc" != 0 ]; then
                log "HAET --threads $t failed (status $rc); the end of $runs/haet_t$t.out:"
                tail -n 10 "$runs/haet_t$t.out" >&2
                haet_ok=0; break
            fi
            if [ ! -s "$rdir/run.json" ]; then
                log "HAET --threads $t wrote no $rdir/run.json (is 'haet run' implemented?)"
                haet_ok=0; break
            fi
            n=$(json_num "$rdir/run.json" n_particles)
            steps=$(json_num "$rdir/run.json" steps)
            psps=$(json_num "$rdir/run.json" particle_steps_per_second)
            wall=$(json_num "$rdir/run.json" wall_time)
            if [ -z "$psps" ] && [ -n "$wall" ] && [ -n "$n" ] && [ -n "$steps" ]; then
                psps=$(calc "print $n * $steps / $wall")
            fi
            if [ -z "$n" ] || [ -z "$psps" ]; then
                log "HAET --threads $t: run.json lacks n_particles or particle_steps_per_second"
                haet_ok=0; break
            fi
            [ "$steps" = "$STEPS" ] || log "warning: HAET ran ${steps:-?} steps, LAMMPS $STEPS"
            [ -z "$l_n" ] || [ "$n" = "$l_n" ] || log "warning: HAET has $n particles, LAMMPS $l_n"
            h_n=$n
            h_wall[$t]=$wall
            h_ns[$t]=$(calc "printf \"%.2f\", 1e9 / $psps")
            h_peak[$t]=$(peak_bytes "$runs/haet_t$t.time")
            h_cpu[$t]=$(cpu_ns "$runs/haet_t$t.time" "$n" "$steps")
            h_bpp[$t]=$(calc "printf \"%.0f\", (${h_peak[$t]} - $h_idle) / $n")
            rss_json=$(json_num "$rdir/run.json" peak_rss_bytes)
            [ -z "$rss_json" ] || log "  run.json peak_rss_bytes $rss_json, /usr/bin/time ${h_peak[$t]}"
        done
    fi
    [ "$haet_ok" = 1 ] || status=1
fi

# --- 4. Report ----------------------------------------------------------------------------------------
mib() { [ -n "$1" ] && calc "printf \"%.1f\", $1 / 1048576" || echo NA; }
or_na() { [ -n "${1:-}" ] && echo "$1" || echo NA; }
ratio() { [ -n "${1:-}" ] && [ -n "${2:-}" ] && calc "printf \"%.3f\", $1 / $2" || echo NA; }

frozen=$(awk '/^Atoms/ { a = 1; next } /^Velocities/ { a = 0 } a && NF >= 7 && $2 == 2 { f++ } END { print f + 0 }' "$flowing")
echo
echo "$name: $(or_na "${l_n:-$h_n}") particles ($frozen frozen), $STEPS steps from bench/${flowing#"$here"/}"
fmt='%-18s %17s %14s %13s %9s %15s\n'
printf "$fmt" "" "ns/particle-step" "CPU ns/p-step" "peak RSS MiB" "idle MiB" "bytes/particle"
printf "$fmt" "LAMMPS (1 proc)" "$(or_na "$l_ns")" "$(or_na "$l_cpu")" "$(mib "$l_peak")" "$(mib "$l_idle")" "$(or_na "$l_bpp")"
if [ "$haet_ok" = 1 ]; then
    for t in $HAET_THREADS; do
        printf "$fmt" "HAET ($t thread$([ "$t" = 1 ] || echo s))" "${h_ns[$t]}" "${h_cpu[$t]}" \
            "$(mib "${h_peak[$t]}")" "$(mib "$h_idle")" "${h_bpp[$t]}"
    done
    echo "HAET idle baseline: $h_idle_how"
fi
first=${HAET_THREADS%% *}
if [ "$haet_ok" = 1 ] && [ -n "$l_ns" ]; then
    echo "time per particle-step, HAET ($first thread) / LAMMPS (1 proc): $(ratio "${h_ns[$first]}" "$l_ns")"
    echo "the same by CPU time: $(ratio "${h_cpu[$first]}" "$l_cpu")"
    echo "bytes per particle, HAET / LAMMPS: $(ratio "${h_bpp[$first]}" "$l_bpp")"
fi
if [ "$haet_ok" = 1 ]; then
    for t in $HAET_THREADS; do
        [ "$t" = "$first" ] || echo "HAET speed-up, $t threads over $first: $(ratio "${h_ns[$first]}" "${h_ns[$t]}")"
    done
fi

# --- 5. Windows ---------------------------------------------------------------------------------------
# The machine's speed changes within a minute, so a whole run's time carries whatever else ran meanwhile. Here each
# code steps the same state in 40 short windows (3D 25 steps, 2D 50; after as many steps to warm up), one code after
# the other, WINDOW_ROUNDS times (order swapped each round): the fastest window of each is its time when the
# machine is least disturbed, and their ratio is the steadiest comparison. LAMMPS: in.<name>.time -var windows;
# HAET: haet_bench TdmChute<2D|3D> (bench/tdm_chute.cpp), one thread.
WINDOW_ROUNDS=${WINDOW_ROUNDS:-8}
wsteps=$([ "$case" = 3d ] && echo 25 || echo 50)
w_l="" w_h=""
if [ "$WINDOW_ROUNDS" -gt 0 ] && [ "$haet_ok" = 1 ] && [ -n "$l_ns" ] && [ -x "$build/haet_bench" ]; then
    wdir=$runs/windows
    mkdir -p "$wdir"
    upper=$(echo "$case" | tr d D)
    lmp_windows() {
        (cd "$wdir" && "$LMP" -in "$here/lammps/in.$name.time" -var datain "$flowing" -var steps "$wsteps" \
            -var wsteps "$wsteps" -var windows 40 -var thermo 1000000000 -log log.lammps -screen none) &&
        awk -v n="$l_n" '/^Loop time of/ { k++; t = $4 / (n * $9) * 1e9; if (k > 1 && (m == "" || t < m)) m = t }
            END { if (m != "") printf "%.2f\n", m }' "$wdir/log.lammps"
    }
    haet_windows() {
        "$build/haet_bench" --benchmark_filter="TdmChute$upper" --benchmark_format=json 2>/dev/null |
            python3 -c 'import json, sys; print("%.2f" % json.load(sys.stdin)["benchmarks"][0]["min_ns_per_particle_step"])'
    }
    smaller() { awk -v a="$1" -v m="$2" 'BEGIN { print (m == "" || a + 0 < m + 0) ? a : m }'; }
    log "windows: $WINDOW_ROUNDS rounds of 40 x $wsteps steps, LAMMPS and HAET one after the other ..."
    for r in $(seq "$WINDOW_ROUNDS"); do
        if [ $((r % 2)) = 1 ]; then a=$(lmp_windows || true); b=$(haet_windows || true)
        else b=$(haet_windows || true); a=$(lmp_windows || true); fi
        log "  round $r: fastest window LAMMPS ${a:-?}, HAET ${b:-?} ns/particle-step"
        [ -z "$a" ] || w_l=$(smaller "$a" "$w_l")
        [ -z "$b" ] || w_h=$(smaller "$b" "$w_h")
    done
    if [ -n "$w_l" ] && [ -n "$w_h" ]; then
        echo "fastest of $((40 * WINDOW_ROUNDS)) windows of $wsteps steps, one thread: LAMMPS $w_l, HAET $w_h ns/particle-step: HAET / LAMMPS $(ratio "$w_h" "$w_l")"
    else
        log "windows: no result (see $wdir/log.lammps; haet_bench --benchmark_filter=TdmChute$upper)"
    fi
fi

load_after=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo NA)
echo "load average (1 min) before / after: $load_before / $load_after"
if awk -v a="$load_before" 'BEGIN { exit !(a + 0 >= 1.5) }'; then
    echo "warning: the machine was busy before the runs (load $load_before on $(nproc) cores): timings are unreliable, the 2-thread ones most"
fi

# Same work? Kinetic energy (translational) at LAMMPS's last thermo step, and HAET's series.csv row of that step.
if [ "$haet_ok" = 1 ] && [ -n "$l_ns" ]; then
    read -r l_kstep l_ke < <(awk '/^ *Step / { on = 1; next } /^Loop time/ { on = 0 }
        on && $1 ~ /^[0-9]+$/ { s = $1; ke = $3 } END { print s, ke }' "$lrun/log.lammps")
    h_ke=$(awk -F, -v s="$l_kstep" 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "kinetic_energy") c = i; if ($i == "step") k = i }; next }
        c && k && $k + 0 == s + 0 { ke = $c } END { print ke }' "$runs/haet_t$first/series.csv" 2>/dev/null || true)
    [ -z "$h_ke" ] || echo "kinetic energy at step $l_kstep (same start, same law): LAMMPS $l_ke, HAET $(calc "printf \"%.8g\", $h_ke")"
fi

# CSV: one row per HAET thread count (a single row with threads NA when HAET did not run), appended to the
# machine's file (columns: bench/results/README.md).
header="case,threads,n_particles,steps,lammps_ns_per_particle_step,haet_ns_per_particle_step,ratio_haet_over_lammps,lammps_bytes_per_particle,haet_bytes_per_particle,haet_speedup_over_1_thread,lammps_cpu_ns_per_particle_step,haet_cpu_ns_per_particle_step,date,haet_commit,load_before,lammps_fastest_window_ns,haet_fastest_window_ns,haet_arch,note"
haet_arch=$(sed -n 's/^HAET_ARCH:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
haet_arch=${haet_arch:-NA}
note=$(printf '%s' "${NOTE:-}" | tr ',\n' ';;')
now=$(date -u +%Y-%m-%dT%H:%M:%SZ)
rows=()
if [ "$haet_ok" = 1 ]; then
    for t in $HAET_THREADS; do
        rows+=("$name,$t,$h_n,$STEPS,$(or_na "$l_ns"),${h_ns[$t]},$(ratio "${h_ns[$t]}" "$l_ns"),$(or_na "$l_bpp"),${h_bpp[$t]},$(ratio "${h_ns[$first]}" "${h_ns[$t]}"),$(or_na "$l_cpu"),${h_cpu[$t]},$now,$haet_commit,$load_before,$(or_na "$w_l"),$(or_na "$w_h"),$haet_arch,$note")
    done
else
    rows+=("$name,NA,$(or_na "$l_n"),$STEPS,$(or_na "$l_ns"),NA,NA,$(or_na "$l_bpp"),NA,NA,$(or_na "$l_cpu"),NA,$now,$haet_commit,$load_before,NA,NA,$haet_arch,$note")
fi
if [ -s "$csv" ] && [ "$(head -n 1 "$csv")" != "$header" ]; then
    log "warning: $csv has other columns; the rows go to $csv.new"
    csv=$csv.new
fi
[ -s "$csv" ] || echo "$header" > "$csv"
printf '%s\n' "${rows[@]}" >> "$csv"
echo "appended to bench/${csv#"$here"/} (commit the rows that record a standing)"
exit $status
