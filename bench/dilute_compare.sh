#!/usr/bin/env bash
# Event-driven against time-driven on a dilute granular gas (issue: event-driven engine), one thread, one run after
# the other.
#
#   bench/dilute_compare.sh BUILD_DIR [OUT_DIR]
#
# examples/dilute_gas3d.toml and examples/dilute_gas2d.toml (4000 rough inelastic particles, e = 0.9, mu = 0.5, volume
# fraction 0.05, periodic box) run with method = "tdm" and method = "edm": same particles, same material, same
# simulated time. Prints the CPU time (user + sys, /usr/bin/time) of each and the ratio TDM / EDM of whole runs
# (goal: >= 50); then the same ratio without the set-up both share (insertion, contact table, outputs, the 2D
# picture), measured by a run of each over 1 us; and the kinetic energy at the end of each run (the two methods
# cool the same gas: they agree within a few per cent, docs/edm.md). CPU times, not wall times, are compared: the
# machines are shared. OUT_DIR defaults to runs/bench.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
setup "$0" "$@"

# last value of column NAME of a series.csv
last_col() { awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
    { v = $c } END { printf "%.6g", v }' "$1"; }

echo "load average (1 min) before: $(cut -d' ' -f1 /proc/loadavg)"
for d in 3d 2d; do
    scene=$root/examples/dilute_gas$d.toml
    echo "--- dilute gas $d: $(basename "$scene"), one thread"
    declare -A cpu=() setup=() ke=()
    for m in tdm edm; do
        run "dilute${d}_${m}_setup" "$scene" --set "method=$m" --set duration=1e-6
        setup[$m]=$CPU
        run "dilute${d}_$m" "$scene" --set "method=$m"
        cpu[$m]=$CPU
        ke[$m]=$(last_col "$out/dilute${d}_$m/series.csv" kinetic_energy)
        printf "%-4s CPU %8.2f s (set-up %5.2f s)   wall %8.2f s   kinetic energy at the end %s J\n" "$m" "$CPU" \
            "${setup[$m]}" "$WALL" "${ke[$m]}"
    done
    awk -v t="${cpu[tdm]}" -v e="${cpu[edm]}" -v t0="${setup[tdm]}" -v e0="${setup[edm]}" -v kt="${ke[tdm]}" \
        -v ke="${ke[edm]}" 'BEGIN {
        # /usr/bin/time counts in 0.01 s: less than that is counted as 0.01 s
        printf "CPU ratio TDM / EDM: %.0f (goal >= 50)\n", t / (e < 0.01 ? 0.01 : e);
        de = e - e0;
        printf "the same without the set-up: %.0f\n", (t - t0) / (de < 0.01 ? 0.01 : de);
        printf "kinetic energy EDM / TDM at the end: %.4f\n", ke / kt }'
done
echo "load average (1 min) after: $(cut -d' ' -f1 /proc/loadavg)"
