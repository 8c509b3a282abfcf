#!/usr/bin/env bash
# What a fine mesh floor costs against the plane it makes: the same settled bed on the plane floor of
# examples/box3d_settle.toml and on a flat mesh of 10 082 triangles at the same height, from the same state.
#
#   bench/mesh_floor.sh BUILD_DIR [CALLGRIND_BUILD_DIR]
#
# 1. Preparation (once, kept in bench/data/, git-ignored): the bed, BED_COUNT (4 000) spheres of
#    examples/box3d_settle.toml rained in and settled for the scene's 0.4 s (100 000 steps) by
#    BUILD_DIR/haet_scene_steps, written as bench/data/bed3d.settled.data; the floor mesh,
#    bench/data/floor_mesh.stl (bench/make_floor_mesh.py: [0, 0.02]^2 at z = 0, 71 x 71 cells of two triangles, the
#    vertices jittered in the plane).
# 2. Wall time: ROUNDS rounds, the plane then the mesh in each; a round reads the bed, steps SETTLE steps untimed,
#    then WINDOWS windows of WSTEPS steps, each timed (haet_scene_steps, one thread). The fastest window of each
#    floor over all rounds is its cost when the machine is least disturbed; their ratio is the figure (goal: at
#    most 1.15), the ratio of the medians beside it, and that of the fastest windows by the process's CPU time
#    (which stops while it waits for a core: on a busy machine the steadier clock).
# 3. Instructions (when valgrind and CALLGRIND_BUILD_DIR/haet_scene_steps are there; default: BUILD_DIR-v3, a build
#    with -DHAET_ARCH=x86-64-v3, which valgrind can run): each floor under callgrind, CG_SETTLE steps untimed then
#    CG_STEPS counted (--toggle-collect on the windows alone), instructions per particle-step and their ratio.
# Both floors must give the same bed: the kinetic energy and the contacts at the end are printed side by side (a
# ball on a flat mesh touches one face, as on the plane, docs/physics.md H.2). Appends one row to
# bench/results/MACHINE/mesh_floor.csv and, with counts, one row per floor and the ratio to
# bench/results/callgrind-x86-64-v3/instructions.csv (columns: bench/results/README.md).
#
# Environment: ROUNDS (6), SETTLE (200), WINDOWS (4), WSTEPS (500), CG_SETTLE (20), CG_STEPS (200), BED_COUNT (4000),
# MACHINE, NOTE. Exit status: 0 measured; 1 a run failed; 2 usage.
set -euo pipefail

