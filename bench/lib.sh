# Shared by the benchmark scripts (sourced, not run).

# setup SCRIPT BUILD_DIR [OUT_DIR]: the arguments of a comparison script. Sets build, root, out (created;
# default runs/bench), haet (the binary); exits 2 without BUILD_DIR, 1 without /usr/bin/time.
setup() {
    local script=$1
    shift
    [ $# -ge 1 ] || { echo "usage: $script BUILD_DIR [OUT_DIR]" >&2; exit 2; }
    build=$(cd "$1" && pwd)
    root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
    out=${2:-$root/runs/bench}
    mkdir -p "$out"
    haet="$build/haet"
    [ -x /usr/bin/time ] || { echo "$script: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
}

# The functions below use `haet` (the binary) and `out` (a directory), as setup leaves them.

# run NAME SCENARIO: runs one scenario on one thread into $out/NAME; sets CPU (user + sys, s) and WALL (s).
run() {
    local name=$1 scenario=$2
    /usr/bin/time -f "%U %S %e" -o "$out/$name.time" "$haet" run "$scenario" --out "$out/$name" --threads 1 --quiet
    read -r user sys wall <"$out/$name.time"
    CPU=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    WALL=$wall
}
