#!/usr/bin/env bash
# What a checkpoint of a hybrid run costs: its size per particle and the wall time to write one, for the hybrid
# scenes of examples/ (the 2D demo, its 3D twin, the 2D silo with its inlet and outlets), each run for DURATION with
# a checkpoint every DURATION / 4 and no snapshots, one thread; the figures are the run's own (`run.json`,
# "checkpoints": the last file's size, the seconds spent making and writing them over their count).
#
#   bench/checkpoint_cost.sh BUILD_DIR
#
# Appends one row per scene to bench/results/MACHINE/checkpoint.csv (columns: bench/results/README.md).
# Environment: DURATION (0.02 s), MACHINE, NOTE. Exit status: 0 measured; 1 a run failed; 2 usage.
set -euo pipefail

[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
[ -x "$1/haet" ] || { echo "$0: no haet in $1" >&2; exit 2; }
build=$(cd "$1" && pwd)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
DURATION=${DURATION:-0.02}
machine=${MACHINE:-$(machine_name)}
csv="$root/bench/results/$machine/checkpoint.csv"
mkdir -p "$(dirname "$csv")"
[ -s "$csv" ] || echo "date,haet_commit,haet_arch,method,dimension,particles,checkpoint_bytes,bytes_per_particle,write_ms,note" >"$csv"
arch=$(sed -n 's/^HAET_ARCH:[A-Z]*=//p' "$build/CMakeCache.txt" 2>/dev/null || true)
commit=$(git -C "$root" rev-parse --short HEAD)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

for scene in haet_demo.toml haet_demo3d.toml silo2d.toml; do
    dir="$out/${scene%.toml}"
    "$build/haet" run -q "$root/examples/$scene" --threads 1 --out "$dir" --set duration="$DURATION" \
        --set output.checkpoint_period="$(python3 -c "print($DURATION / 4)")" --set output.snapshot_period=-1 ||
        exit 1
    row=$(python3 - "$dir/run.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
c = j["checkpoints"]
n = j["n_particles"]
print("%s,%d,%d,%d,%.1f,%.2f" % (j["method"], j["dimension"], n, c["last_bytes"], c["last_bytes"] / n,
                                  1000 * c["seconds"] / c["written"]))
EOF
)
    note="$scene duration=$DURATION checkpoint_period=DURATION/4 one thread${NOTE:+; $NOTE}"
    echo "$(date -u +%Y-%m-%d),$commit,${arch:-NA},$row,$note" | tee -a "$csv"
done
