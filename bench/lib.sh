# Shared by the benchmark scripts (sourced, not run).

# machine_name: the processor as a directory name of bench/results/ ("amd-epyc-zen4", "intel-xeon-platinum-8375c"):
# the model name of /proc/cpuinfo in lower case, runs of other characters as "-"; AMD's generation added from the
# family and model numbers when the name does not hold it (a virtual machine may show only "AMD EPYC").
machine_name() {
    awk -F': *' '
        /^model name/ && name == "" { name = $2 } /^cpu family/ && fam == "" { fam = $2 } /^model\t/ && mod == "" { mod = $2 }
        END {
            s = tolower(name); gsub(/\((r|tm)\)|cpu @.*|[0-9]+-core processor|processor/, "", s)
            gsub(/[^a-z0-9]+/, "-", s); gsub(/^-+|-+$/, "", s); if (s == "") s = "unknown"
            if (s ~ /^amd/ && s !~ /zen/) {
                z = ""
                if (fam == 23) z = "zen2"
                else if (fam == 25) z = ((mod >= 16 && mod < 32) || (mod >= 96 && mod < 128) || (mod >= 160 && mod < 176)) ? "zen4" : "zen3"
                else if (fam == 26) z = "zen5"
                s = s "-" (z != "" ? z : "f" fam "m" mod)
            }
            print s
        }' /proc/cpuinfo 2>/dev/null || echo unknown
}

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

# run NAME SCENARIO [--set KEY=VALUE ...]: runs one scenario on one thread into $out/NAME, with the overrides
# given; sets CPU (user + sys, s) and WALL (s). Returns haet's exit status when the run fails (a scene a method
# refuses, say), after saying so: callers that go on without it test the status (`if run ...`), for under `if`
# bash does not stop at the failed command itself.
run() {
    local name=$1 scenario=$2 rc=0
    shift 2
    /usr/bin/time -f "%U %S %e" -o "$out/$name.time" "$haet" run "$scenario" "$@" --out "$out/$name" --threads 1 \
        --quiet || rc=$?
    if [ "$rc" -ne 0 ]; then
        echo "$name: haet exited with status $rc" >&2
        return "$rc"
    fi
    # time's last line holds the figures (a line before it reports a signal or a status)
    read -r user sys wall < <(tail -n 1 "$out/$name.time")
    CPU=$(awk -v u="$user" -v s="$sys" 'BEGIN { printf "%.2f", u + s }')
    WALL=$wall
}

# chute_args SCRIPT BUILD_DIR [3d|2d]: the arguments of a script on the chute of bench/lammps/; sets build (the
# build directory, absolute) and case (3d by default, or 2d); exits 2 with the usage otherwise.
chute_args() {
    local script=$1
    shift
    [ $# -ge 1 ] && [ $# -le 2 ] || { echo "usage: $script BUILD_DIR [3d|2d]" >&2; exit 2; }
    case=${2:-3d}
    case $case in 3d|2d) ;; *) echo "usage: $script BUILD_DIR [3d|2d]" >&2; exit 2 ;; esac
    [ -d "$1" ] || { echo "$script: build directory not found: $1" >&2; exit 2; }
    build=$(cd "$1" && pwd)
}
