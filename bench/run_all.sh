#!/usr/bin/env bash
# `make bench`: every benchmark, one after the other (never two heavy processes at once).
#
#   bench/run_all.sh BUILD_DIR
#
# 1. bench/compare_lammps.sh BUILD_DIR 3d   HAET against LAMMPS, 3D chute (32 000 spheres)
# 2. bench/compare_lammps.sh BUILD_DIR 2d   the same in 2D (8 000 disks)
# 3. bench/haet_compare.sh BUILD_DIR        the hybrid against pure TDM and EDM (demo), dilute-fraction sweep
# 4. bench/dilute_compare.sh BUILD_DIR      EDM against TDM on a dilute granular gas, 3D and 2D
# 5. bench/compare_liggghts.sh BUILD_DIR    HAET against LIGGGHTS, the 3D silo of two STL meshes (6 000 spheres)
# 6. bench/mesh_floor.sh BUILD_DIR          a settled bed on a 10 082-triangle mesh floor against its plane (wall time;
#                                           instruction counts too when BUILD_DIR-v3, an x86-64-v3 build, exists)
# 7. bench/render_frames.sh BUILD_DIR      haet render of 20 000 spheres: CPU and wall time per frame
# 8. BUILD_DIR/haet_bench                   Google Benchmark micro-benchmarks, when built
# 9. BUILD_DIR/haet_bench PolygonSettle2D   10 000 hexagons vs 10 000 disks settling, 1 and 2 threads, side by
#                                           side in one run, with the polygon/disk cost ratio
# 10. bench/python_step_loop.py             a Python loop of 10 000 sim.step(1) against sim.step(10000), 10 000
#                                           disks (when the module is built: BUILD_DIR/python)
# 11. bench/peers/edmd_smallenburg.sh       the event-driven engine against Smallenburg's EDMD (Single, Cell), 3D
#                                           phi = 0.1, 0.3, 0.45, when EDMD_SOURCE names a checkout of it
# The first run on a machine prepares the flowing states with LAMMPS (10-15 min for 3D, once; kept in
# bench/data/) and LIGGGHTS (a few minutes), and the settled bed (about a minute). Installs the Debian packages
# lammps, liggghts and time when missing. Exits non-zero when any part failed, after running the others.
set -uo pipefail

[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
[ -d "$1" ] || { echo "$0: build directory not found: $1" >&2; exit 2; }
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

missing=""
command -v "${LMP:-lmp}" >/dev/null || missing="$missing lammps"
command -v "${LIGGGHTS:-liggghts}" >/dev/null || missing="$missing liggghts"
[ -x /usr/bin/time ] || missing="$missing time"
if [ -n "$missing" ]; then
    echo "installing:$missing"
    sudo=""; [ "$(id -u)" = 0 ] || sudo=sudo
    $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $missing >/dev/null ||
        { echo "$0: could not install$missing" >&2; exit 1; }
fi

failed=""
for c in 3d 2d; do
    echo "=== chute $c: HAET vs LAMMPS"
    "$here/compare_lammps.sh" "$build" "$c" || failed="$failed chute$c"
    echo
done

echo "=== hybrid: HAET vs TDM vs EDM"
"$here/haet_compare.sh" "$build" || failed="$failed haet"
echo

echo "=== dilute gas: EDM vs TDM"
"$here/dilute_compare.sh" "$build" || failed="$failed dilute"
echo

echo "=== silo: HAET vs LIGGGHTS"
"$here/compare_liggghts.sh" "$build" || failed="$failed silo"
echo

echo "=== mesh floor vs plane floor"
"$here/mesh_floor.sh" "$build" || failed="$failed mesh_floor"
echo

echo "=== pictures: haet render of 20 000 spheres"
"$here/render_frames.sh" "$build" || failed="$failed render"
echo

if [ -x "$build/haet_bench" ]; then
    echo "=== micro-benchmarks: $build/haet_bench"
    "$build/haet_bench" --benchmark_min_time=0.5 --benchmark_filter='^Edm' || failed="$failed haet_bench"
    echo
    echo "=== polygons vs disks: 10 000 hexagons / disks settling in a box (bench/polygon_settle.cpp)"
    csv=$(mktemp)
    if "$build/haet_bench" --benchmark_filter='^PolygonSettle2D' --benchmark_format=csv > "$csv"; then
        # particle_steps_per_s is the 12th CSV column; names look like "PolygonSettle2D/hexagons/1/...".
        awk -F, 'NR > 1 && $1 ~ /PolygonSettle2D/ {
                     split($1, part, "/"); gsub(/"/, "", part[2]); rate[part[2] "/" part[3]] = $12 }
                 END {
                     for (t = 1; t <= 2; ++t) {
                         h = rate["hexagons/" t]; d = rate["disks/" t]
                         printf "threads %d: hexagons %.3g polygon-steps/s, disks %.3g disk-steps/s, " \
                                "polygon step / disk step = %.2f\n", t, h, d, (h > 0 ? d / h : 0)
                     }
                 }' "$csv"
    else
        failed="$failed polygon_settle"
    fi
    rm -f "$csv"
else
    echo "=== micro-benchmarks: $build/haet_bench not built (needs libbenchmark-dev and bench/*.cpp); skipped"
fi

if ls "$build"/python/haet*.so >/dev/null 2>&1; then
    echo "=== Python: a loop of single steps against one call (bench/python_step_loop.py)"
    PYTHONPATH="$build/python" /usr/bin/python3 "$here/python_step_loop.py" || failed="$failed python_step_loop"
    echo
else
    echo "=== Python: $build/python not built (make python); skipped"
fi

if [ -n "${EDMD_SOURCE:-}" ]; then
    echo "=== event-driven gas: HAET vs Smallenburg's EDMD ($EDMD_SOURCE)"
    "$here/peers/edmd_smallenburg.sh" "$EDMD_SOURCE" "$build" || failed="$failed peers_edmd"
    echo
else
    echo "=== event-driven peers: EDMD_SOURCE not set (a checkout of https://github.com/FSmallenburg/EDMD); skipped"
fi

if [ -n "$failed" ]; then
    echo "bench: failed:$failed" >&2
    exit 1
fi
echo "bench: done"
