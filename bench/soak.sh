#!/usr/bin/env bash
# A soak: a long hybrid run with an inlet and outlets, its resident memory sampled while it runs.
#
#   bench/soak.sh BUILD_DIR [OUT_DIR]
#
# Runs SCENE (examples/silo2d.toml: fed at the top, drained below, method "haet") for STEPS (10^6) time steps on one
# thread, sampling the process's resident set (VmRSS of /proc/PID/status) every SAMPLE (5) seconds, and checks:
#   * no particle lost or duplicated: at every row of series.csv, n_particles = initial + inserted - removed (from
#     the inlets' and the removing outlets' columns; counters do not remove), and the ids of every snapshot are
#     distinct;
#   * memory flat: once the count has reached its steady level (the last half of the run), the resident set's
#     growth from the first to the last sample of that half, in bytes and per particle; and its peak.
# Writes OUT_DIR/soak/rss.csv (wall s, rss bytes) and appends one row to bench/results/MACHINE/soak.csv. Exit status:
# 0 both checks hold; 1 a check failed or the run failed; 2 usage.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
setup "$0" "$@"
SCENE=${SCENE:-$root/examples/silo2d.toml}
STEPS=${STEPS:-1000000}
SAMPLE=${SAMPLE:-5}
dir="$out/soak"
rm -rf "$dir" "$dir.probe"
mkdir -p "$dir"

# The scene's time step, from a run of a few steps.
"$haet" run "$SCENE" --set duration=1e-4 --set output.snapshot_period=-1 --out "$dir.probe" --threads 1 --quiet
dt=$(python3 -c 'import json, sys; print(repr(json.load(open(sys.argv[1]))["dt"]))' "$dir.probe/run.json")
rm -rf "$dir.probe"
duration=$(python3 -c "print(repr($STEPS * $dt))")
echo "soak: $(basename "$SCENE"), $STEPS steps of $dt s = $duration s simulated, one thread"

# The periods first: the background command's only child must be the run.
rows=$(python3 -c "print(repr($duration / 500))")
shots=$(python3 -c "print(repr($duration / 10))")
/usr/bin/time -f "%U %S %e" -o "$dir.time" "$haet" run "$SCENE" --set "duration=$duration" \
    --set "output.series_period=$rows" --set "output.snapshot_period=$shots" --out "$dir/run" --threads 1 --quiet &
pid=$!
# /usr/bin/time's child is the run (named "exe" once it has re-executed itself with its OpenMP settings): wait
# until it has been started.
child=""
for _ in $(seq 1 100); do
    child=$(pgrep -P "$pid" | head -n 1 || true)
    [ -n "$child" ] && break
    sleep 0.1
done
[ -n "$child" ] || { echo "soak: the run did not start" >&2; exit 1; }
echo "wall_s,rss_bytes" >"$dir/rss.csv"
start=$(date +%s.%N)
while kill -0 "$pid" 2>/dev/null; do
    rss=$(awk '/^VmRSS/ { print $2 * 1024 }' "/proc/$child/status" 2>/dev/null || true)
    [ -n "$rss" ] && echo "$(awk -v s="$start" -v n="$(date +%s.%N)" 'BEGIN { printf "%.1f", n - s }'),$rss" \
        >>"$dir/rss.csv"
    sleep "$SAMPLE"
done
wait "$pid" || { echo "soak: the run failed (see $dir/run)" >&2; exit 1; }
read -r user sys wall <"$dir.time"

machine=$(machine_name)
mkdir -p "$root/bench/results/$machine"
csv="$root/bench/results/$machine/soak.csv"
[ -f "$csv" ] || echo "date,commit,scene,steps,cpu_s,particles_min,particles_max,rss_growth_bytes,rss_growth_bytes_per_particle,rss_peak_bytes,balanced,ids_unique" >"$csv"
python3 - "$dir" "$csv" "$(basename "$SCENE" .toml)" "$STEPS" "$user" "$sys" \
    "$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)" <<'EOF'
import csv, datetime, glob, json, re, struct, sys

d, out, scene, steps, user, sys_t, commit = sys.argv[1:8]
run = json.load(open(f"{d}/run/run.json"))
flows = run["flows"]
inlets = list(flows["inlets"])
removing = [k for k, v in flows["outlets"].items() if not v.get("counter")]
rows = list(csv.DictReader(open(f"{d}/run/series.csv")))
bad = [r["time"] for r in rows
       if float(r["n_particles"]) != flows["initial_particles"] + sum(float(r[f"{k}_particles"]) for k in inlets)
       - sum(float(r[f"{k}_particles"]) for k in removing)]
counts = [float(r["n_particles"]) for r in rows]

def ids(path):  # the id array of a snapshot (appended raw data, UInt64 block headers)
    b = open(path, "rb").read()
    m = re.search(rb'Name="id"[^>]*offset="(\d+)"', b)
    start = b.index(b"_", b.index(b"<AppendedData")) + 1 + int(m.group(1))
    n = struct.unpack_from("<Q", b, start)[0] // 8
    return struct.unpack_from(f"<{n}q", b, start + 8)

dup = [p for p in sorted(glob.glob(f"{d}/run/particles_*.vtu")) if len(set(ids(p))) != len(ids(p))]
rss = [(float(a), int(b)) for a, b in (l.split(",") for l in open(f"{d}/rss.csv").read().split()[1:])]
half = rss[len(rss) // 2:]
growth = half[-1][1] - half[0][1] if len(half) >= 2 else 0
nmax = max(counts)
per = growth / nmax
print(f"particles {min(counts):.0f} .. {nmax:.0f}; rows balanced: {len(rows) - len(bad)} of {len(rows)}; "
      f"snapshots with duplicate ids: {len(dup)} of {len(glob.glob(f'{d}/run/particles_*.vtu'))}")
print(f"resident set: peak {max(b for _, b in rss) / 2**20:.1f} MiB over {len(rss)} samples; growth over the last "
      f"half {growth / 2**10:.0f} KiB ({per:.1f} bytes per particle); CPU {float(user) + float(sys_t):.1f} s")
ok = not bad and not dup and abs(per) < 50
with open(out, "a") as f:
    f.write(f"{datetime.date.today()},{commit},{scene},{steps},{float(user) + float(sys_t):.1f},{min(counts):.0f},"
            f"{nmax:.0f},{growth},{per:.2f},{max(b for _, b in rss)},{not bad},{not dup}\n")
sys.exit(0 if ok else 1)
EOF
