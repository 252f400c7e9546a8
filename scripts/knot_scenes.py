#!/usr/bin/env python3
"""The Cornell room with a generated torus knot in place of its two spheres, at N triangles.

Usage: scripts/knot_scenes.py OUTDIR N [N ...]

For issue 21's mesh scenes (twinpath against Mitsuba 3 on 10k to 1M triangles): writes
OUTDIR/knot_N.ply (binary little-endian PLY, float32 positions, no normals: flat shading on
both renderers) and OUTDIR/knot_N.toml (scenes/cornell.toml's walls, materials and sphere
light, the knot in white). The knot is the (2, 3) torus knot, a tube of radius 0.12 around
the curve ((2 + cos 3t) cos 2t, (2 + cos 3t) sin 2t, sin 3t) scaled by 0.22 and centred at
(0, 0.75, 0), so it sits on nothing and casts shadows on the floor and walls.
scripts/peer_mitsuba.py --mesh OUTDIR/knot_N.ply builds the same scene in Mitsuba 3.
Plain Python, no packages.
"""

import math
import pathlib
import struct
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CENTRE = (0.0, 0.75, 0.0)
SCALE = 0.22
TUBE = 0.12 / SCALE  # tube radius in the curve's units


def curve(t):
    """Point and derivative of the (2, 3) torus knot at t in [0, 2 pi)."""
    r = 2 + math.cos(3 * t)
    p = (r * math.cos(2 * t), r * math.sin(2 * t), math.sin(3 * t))
    dr = -3 * math.sin(3 * t)
    d = (dr * math.cos(2 * t) - 2 * r * math.sin(2 * t),
         dr * math.sin(2 * t) + 2 * r * math.cos(2 * t),
         3 * math.cos(3 * t))
    return p, d


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def knot(triangles):
    """Vertices and faces of a knot tube of about `triangles` triangles (2 per quad)."""
    around = max(6, int(round(math.sqrt(triangles / 2 / 12))))
    along = max(12, triangles // (2 * around))
    verts = []
    for i in range(along):
        t = 2 * math.pi * i / along
        p, d = curve(t)
        tangent = normalize(d)
        # A frame from the curve's radial direction (never parallel to this knot's tangent).
        radial = normalize((p[0], p[1], 0.0))
        n = normalize(cross(tangent, radial))
        b = cross(tangent, n)
        for j in range(around):
            a = 2 * math.pi * j / around
            c, s = math.cos(a), math.sin(a)
            q = [p[k] + TUBE * (c * n[k] + s * b[k]) for k in range(3)]
            # The curve's z is up (y in the scene): (x, y, z) -> (x, z, y).
            verts.append((CENTRE[0] + SCALE * q[0], CENTRE[1] + SCALE * q[2],
                          CENTRE[2] + SCALE * q[1]))
    faces = []
    for i in range(along):
        for j in range(around):
            p0 = i * around + j
            p1 = ((i + 1) % along) * around + j
            p2 = ((i + 1) % along) * around + (j + 1) % around
            p3 = i * around + (j + 1) % around
            faces.append((p0, p1, p2))
            faces.append((p0, p2, p3))
    return verts, faces


def write_ply(path, verts, faces):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(b"".join(struct.pack("<3f", *v) for v in verts))
        f.write(b"".join(struct.pack("<B3i", 3, *t) for t in faces))


def scene_toml(ply_name):
    base = (ROOT / "scenes/cornell.toml").read_text()
    head = base[: base.index("[[sphere]] # sphere_left")]
    light = base[base.index("[[sphere]] # the light"):]
    return (head + f'[[mesh]] # the torus knot (scripts/knot_scenes.py)\nfile = "{ply_name}"\n'
            'material = "white"\n\n' + light)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for n in map(int, sys.argv[2:]):
        verts, faces = knot(n)
        write_ply(out / f"knot_{n}.ply", verts, faces)
        (out / f"knot_{n}.toml").write_text(scene_toml(f"knot_{n}.ply"))
        print(f"{out}/knot_{n}.toml: {len(faces)} triangles", file=sys.stderr)


if __name__ == "__main__":
    main()