[ $# -ge 1 ] && [ $# -le 2 ] || { echo "usage: $0 BUILD_DIR [CALLGRIND_BUILD_DIR]" >&2; exit 2; }
[ -d "$1" ] || { echo "$0: build directory not found: $1" >&2; exit 2; }
build=$(cd "$1" && pwd)
cgbuild=${2:-$build-v3}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
ROUNDS=${ROUNDS:-6}
SETTLE=${SETTLE:-200}
WINDOWS=${WINDOWS:-4}
WSTEPS=${WSTEPS:-500}
CG_SETTLE=${CG_SETTLE:-20}
CG_STEPS=${CG_STEPS:-200}
BED_COUNT=${BED_COUNT:-4000}
data=$here/data
runs=$data/runs/mesh_floor
machine=${MACHINE:-$(machine_name)}
csv=$here/results/$machine/mesh_floor.csv
cgcsv=$here/results/callgrind-x86-64-v3/instructions.csv
scene=$root/examples/box3d_settle.toml
tool=$build/haet_scene_steps
[ -x "$tool" ] || { echo "$0: $tool not found (cmake --build $build --target haet_scene_steps)" >&2; exit 1; }
mkdir -p "$data" "$runs" "$(dirname "$csv")"
log() { printf '%s\n' "$*" >&2; }
calc() { awk "BEGIN { $1 }"; }
kv() { tr ' ' '\n' < "$1" | sed -n "s/^$2=//p"; }

# --- 1. Preparation ---------------------------------------------------------------------------------
bed=$data/bed3d.settled.data
mesh=$data/floor_mesh.stl
if [ ! -s "$bed" ]; then
    log "preparing $bed: $BED_COUNT spheres of box3d_settle.toml settling for 0.4 s (one-off, about a minute)"
    "$tool" "$scene" --set "insert[1].count=$BED_COUNT" --steps 100000 --write "$bed" > "$runs/prep.out"
fi
[ -s "$mesh" ] || python3 "$here/make_floor_mesh.py" "$mesh" >&2
triangles=$(od -A n -t u4 -j 80 -N 4 "$mesh" | tr -d ' ')
# The bed replaces the scene's insertion; the mesh replaces its first wall, the floor plane at z = 0.
sets=(--set "insert[1]={ arrangement = \"file\", format = \"lammps\", file = \"$bed\", material = \"glass\" }")
mesh_set=(--set "walls[1]={ type = \"mesh\", file = \"$mesh\", material = \"glass\" }")
floor_sets() { if [ "$1" = mesh ]; then printf '%s\0' "${sets[@]}" "${mesh_set[@]}"; else printf '%s\0' "${sets[@]}"; fi; }

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

# --- 2. Wall time, alternating rounds -------------------------------------------------------------------
declare -A best bestcpu
p_med=() m_med=()
for r in $(seq "$ROUNDS"); do
    for f in plane mesh; do
        out=$runs/${f}_$r.out
        mapfile -d '' args < <(floor_sets "$f")
        if ! "$tool" "$scene" "${args[@]}" --settle "$SETTLE" --steps "$WSTEPS" --windows "$WINDOWS" --threads 1 \
                > "$out" 2> "$runs/${f}_$r.err"; then
            log "the $f floor failed in round $r; see $runs/${f}_$r.err"
            exit 1
        fi
        m=$(kv "$out" min_ns_per_particle_step)
        best[$f]=$(awk -v a="$m" -v b="${best[$f]:-}" 'BEGIN { print (b == "" || a + 0 < b + 0) ? a : b }')
        c=$(kv "$out" min_cpu_ns_per_particle_step)
        bestcpu[$f]=$(awk -v a="$c" -v b="${bestcpu[$f]:-}" 'BEGIN { print (b == "" || a + 0 < b + 0) ? a : b }')
        if [ "$f" = plane ]; then p_med+=("$(kv "$out" median_ns_per_particle_step)"); else m_med+=("$(kv "$out" median_ns_per_particle_step)"); fi
    done
    log "round $r: fastest windows so far: plane ${best[plane]}, mesh ${best[mesh]} ns/particle-step"
done
median() { printf '%s\n' "$@" | sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
ratio() { calc "printf \"%.3f\", $1 / $2"; }
pm=$(median "${p_med[@]}") mm=$(median "${m_med[@]}")
load_after=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo NA)
n=$(kv "$runs/plane_1.out" particles)

echo
echo "mesh floor: $n settled spheres on the plane z = 0 and on a flat mesh of $triangles triangles there, one thread"
echo "fastest of $((ROUNDS * WINDOWS)) windows of $WSTEPS steps: plane ${best[plane]}, mesh ${best[mesh]} ns/particle-step: mesh / plane $(ratio "${best[mesh]}" "${best[plane]}") (goal: at most 1.15)"
echo "medians of the rounds' median windows: plane $pm, mesh $mm: mesh / plane $(ratio "$mm" "$pm")"
echo "fastest windows by CPU time (the process's, which stops while it waits for a core): plane ${bestcpu[plane]}, mesh ${bestcpu[mesh]}: mesh / plane $(ratio "${bestcpu[mesh]}" "${bestcpu[plane]}")"
for f in plane mesh; do
    o=$runs/${f}_$ROUNDS.out
    echo "the same bed, $f floor: kinetic energy $(kv "$o" kinetic_energy) J, pair contacts $(kv "$o" pair_contacts), wall contacts $(kv "$o" wall_contacts)"
done
echo "load average (1 min) before / after: $load_before / $load_after"

# --- 3. Instructions ------------------------------------------------------------------------------------
cg=()
if command -v valgrind >/dev/null && [ -x "$cgbuild/haet_scene_steps" ]; then
    cg_arch=$(sed -n 's/^HAET_ARCH:[A-Z]*=//p' "$cgbuild/CMakeCache.txt" 2>/dev/null || true)
    for f in plane mesh; do
        mapfile -d '' args < <(floor_sets "$f")
        valgrind --tool=callgrind --callgrind-out-file="$runs/cg_$f.out" --toggle-collect='*timedWindows*' \
            "$cgbuild/haet_scene_steps" "$scene" "${args[@]}" --settle "$CG_SETTLE" --steps "$CG_STEPS" \
            > "$runs/cg_$f.txt" 2>&1 || { log "callgrind failed; see $runs/cg_$f.txt"; exit 1; }
        ir=$(sed -n 's/^summary: *//p' "$runs/cg_$f.out")
        cg+=("$(calc "printf \"%.1f\", $ir / ($n * $CG_STEPS)")")
    done
    echo "instructions per particle-step ($cg_arch, $CG_STEPS steps after $CG_SETTLE): plane ${cg[0]}, mesh ${cg[1]}: mesh / plane $(ratio "${cg[1]}" "${cg[0]}")"
else
    log "instruction counts skipped: no valgrind or no $cgbuild/haet_scene_steps (a build with -DHAET_ARCH=x86-64-v3)"
fi

header="case,n_particles,triangles,settle_steps,windows,window_steps,rounds,plane_fastest_ns,mesh_fastest_ns,ratio_fastest,plane_fastest_cpu_ns,mesh_fastest_cpu_ns,ratio_fastest_cpu,plane_median_ns,mesh_median_ns,ratio_median,plane_instructions,mesh_instructions,ratio_instructions,goal,date,haet_commit,haet_arch,load_before,load_after,note"
note=$(printf '%s' "${NOTE:-}" | tr ',\n' ';;')
cg_ratio=NA
[ "${#cg[@]}" -eq 2 ] && cg_ratio=$(ratio "${cg[1]}" "${cg[0]}")
row="bed3d,$n,$triangles,$SETTLE,$WINDOWS,$WSTEPS,$ROUNDS,${best[plane]},${best[mesh]},$(ratio "${best[mesh]}" "${best[plane]}"),${bestcpu[plane]},${bestcpu[mesh]},$(ratio "${bestcpu[mesh]}" "${bestcpu[plane]}"),$pm,$mm,$(ratio "$mm" "$pm"),${cg[0]:-NA},${cg[1]:-NA},$cg_ratio,1.15,$(date -u +%Y-%m-%dT%H:%M:%SZ),$haet_commit,$haet_arch,$load_before,$load_after,$note"
if [ -s "$csv" ] && [ "$(head -n 1 "$csv")" != "$header" ]; then
    log "warning: $csv has other columns; the row goes to $csv.new"
    csv=$csv.new
fi
[ -s "$csv" ] || echo "$header" > "$csv"
echo "$row" >> "$csv"
echo "appended to bench/${csv#"$here"/}"
if [ "${#cg[@]}" -eq 2 ]; then
    for k in 0 1; do
        f=$([ "$k" = 0 ] && echo plane || echo mesh)
        echo "mesh_floor,bed3d_$f,1,haet,$haet_commit,$cg_arch,${cg[$k]},instructions per particle-step,mesh_floor_window,$n spheres; $CG_STEPS steps after $CG_SETTLE; $triangles triangles" >> "$cgcsv"
    done
    echo "mesh_floor,bed3d_mesh_over_plane,1,haet,$haet_commit,$cg_arch,$cg_ratio,ratio,mesh_floor_window,$triangles triangles against the plane" >> "$cgcsv"
    echo "appended to bench/${cgcsv#"$here"/}"
fi
