#!/usr/bin/env bash
# Writes the starting lattice of the granular-chute benchmark as a LAMMPS data file (atom_style sphere):
# "Atoms # sphere" lines "id type diameter density x y z" and a "Velocities" section "id vx vy vz wx wy wz".
#
#   bench/make_chute_data.sh 3d   OUT [SEED]   40 x 20 x 40 simple-cubic lattice, 32 000 spheres
#   bench/make_chute_data.sh 2d   OUT [SEED]   200 x 40 square lattice, 8 000 disks (z = 0)
#   bench/make_chute_data.sh idle3d OUT        1 sphere at rest in the middle of the 3d box (memory baseline)
#   bench/make_chute_data.sh idle2d OUT        1 disk at rest in the middle of the 2d box
#
# Units are LAMMPS lj: diameter 1, mass 1 (density 6/pi; LAMMPS takes mass = density * (4/3) pi r^3 in 2D too).
# Lattice spacing 1.05; centres at (i + 1/2) * 1.05. The bottom layer (3D: lowest z plane, 2D: lowest y row)
# is atom type 2, the frozen base; the rest are type 1 with uniform random velocities in [-0.1, 0.1] per
# component (zero spin). x and y (2D: x) span exactly the lattice period; the open axis reaches twice the
# lattice height so the flow has room above it (LAMMPS "fm": the upper bound only ever grows).
# Overrides for quick tests: NX NY NZ (NZ is unused in 2D) and VAMP (velocity amplitude).
set -euo pipefail

usage() { echo "usage: $0 3d|2d|idle3d|idle2d OUT [SEED]" >&2; exit 2; }
[ $# -ge 2 ] || usage
kind=$1 out=$2 seed=${3:-20240601}

case $kind in
  3d)     dim=3 nx=${NX:-40}  ny=${NY:-20} nz=${NZ:-40} ;;
  2d)     dim=2 nx=${NX:-200} ny=${NY:-40} nz=1 ;;
  idle3d) dim=3 nx=${NX:-40}  ny=${NY:-20} nz=${NZ:-40} ;;
  idle2d) dim=2 nx=${NX:-200} ny=${NY:-40} nz=1 ;;
  *) usage ;;
esac

mkdir -p "$(dirname "$out")"
tmp="$out.tmp.$$"
trap 'rm -f "$tmp"' EXIT

awk -v dim="$dim" -v nx="$nx" -v ny="$ny" -v nz="$nz" -v a=1.05 -v seed="$seed" -v vamp="${VAMP:-0.1}" \
    -v kind="$kind" '
function u() { return vamp * (2 * rand() - 1) }
BEGIN {
    srand(seed)
    rho = 6 / (4 * atan2(1, 1))        # 6 / pi: mass 1 for diameter 1
    n = 0
    if (dim == 3) { xhi = nx * a; yhi = ny * a; zlo = 0; zhi = 2 * nz * a }
    else { xhi = nx * a; yhi = 2 * ny * a; zlo = -0.5; zhi = 0.5 }
    if (kind ~ /^idle/) {
        # One free particle at rest in the middle of the same box: the same input with (almost) no atoms, so
        # what grows with the box (cells, bins, pictures) cancels out of the memory per particle.
        n = 1; type[1] = 1; x[1] = xhi / 2; y[1] = yhi / 2; z[1] = (dim == 3) ? zhi / 2 : 0
        vx[1] = vy[1] = vz[1] = 0
        title = "HAET chute benchmark: idle baseline, 1 particle in the " dim "D box"
    } else if (dim == 3) {
        for (k = 0; k < nz; k++) for (j = 0; j < ny; j++) for (i = 0; i < nx; i++) {
            n++
            x[n] = (i + 0.5) * a; y[n] = (j + 0.5) * a; z[n] = (k + 0.5) * a
            type[n] = (k == 0) ? 2 : 1
            if (k == 0) { vx[n] = vy[n] = vz[n] = 0 } else { vx[n] = u(); vy[n] = u(); vz[n] = u() }
        }
        title = sprintf("HAET chute benchmark: 3D simple-cubic lattice %d x %d x %d, spacing %g, seed %d", nx, ny, nz, a, seed)
    } else {
        for (j = 0; j < ny; j++) for (i = 0; i < nx; i++) {
            n++
            x[n] = (i + 0.5) * a; y[n] = (j + 0.5) * a; z[n] = 0
            type[n] = (j == 0) ? 2 : 1
            if (j == 0) { vx[n] = vy[n] = 0 } else { vx[n] = u(); vy[n] = u() }
            vz[n] = 0
        }
        title = sprintf("HAET chute benchmark: 2D square lattice %d x %d, spacing %g, seed %d", nx, ny, a, seed)
    }
    print "LAMMPS data file: " title " (bench/make_chute_data.sh)"
    print ""
    printf "%d atoms\n2 atom types\n\n", n
    printf "0 %.10g xlo xhi\n0 %.10g ylo yhi\n%.10g %.10g zlo zhi\n\n", xhi, yhi, zlo, zhi
    print "Atoms # sphere\n"
    for (p = 1; p <= n; p++) printf "%d %d 1 %.16g %.10g %.10g %.10g\n", p, type[p], rho, x[p], y[p], z[p]
    print "\nVelocities\n"
    for (p = 1; p <= n; p++) printf "%d %.10g %.10g %.10g 0 0 0\n", p, vx[p], vy[p], vz[p]
}' > "$tmp"
mv "$tmp" "$out"
trap - EXIT
echo "wrote $out ($(awk '/ atoms$/ {print $1; exit}' "$out") particles)"
