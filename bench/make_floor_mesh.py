#!/usr/bin/env python3
"""Writes the flat mesh floor of bench/mesh_floor.sh: the floor of examples/box3d_settle.toml, [0, 0.02]^2 at z = 0,
as tools/make_stl.py's incline at a finer grid (its interior vertices jittered in the plane, so that no two edges
line up), a binary STL of 2 n^2 triangles (n = 71 by default: 10 082), normal +z.

    bench/make_floor_mesh.py OUT [--cells N] [--size L]

The file (about 0.5 MB) is made when missing and not committed; the same arguments give the same bytes.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import make_stl  # noqa: E402  (tools/make_stl.py: the shapes of examples/meshes/)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--cells", type=int, default=71, help="cells along each side (2 triangles each)")
    ap.add_argument("--size", type=float, default=0.02, help="side of the square [m]")
    args = ap.parse_args(argv)
    tris = make_stl.incline(lx=args.size, ly=args.size, nx=args.cells, ny=args.cells)
    header = "flat floor %g x %g m, %d x %d cells, jittered, normal +z" % (args.size, args.size, args.cells,
                                                                          args.cells)
    data = make_stl.binary_stl(tris, header)
    tmp = args.out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, args.out)
    print("%s: %d triangles, %d bytes" % (args.out, len(tris), len(data)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
