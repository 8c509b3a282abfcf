#!/usr/bin/env bash
# HAET's event-driven engine against Smallenburg's EDMD (F. Smallenburg, Eur. Phys. J. E 45, 22 (2022); its Single
# and Cell variants), side by side on one machine: elastic smooth hard spheres in a periodic cube, the same starting
# configuration, alternating rounds, collisions per CPU second of whole runs minus a short run of the same input.
#
#   bench/peers/edmd_smallenburg.sh EDMD_SOURCE BUILD_DIR
#
# EDMD_SOURCE: a checkout of https://github.com/FSmallenburg/EDMD that the user fetched (nothing is downloaded
# here); it is copied, its run parameters set in the copy (the globals at the top of mdSingle.c / mdCell.c: end
# time, input file, no thermostat, no snapshots), and built with its own Makefile (gcc -Ofast -march=native).
# BUILD_DIR: HAET's build (BUILD_DIR/haet, method = "edm", one thread).
#
# For each volume fraction of PHIS (0.1 0.3 0.45): bench/peers/make_gas.py writes N = 4 CELLS^3 spheres (CELLS = 30:
# 108 000) on an fcc lattice with Maxwell velocities at k_B T = 1, for both codes (Smallenburg's code draws its own
# velocities at the same temperature). Both simulate the same time T, chosen from Enskog's collision rate so that the
# gas has about PER_PARTICLE collisions per sphere (default 20): the same work. ROUNDS rounds (default 3), in each:
# Single, Cell, HAET, each a long run (T) and a short one (T / 10); a code's rate is
# (collisions_long - collisions_short) / (cpu_long - cpu_short), start-up and reading excluded. The ratio of each
# round is HAET's rate over the better peer's in that round; its min / median / max are printed. Bytes per particle:
# the peak resident memory of the long run less that of the same code on 108 spheres, over the difference in count.
# Appends one row per volume fraction to bench/results/MACHINE/peers_edmd.csv (columns: bench/results/README.md).
#
# Environment: PHIS, CELLS, ROUNDS, PER_PARTICLE, MACHINE, NOTE, KEEP (1: keep the run directories).
# Exit status: 0 measured; 1 a code failed to build or run; 2 usage.
set -euo pipefail

