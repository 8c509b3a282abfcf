# Shared by the benchmark scripts (sourced, not run). The caller sets `haet` (the binary) and `out` (a directory).

# run NAME SCENARIO: runs one scenario on one thread into $out/NAME; sets CPU (user + sys, s) and WALL (s).
run() {
    local name=$1 scenario=$2
    /usr/bin/time -f "%U %S %e" -o "$out/$name.time" "$haet" run "$scenario" --out "$out/$name" --threads 1 --quiet
    read -r user sys wall <"$out/$name.time"
    CPU=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    WALL=$wall
}
