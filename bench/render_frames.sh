#!/usr/bin/env bash
# What a picture of a 3D state costs: `haet render` of FRAMES snapshots of SPHERES spheres (examples/box3d_settle.toml
# with smaller spheres, rained in for a few steps, seen obliquely from above), ROUNDS times; the fastest round by CPU
# time and by wall time, per frame. A frame is the reading of its snapshot and walls, the drawing (a 900 px wide
# view, about 2 100 px tall) and the PNG encoding; the colour bar is given (--range), so no pass finds it.
#
#   bench/render_frames.sh BUILD_DIR
#
# Appends one row to bench/results/MACHINE/render.csv (columns: bench/results/README.md).
# Environment: SPHERES (20000), ROUNDS (5), MACHINE, NOTE. Exit status: 0 measured; 1 a run failed; 2 usage.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
[ -d "$1" ] || { echo "$0: build directory not found: $1" >&2; exit 2; }
setup "$0" "$1" "$here/data/runs/render_frames"
SPHERES=${SPHERES:-20000}
ROUNDS=${ROUNDS:-5}
machine=${MACHINE:-$(machine_name)}
csv=$here/results/$machine/render.csv
runs=$out
[ -x "$haet" ] || { echo "$0: $haet not found" >&2; exit 1; }
mkdir -p "$(dirname "$csv")"
load_before=$(cut -d' ' -f1 /proc/loadavg)

# Five snapshots 0.5 ms apart: the spheres where they were placed, falling.
"$haet" run -q "$root/examples/box3d_settle.toml" --out "$runs/run" --threads 1 \
    --set "insert[1].count=$SPHERES" --set 'insert[1].radius=[0.00025, 0.0003]' --set duration=0.002 \
    --set output.snapshot_period=0.0005 --set 'output.view=[1, 1, -0.5]'
frames=$(grep -c '<DataSet' "$runs/run/particles.pvd")
best_cpu="" best_wall=""
for ((r = 0; r < ROUNDS; ++r)); do
    /usr/bin/time -f '%U %S %e' -o "$runs/time.txt" \
        "$haet" render "$runs/run" --no-movie --range 0,0.1 --out "$runs/frames" 2>/dev/null
    read -r user sys wall < "$runs/time.txt"
    cpu=$(awk "BEGIN { print $user + $sys }")
    best_cpu=$(awk "BEGIN { b = \"$best_cpu\"; print (b == \"\" || $cpu < b) ? $cpu : b }")
    best_wall=$(awk "BEGIN { b = \"$best_wall\"; print (b == \"\" || $wall < b) ? $wall : b }")
done
size=$(python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print('%dx%d' % struct.unpack('>II', d[16:24]))" \
    "$runs/frames/frame_000000.png")
load_after=$(cut -d' ' -f1 /proc/loadavg)
cpu_frame=$(awk "BEGIN { printf \"%.4f\", $best_cpu / $frames }")
wall_frame=$(awk "BEGIN { printf \"%.4f\", $best_wall / $frames }")
printf 'render %s spheres, %s frames of %s px: %s s CPU, %s s wall per frame (fastest of %s)\n' "$SPHERES" "$frames" \
    "$size" "$cpu_frame" "$wall_frame" "$ROUNDS"
[ -s "$csv" ] || echo "case,spheres,frames,picture_px,rounds,cpu_s_per_frame,wall_s_per_frame,date,haet_commit,haet_arch,load_before,load_after,note" > "$csv"
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo NA)
arch=$(sed -n 's/^HAET_ARCH:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null)
echo "box3d_rain,$SPHERES,$frames,$size,$ROUNDS,$cpu_frame,$wall_frame,$(date -u +%Y-%m-%dT%H:%M:%SZ),$commit,${arch:-NA},$load_before,$load_after,${NOTE:-}" >> "$csv"
