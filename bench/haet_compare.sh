# The hybrid against the single methods (issue: HAET performance), one thread.
#
#   bench/haet_compare.sh BUILD_DIR [OUT_DIR]
#
# 1. The flagship demo examples/silo2d.toml, its 3D variant silo3d_discharge.toml and the falling-stream demo
#    examples/haet_demo.toml (or the scenes in $DEMOS), each run three ways, method = "tdm", "haet" and "edm", same
#    physics and simulated time, in $ROUNDS alternating rounds (tdm, haet, edm, tdm, ...: a slow spell of the shared
#    machine hits all three alike). Prints
#    per round the CPU time (user + sys) and wall time of each, the speed-up TDM / HAET and the ratio EDM / HAET
#    with their min / median / max over the rounds, the bound N_total / N_dense (time average of n_tdm in the
#    hybrid's series.csv), and for a scene with an outlet named "orifice" the discharge rate of each method (mean
#    orifice_rate over the second half of the run: the physics must agree, not only the time). Appends the rounds
#    to bench/results/MACHINE/haet_demo.csv.
# 2. The dilute-fraction sweep: examples/bed_and_cloud2d.toml with a bed of (1 - f) N disks and a falling cloud of
#    f N that does not reach the bed within the run (the counts and the method set by `haet run --set`), for f in
#    $FRACTIONS; TDM and HAET each. Writes OUT_DIR/haet_sweep.csv (fraction, measured mean event-driven fraction,
#    CPU times, speed-up, bound) and OUT_DIR/haet_sweep.png.
#
# CPU times, not wall times, are compared: the machines are shared. OUT_DIR defaults to runs/bench.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=bench/lib.sh
. "$here/lib.sh"
setup "$0" "$@"
DEMOS=${DEMOS:-"$root/examples/silo2d.toml $root/examples/silo3d_discharge.toml $root/examples/haet_demo.toml"}
ROUNDS=${ROUNDS:-3}
N=${SWEEP_N:-4000}
FRACTIONS=${FRACTIONS:-"0.5 0.75 0.9 0.95"}

# mean of column COL of a series.csv (rows with time >= FROM, default all; empty cells skipped)
mean_col() { awk -F, -v name="$2" -v from="${3:-0}" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
    c && $1 >= from && $c != "" { s += $c; n++ } END { if (n) printf "%.6g", s / n; else printf "NA" }' "$1"; }
# min / median / max of the numbers on stdin
stats() { sort -g | awk '{ v[NR] = $1 } END { if (NR) printf "%.3f / %.3f / %.3f", v[1], v[int((NR + 1) / 2)], v[NR] }'; }

machine=$(machine_name)
results="$root/bench/results/$machine"
mkdir -p "$results"
csv_demo="$results/haet_demo.csv"
[ -f "$csv_demo" ] || echo "date,commit,scene,round,method,cpu_s,wall_s,simulated_s,orifice_rate,bound" >"$csv_demo"
commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)

for demo in $DEMOS; do
    scene=$(basename "$demo" .toml)
    duration=$(awk -F'[= ]+' '/^duration/ { print $2; exit }' "$demo")
    echo "--- demo: $scene ($duration s simulated), one thread, $ROUNDS alternating rounds"
    : >"$out/${scene}_speedup.txt"
    : >"$out/${scene}_edm_ratio.txt"
    for r in $(seq 1 "$ROUNDS"); do
        declare -A cpu=()
        for m in tdm haet edm; do
            name="${scene}_${m}_$r"
            if run "$name" "$demo" --set "method=$m"; then
                cpu[$m]=$CPU
                rate=$(mean_col "$out/$name/series.csv" orifice_rate "$(awk -v d="$duration" 'BEGIN { print d / 2 }')")
                bound=NA
                if [ "$m" = haet ]; then
                    bound=$(awk -v n="$(mean_col "$out/$name/series.csv" n_particles)" \
                        -v d="$(mean_col "$out/$name/series.csv" n_tdm)" 'BEGIN { printf "%.3f", n / d }')
                fi
                printf "round %d  %-5s CPU %8.2f s   wall %8.2f s   orifice rate %-10s bound %s\n" \
                    "$r" "$m" "$CPU" "$WALL" "$rate" "$bound"
                echo "$(date -u +%F),$commit,$scene,$r,$m,$CPU,$WALL,$duration,$rate,$bound" >>"$csv_demo"
            else
                cpu[$m]=""
                echo "round $r  $m: run failed (see $out/$name)"
            fi
        done
        [ -n "${cpu[tdm]}" ] && [ -n "${cpu[haet]}" ] &&
            awk -v t="${cpu[tdm]}" -v h="${cpu[haet]}" 'BEGIN { printf "%.4f\n", t / h }' >>"$out/${scene}_speedup.txt"
        [ -n "${cpu[edm]}" ] && [ -n "${cpu[haet]}" ] &&
            awk -v e="${cpu[edm]}" -v h="${cpu[haet]}" 'BEGIN { printf "%.4f\n", e / h }' >>"$out/${scene}_edm_ratio.txt"
        unset cpu
    done
    echo "$scene: speed-up TDM / HAET (min / median / max): $(stats <"$out/${scene}_speedup.txt")"
    echo "$scene: ratio    EDM / HAET (min / median / max): $(stats <"$out/${scene}_edm_ratio.txt")"
done

echo "--- sweep: N = $N, fractions $FRACTIONS"
declare -A cpu=()
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
