#!/usr/bin/env bash
# `make bench`: every benchmark, one after the other (never two heavy processes at once).
#
#   bench/run_all.sh BUILD_DIR
#
# 1. bench/compare_lammps.sh BUILD_DIR 3d   HAET against LAMMPS, 3D chute (32 000 spheres)
# 2. bench/compare_lammps.sh BUILD_DIR 2d   the same in 2D (8 000 disks)
# 3. bench/haet_compare.sh BUILD_DIR        the hybrid against pure TDM and EDM (demo), dilute-fraction sweep
# 4. bench/dilute_compare.sh BUILD_DIR      EDM against TDM on a dilute granular gas, 3D and 2D
# 5. BUILD_DIR/haet_bench                   Google Benchmark micro-benchmarks, when built
# The first run on a machine prepares the flowing states with LAMMPS (10-15 min for 3D, once; kept in
# bench/data/). Installs the Debian packages lammps and time when missing. Exits non-zero when any part failed,
# after running the others.
set -uo pipefail

[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
[ -d "$1" ] || { echo "$0: build directory not found: $1" >&2; exit 2; }
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

missing=""
command -v "${LMP:-lmp}" >/dev/null || missing="$missing lammps"
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

if [ -x "$build/haet_bench" ]; then
    echo "=== micro-benchmarks: $build/haet_bench"
    "$build/haet_bench" --benchmark_min_time=0.5 || failed="$failed haet_bench"
else
    echo "=== micro-benchmarks: $build/haet_bench not built (needs libbenchmark-dev and bench/*.cpp); skipped"
fi

if [ -n "$failed" ]; then
    echo "bench: failed:$failed" >&2
    exit 1
fi
echo "bench: done"
