#!/usr/bin/env python3
"""Generates the STL meshes the examples use (examples/meshes/), in metres, with the Python standard library only.

    python3 tools/make_stl.py [--out DIR]      (default: examples/meshes next to this script's folder)

The files are committed; tests/test_stl_meshes.cpp runs this script into a temporary folder and checks that it
writes the same bytes, and that the reader takes every file. Change a shape here, run the script, commit both.

Orientation: a triangle's vertex order is counter-clockwise seen from the side its normal points to, and the normal
points to where the particles are (into a container, out of a solid body). Axis-symmetric shapes stand on the z axis
with their base at z = 0; a scene places them with the loader's scale, rotation and translation.

Every coordinate is rounded to 1e-10 m before it is written (ASCII) or rounded to float32 (binary), so the bytes do
not depend on the last bit of the platform's sin and cos.
"""
import argparse
import math
import os
import random
import struct
import sys


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def normal(t):
    n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
    ln = math.sqrt(dot(n, n))
    return (n[0] / ln, n[1] / ln, n[2] / ln) if ln > 0 else (0.0, 0.0, 0.0)


def rounded(p):
    return tuple(round(x, 10) + 0.0 for x in p)  # + 0.0: no "-0.0" in the text


def oriented(t, toward):
    """The triangle t, its last two vertices swapped if its normal does not point along `toward`."""
    t = tuple(rounded(p) for p in t)
    n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
    assert dot(n, n) > 0, "degenerate triangle"
    return t if dot(n, toward) > 0 else (t[0], t[2], t[1])


def centroid(t):
    return tuple((t[0][k] + t[1][k] + t[2][k]) / 3 for k in range(3))


def radial_in(t):
    """Direction from the triangle's centroid towards the z axis."""
    c = centroid(t)
    return (-c[0], -c[1], 0.0)


def ring(r, z, k, n):
    a = 2 * math.pi * k / n
    return (r * math.cos(a), r * math.sin(a), z)


def band(r0, z0, r1, z1, around, rows):
    """A surface of revolution between the circles (r0, z0) and (r1, z1): `rows` rows of 2 `around` triangles,
    oriented towards the axis (a container's inside)."""
    tris = []
    for j in range(rows):
        ra, za = r0 + (r1 - r0) * j / rows, z0 + (z1 - z0) * j / rows
        rb, zb = r0 + (r1 - r0) * (j + 1) / rows, z0 + (z1 - z0) * (j + 1) / rows
        for k in range(around):
            a, b = ring(ra, za, k, around), ring(ra, za, k + 1, around)
            c, d = ring(rb, zb, k, around), ring(rb, zb, k + 1, around)
            for t in ((a, b, d), (a, d, c)):
                tris.append(oriented(t, radial_in(t)))
    return tris


def disc(r, z, around, rings, up):
    """A disc of radius r at height z from `rings` concentric rings (a fan in the middle), normal +z if up."""
    tris = []
    direction = (0.0, 0.0, 1.0 if up else -1.0)
    for j in range(rings):
        ra, rb = r * j / rings, r * (j + 1) / rings
        for k in range(around):
            c, d = ring(rb, z, k, around), ring(rb, z, k + 1, around)
            if j == 0:
                tris.append(oriented(((0.0, 0.0, z), c, d), direction))
                continue
            a, b = ring(ra, z, k, around), ring(ra, z, k + 1, around)
            tris.append(oriented((a, c, d), direction))
            tris.append(oriented((a, d, b), direction))
    return tris


def incline(lx=0.1, ly=0.05, nx=40, ny=20, jitter=0.2, seed=19):
    """A flat rectangle [0, lx] x [0, ly] at z = 0, normal +z, as an nx x ny grid of cells of two triangles each;
    the interior vertices moved at random in the plane by up to `jitter` of a cell along x and y, so that no
    two edges are aligned. A scene tilts it with the loader's rotation (an incline)."""
    rng = random.Random(seed)
    pts = {}
    for i in range(nx + 1):
        for j in range(ny + 1):
            x, y = lx * i / nx, ly * j / ny
            if 0 < i < nx and 0 < j < ny:
                x += lx / nx * jitter * (2 * rng.random() - 1)
                y += ly / ny * jitter * (2 * rng.random() - 1)
            pts[i, j] = (x, y, 0.0)
    up = (0.0, 0.0, 1.0)
    tris = []
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = pts[i, j], pts[i + 1, j], pts[i, j + 1], pts[i + 1, j + 1]
            for t in ((a, b, d), (a, d, c)):
                n = cross(sub(t[1], t[0]), sub(t[2], t[0]))
                assert n[2] > 0.2 * (lx / nx) * (ly / ny), "jitter folded a triangle"
                tris.append(oriented(t, up))
    return tris


def cylinder(radius=0.02, height=0.06, around=64, rows=4):
    """The mantle of a cylinder on the z axis, z in [0, height], open at both ends, normals inward."""
    return band(radius, 0.0, radius, height, around, rows)


