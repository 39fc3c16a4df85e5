#!/usr/bin/env python3
"""Paints a mesh's faces by the direction they face and writes a PLY with vertex colours.

The stress sets of issue 20 need objects whose near-symmetric poses differ in colour only (a
juice carton is almost a square prism; which face is in front shows in its print). This gives
every face one of six colours by the object-frame axis its normal is closest to, so that a turn
about any axis changes the colours the camera sees:

    scripts/paint_mesh.py ../shared/data/meshes/juicecarton.stl juicecarton_painted.ply

Reads binary or ASCII STL; writes binary little-endian PLY in the same units (vertices are
repeated per face, so each face keeps its flat colour). Standard library only.
"""
import struct
import sys

# +x, -x, +y, -y, +z, -z (RGB 0..255): well apart in hue and brightness.
COLOURS = [(200, 40, 40), (40, 170, 60), (50, 80, 210), (230, 200, 40), (235, 235, 235), (120, 60, 150)]


def read_stl(path):
    data = open(path, "rb").read()
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * count == len(data):
            tris = []
            for i in range(count):
                v = struct.unpack_from("<12f", data, 84 + 50 * i)
                tris.append((v[3:6], v[6:9], v[9:12]))
            return tris
    tris, verts = [], []
    for line in data.decode("ascii", errors="replace").splitlines():
        words = line.split()
        if words[:1] == ["vertex"]:
            verts.append(tuple(float(w) for w in words[1:4]))
            if len(verts) == 3:
                tris.append(tuple(verts))
                verts = []
    if not tris:
        sys.exit(f"{path}: no triangles (not an STL file?)")
    return tris


def colour_of(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    axis = max(range(3), key=lambda i: abs(n[i]))
    return COLOURS[2 * axis + (0 if n[axis] >= 0 else 1)]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, dst = sys.argv[1], sys.argv[2]
    tris = read_stl(src)
    with open(dst, "xb") as out:  # never overwrites
        out.write(("ply\nformat binary_little_endian 1.0\n"
                   f"comment painted by scripts/paint_mesh.py from {src.split('/')[-1]}\n"
                   f"element vertex {3 * len(tris)}\nproperty float x\nproperty float y\nproperty float z\n"
                   "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                   f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
        for a, b, c in tris:
            rgb = colour_of(a, b, c)
            for v in (a, b, c):
                out.write(struct.pack("<3f3B", *v, *rgb))
        for i in range(len(tris)):
            out.write(struct.pack("<B3i", 3, 3 * i, 3 * i + 1, 3 * i + 2))
    print(f"{dst}: {len(tris)} faces painted by the axis they face")


if __name__ == "__main__":
    main()