[ $# -eq 2 ] || { echo "usage: $0 EDMD_SOURCE BUILD_DIR" >&2; exit 2; }
[ -f "$1/Single/mdSingle.c" ] && [ -f "$1/Cell/mdCell.c" ] ||
    { echo "$0: $1 is not a checkout of Smallenburg's EDMD (no Single/mdSingle.c, Cell/mdCell.c)" >&2; exit 2; }
[ -x "$2/haet" ] || { echo "$0: $2/haet not found (build HAET first)" >&2; exit 2; }
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
bench=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$bench/lib.sh"
PHIS=${PHIS:-0.1 0.3 0.45}
CELLS=${CELLS:-30}
ROUNDS=${ROUNDS:-3}
PER_PARTICLE=${PER_PARTICLE:-20}
machine=${MACHINE:-$(machine_name)}
csv=$bench/results/$machine/peers_edmd.csv
[ -x /usr/bin/time ] || { echo "$0: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/haet-peers.XXXXXX")
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$work"' EXIT
log() { printf '%s\n' "$*" >&2; }
calc() { awk "BEGIN { $1 }"; }

# --- the peer, built from a copy with its parameters set -------------------------------------------------------
# set_param FILE REGEX REPLACEMENT: one substitution that must match exactly one line (a changed code is named).
set_param() {
    local file=$1 re=$2 to=$3
    [ "$(grep -c -E "$re" "$file")" = 1 ] || { log "$0: $file: no single line matches '$re' (another version of EDMD?)"; exit 1; }
    sed -i -E "s|$re|$to|" "$file"
}
# build_peer NAME VARIANT TIME: $work/peer/NAME/md, the VARIANT (Single, Cell) ending at TIME, reading init.sph
# from its working directory.
build_peer() {
    local v=$2 t=$3 d=$work/peer/$1 f=md$2.c
    rm -rf "$d"; mkdir -p "$d"; cp "$src/$v/"* "$d/"
    set_param "$d/$f" '^double maxtime = [^;]*;' "double maxtime = $t;"
    set_param "$d/$f" '^int makesnapshots = [^;]*;' 'int makesnapshots = 0;'
    set_param "$d/$f" '^double writeinterval = [^;]*;' "double writeinterval = $(calc "print $t / 10");"
    set_param "$d/$f" '^double snapshotinterval = [^;]*;' "double snapshotinterval = $(calc "print $t / 10");"
    set_param "$d/$f" '^int initialconfig = [^;]*;' 'int initialconfig = 0;'
    set_param "$d/$f" '^char inputfilename\[100\] = [^;]*;' 'char inputfilename[100] = "init.sph";'
    set_param "$d/$f" '^const int usethermostat = [^;]*;' 'const int usethermostat = 0;'
    make -s -C "$d" > "$d/build.log" 2>&1 || { log "$0: building $v failed; see $d/build.log"; tail -n 5 "$d/build.log" >&2; exit 1; }
}

# Each run sets COLL (collisions), CPU (user + sys, s), RSS (peak resident, bytes).
read_time() { read -r u s m < <(tail -n 1 "$1"); CPU=$(calc "printf \"%.3f\", $u + $s"); RSS=$((m * 1024)); }
# peer_run NAME DIR CONFIG: the peer built as NAME, in DIR with CONFIG as init.sph.
peer_run() {
    local v=$1 d=$2 cfg=$3
    mkdir -p "$d"; cp "$cfg" "$d/init.sph"
    (cd "$d" && /usr/bin/time -f "%U %S %M" -o time.out "$work/peer/$v/md" > screen.out 2>&1) ||
        { log "$0: $v failed in $d"; tail -n 5 "$d/screen.out" >&2; exit 1; }
    read_time "$d/time.out"
    COLL=$(sed -n 's/.*Collisions: \([0-9]*\),.*/\1/p' "$d/screen.out" | tail -n 1)
    [ -n "$COLL" ] || { log "$0: $v printed no collision count in $d/screen.out"; exit 1; }
}
# haet_run DIR CSV L T
haet_run() {
    local d=$1 cfg=$2 l=$3 t=$4
    mkdir -p "$d"
    cat > "$d/gas.toml" <<TOML
# Elastic smooth hard spheres of diameter 1 and mass 1 (density 6/pi) in a periodic cube: bench/peers/.
name = "peer_gas"
dimension = 3
method = "edm"
duration = $t
seed = 1
[domain]
lo = [0.0, 0.0, 0.0]
hi = [$l, $l, $l]
periodic = [true, true, true]
[materials.sphere]
density = 1.9098593171027440
restitution = 1.0
friction = 0.0
[contact]
normal = "linear"
duration = 1e-3         # unused by elastic hard spheres; the loader needs a contact time
[edm]
tc_model = false
[[insert]]
arrangement = "file"
format = "csv"
file = "$cfg"
material = "sphere"
[output]
series_period = $t
snapshot_period = -1
TOML
    /usr/bin/time -f "%U %S %M" -o "$d/time.out" "$build/haet" run "$d/gas.toml" --out "$d/out" --threads 1 --quiet \
        > "$d/screen.out" 2>&1 || { log "$0: haet failed in $d"; tail -n 5 "$d/screen.out" >&2; exit 1; }
    read_time "$d/time.out"
    COLL=$(python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['collisions'])" "$d/out/run.json")
}

haet_commit=$(git -C "$bench/.." rev-parse --short HEAD 2>/dev/null || echo NA)
haet_arch=$(sed -n 's/^HAET_ARCH:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
peer_commit=$(git -C "$src" rev-parse --short HEAD 2>/dev/null || echo NA)
mkdir -p "$(dirname "$csv")"
[ -s "$csv" ] || echo "phi,n,sim_time,rounds,single_median,cell_median,haet_min,haet_median,haet_max,best_peer,ratio_min,ratio_median,ratio_max,single_bytes_per_particle,cell_bytes_per_particle,haet_bytes_per_particle,date,haet_commit,haet_arch,peer_commit,load_before,load_after,note" > "$csv"
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
minof() { printf '%s\n' "$@" | sort -g | head -n 1; }
maxof() { printf '%s\n' "$@" | sort -g | tail -n 1; }

echo "Smallenburg EDMD ($peer_commit: Single, Cell) vs HAET ($haet_commit, $haet_arch), one core each, $(machine_name)"
printf '%-5s %8s %6s | %-30s | %-30s | %-30s | %s\n' phi N T "Single 10^3 coll/CPU s" "Cell" "HAET" "HAET / best peer min med max; bytes/particle S C H"
status=0
for phi in $PHIS; do
    load_before=$(cut -d' ' -f1 /proc/loadavg)
    g=$work/gas_$phi
    read -r n box < <(python3 "$here/make_gas.py" "$phi" "$CELLS" 7 "$g")
    read -r n0 box0 < <(python3 "$here/make_gas.py" "$phi" 3 7 "${g}_small")
    # Enskog's collision rate per sphere, 24 phi g(sigma) sqrt(k_B T / (pi m)) / sigma, g from Carnahan-Starling.
    t=$(calc "g = (1 - $phi / 2) / (1 - $phi)^3; w = 24 * $phi * g / sqrt(3.141592653589793); printf \"%.4g\", 2 * $PER_PARTICLE / w")
    ts=$(calc "printf \"%.4g\", $t / 10")
    declare -A rss=() rss0=()
    for v in Single Cell; do
        build_peer "${v}_long" "$v" "$t"
        build_peer "${v}_short" "$v" "$ts"
    done
    ratios=() hs=() ss=() cs=()
    for r in $(seq "$ROUNDS"); do
        best=0
        for v in Single Cell HAET; do
            if [ $v = HAET ]; then
                haet_run "$work/h_${phi}_${r}_l" "$g.csv" "$box" "$t"; cl=$COLL cpl=$CPU rl=$RSS
                haet_run "$work/h_${phi}_${r}_s" "$g.csv" "$box" "$ts"; cs_=$COLL cps=$CPU
                [ "$r" = 1 ] && { haet_run "$work/h_${phi}_0" "${g}_small.csv" "$box0" "$ts"; rss0[$v]=$RSS; }
            else
                peer_run "${v}_long" "$work/${v}_${phi}_${r}_l" "$g.sph"; cl=$COLL cpl=$CPU rl=$RSS
                peer_run "${v}_short" "$work/${v}_${phi}_${r}_s" "$g.sph"; cs_=$COLL cps=$CPU
                [ "$r" = 1 ] && { peer_run "${v}_short" "$work/${v}_${phi}_0" "${g}_small.sph"; rss0[$v]=$RSS; }
            fi
            x=$(calc "d = $cpl - $cps; printf \"%.0f\", (d > 0) ? ($cl - $cs_) / d : 0")
            rss[$v]=$rl
            case $v in Single) ss+=("$x") ;; Cell) cs+=("$x") ;; HAET) hs+=("$x") ;; esac
            if [ $v != HAET ] && [ "$x" -gt "$best" ]; then best=$x; fi
            [ $v = HAET ] && ratios+=("$(calc "printf \"%.3f\", $x / $best")")
        done
        log "phi $phi round $r: Single ${ss[-1]}, Cell ${cs[-1]}, HAET ${hs[-1]} collisions per CPU second"
    done
    bpp() { calc "printf \"%.1f\", (${rss[$1]} - ${rss0[$1]}) / ($n - $n0)"; }
    sm=$(median "${ss[@]}") cm=$(median "${cs[@]}") hm=$(median "${hs[@]}")
    bestpeer=Single; [ "$(calc "print ($cm > $sm)")" = 1 ] && bestpeer=Cell
    rmin=$(minof "${ratios[@]}") rmed=$(median "${ratios[@]}") rmax=$(maxof "${ratios[@]}")
    k() { calc "printf \"%.1f\", $1 / 1000"; }
    printf '%-5s %8s %6s | %-30s | %-30s | %-30s | %s %s %s; %s %s %s\n' "$phi" "$n" "$t" \
        "$(k "$(minof "${ss[@]}")")/$(k "$sm")/$(k "$(maxof "${ss[@]}")")" \
        "$(k "$(minof "${cs[@]}")")/$(k "$cm")/$(k "$(maxof "${cs[@]}")")" \
        "$(k "$(minof "${hs[@]}")")/$(k "$hm")/$(k "$(maxof "${hs[@]}")")" "$rmin" "$rmed" "$rmax" \
        "$(bpp Single)" "$(bpp Cell)" "$(bpp HAET)"
    load_after=$(cut -d' ' -f1 /proc/loadavg)
    echo "$phi,$n,$t,$ROUNDS,$sm,$cm,$(minof "${hs[@]}"),$hm,$(maxof "${hs[@]}"),$bestpeer,$rmin,$rmed,$rmax,$(bpp Single),$(bpp Cell),$(bpp HAET),$(date -u +%Y-%m-%dT%H:%M:%SZ),$haet_commit,${haet_arch:-NA},$peer_commit,$load_before,$load_after,${NOTE:-}" >> "$csv"
done
echo "rows appended to $csv (the goal: HAET at least 2x the better peer at every density)"
exit $status