def hopper(top=0.02, orifice=0.004, height=0.016, around=64, rows=4):
    """A conical hopper: the frustum from the orifice (radius `orifice` at z = 0) to radius `top` at z = height,
    open at both ends, normals inward (towards the axis, where the grains are)."""
    return band(orifice, 0.0, top, height, around, rows)


def drum(radius=0.05, length=0.03, around=96, rows=3, rings=4):
    """A closed drum: the mantle of radius `radius` on the z axis, z in [0, length], and its two end caps; all
    normals inward."""
    return (band(radius, 0.0, radius, length, around, rows) + disc(radius, 0.0, around, rings, True) +
            disc(radius, length, around, rings, False))


def box(corners_of):
    """The 12 triangles of a box given by its 8 corners corners_of(i, j, k), i, j, k in {0, 1}, normals out."""
    c = {(i, j, k): corners_of(i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1)}
    mid = tuple(sum(p[m] for p in c.values()) / 8 for m in range(3))
    faces = []
    for axis in range(3):
        for side in (0, 1):
            quad = []
            for u, v in ((0, 0), (1, 0), (1, 1), (0, 1)):
                idx = [0, 0, 0]
                idx[axis] = side
                idx[(axis + 1) % 3], idx[(axis + 2) % 3] = u, v
                quad.append(c[tuple(idx)])
            faces.append(quad)
    tris = []
    for q in faces:
        for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
            tris.append(oriented(t, sub(centroid(t), mid)))
    return tris


def mixer(hub=0.004, hub_height=0.012, reach=0.018, width=0.008, thickness=0.0015, pitch_deg=30.0, around=24):
    """A two-blade mixer on the z axis: a closed hub cylinder (radius `hub`, z in [0, hub_height]) and two flat
    blades, boxes from the hub to radius `reach` along +x and -x, `width` high and `thickness` thick, each turned
    by `pitch_deg` about its own radial line (a pitched-blade impeller). Normals out of the solid: the grains are
    outside. The blades' inner ends sit inside the hub (a contact sees the surfaces, not a union of solids)."""
    tris = [(t[0], t[2], t[1]) for t in band(hub, 0.0, hub, hub_height, around, 1)]  # band() faces the axis
    tris += disc(hub, 0.0, around, 1, False) + disc(hub, hub_height, around, 1, True)
    zc = 0.5 * hub_height
    p = math.radians(pitch_deg)
    for sign in (1.0, -1.0):
        def corner(i, j, k, sign=sign):
            r = (0.8 * hub + (reach - 0.8 * hub) * i) * sign  # along x
            h = (j - 0.5) * width  # along the blade's width, before the pitch: z
            t = (k - 0.5) * thickness  # along its thickness, before the pitch: y
            # pitch: rotate (y, z) about the blade's radial line (x)
            return (r, t * math.cos(p) - h * math.sin(p), zc + t * math.sin(p) + h * math.cos(p))
        tris += box(corner)
    return tris


def ascii_stl(tris, name):
    out = ["solid " + name]
    for t in tris:
        out.append("  facet normal %r %r %r" % tuple(round(x, 10) + 0.0 for x in normal(t)))
        out.append("    outer loop")
        for p in t:
            out.append("      vertex %r %r %r" % p)
        out.append("    endloop")
        out.append("  endfacet")
    out.append("endsolid " + name)
    return ("\n".join(out) + "\n").encode("ascii")


def binary_stl(tris, header):
    h = header.encode("ascii")[:80]
    out = [h + b"\0" * (80 - len(h)), struct.pack("<I", len(tris))]
    for t in tris:
        out.append(struct.pack("<12fH", *normal(t), *t[0], *t[1], *t[2], 0))
    return b"".join(out)


# name, (shape, format); the text after the name is the solid name (ASCII) or the header (binary).
MESHES = {
    "incline.stl": (incline, "binary", "incline 0.1 x 0.05 m, 40 x 20 cells, jittered, normal +z"),
    "cylinder.stl": (cylinder, "ascii", "cylinder mantle R 0.02 H 0.06 m, 64 around, open, inward"),
    "hopper.stl": (hopper, "ascii", "conical hopper R 0.02 orifice 0.004 H 0.016 m, open, inward"),
    "drum.stl": (drum, "binary", "drum R 0.05 L 0.03 m, 96 around, capped, inward"),
    "mixer.stl": (mixer, "ascii", "two-blade mixer reach 0.018 m, hub 0.004 m, pitch 30 deg, outward"),
}


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(here, "..", "examples", "meshes"), help="output folder")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for name, (shape, fmt, text) in MESHES.items():
        tris = shape()
        data = binary_stl(tris, text) if fmt == "binary" else ascii_stl(tris, text)
        assert len(data) < 1 << 20, name + " is over 1 MB"
        with open(os.path.join(args.out, name), "wb") as f:
            f.write(data)
        print("%s: %d triangles, %s, %d bytes" % (name, len(tris), fmt, len(data)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
