#!/usr/bin/env bash
# The hybrid against the single methods (issue: HAET performance), one thread, one run after the other.
#
#   bench/haet_compare.sh BUILD_DIR [OUT_DIR]
#
# 1. The flagship demo examples/haet_demo.toml (or $DEMO) run three ways, method = "tdm", "edm" and "haet", same
#    physics and simulated time. Prints CPU time (user + sys) and wall time of each and the ratios TDM / HAET and
#    EDM / HAET, and the bound N_total / N_dense (time average of n_tdm in the hybrid's series.csv).
# 2. The dilute-fraction sweep: examples/bed_and_cloud2d.toml with a bed of (1 - f) N disks and a falling cloud of
#    f N that does not reach the bed within the run (the counts and the method set by `haet run --set`), for f in $FRACTIONS; TDM and HAET each. Writes OUT_DIR/haet_sweep.csv
#    (fraction, measured mean event-driven fraction, CPU times, speed-up, bound) and OUT_DIR/haet_sweep.png.
#
# CPU times, not wall times, are compared: the machines are shared. OUT_DIR defaults to runs/bench.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
setup "$0" "$@"
demo=${DEMO:-$root/examples/haet_demo.toml}
N=${SWEEP_N:-4000}
FRACTIONS=${FRACTIONS:-"0.5 0.75 0.9 0.95"}

# mean of column COL of a series.csv
mean_col() { awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
    { s += $c; n++ } END { printf "%.6g", s / n }' "$1"; }

echo "--- demo: $(basename "$demo"), one thread"
declare -A cpu
for m in tdm edm haet; do
    if run "demo_$m" "$demo" --set "method=$m"; then
        cpu[$m]=$CPU
        printf "%-5s CPU %8.2f s   wall %8.2f s\n" "$m" "$CPU" "$WALL"
    else
        cpu[$m]=""
        echo "$m: run failed (see $out/demo_$m)"
    fi
done
n_total=$(mean_col "$out/demo_haet/series.csv" n_particles)
n_dense=$(mean_col "$out/demo_haet/series.csv" n_tdm)
awk -v t="${cpu[tdm]}" -v e="${cpu[edm]}" -v h="${cpu[haet]}" -v n="$n_total" -v d="$n_dense" 'BEGIN {
    if (t != "" && h > 0) printf "speed-up TDM / HAET: %.2f\n", t / h;
    if (e != "" && h > 0) printf "ratio    EDM / HAET: %.2f\n", e / h;
    printf "bound N_total / N_dense (time average): %.2f (N_dense = %.0f of %.0f)\n", n / d, d, n }'

echo "--- sweep: N = $N, fractions $FRACTIONS"
csv="$out/haet_sweep.csv"
echo "fraction,edm_fraction,cpu_tdm,cpu_haet,speedup,bound" >"$csv.tmp"
for f in $FRACTIONS; do
    rain=$(awk -v n="$N" -v f="$f" 'BEGIN { printf "%d", n * f + 0.5 }')
    bed=$((N - rain))
    for m in tdm haet; do
        run "sweep_${f}_$m" "$root/examples/bed_and_cloud2d.toml" --set "method=$m" --set "insert[1].count=$bed" \
            --set "insert[2].count=$rain"
        cpu[$m]=$CPU
    done
    series="$out/sweep_${f}_haet/series.csv"
    ef=$(awk -v e="$(mean_col "$series" n_edm)" -v n="$N" 'BEGIN { printf "%.4f", e / n }')
    bound=$(awk -v d="$(mean_col "$series" n_tdm)" -v n="$N" 'BEGIN { printf "%.3f", n / d }')
    speedup=$(awk -v t="${cpu[tdm]}" -v h="${cpu[haet]}" 'BEGIN { printf "%.3f", t / h }')
    echo "$f,$ef,${cpu[tdm]},${cpu[haet]},$speedup,$bound" >>"$csv.tmp"
    printf "f = %-5s event-driven %.3f   TDM %7.2f s   HAET %7.2f s   speed-up %6.2f   bound %6.2f\n" \
        "$f" "$ef" "${cpu[tdm]}" "${cpu[haet]}" "$speedup" "$bound"
done
mv "$csv.tmp" "$csv"
"$haet" plot "$csv" -x edm_fraction -y speedup -y bound --logy --title "HAET speed-up over TDM against the event-driven fraction" \
    -o "$out/haet_sweep.png"
echo "wrote $csv and $out/haet_sweep.png"
