#!/usr/bin/env python3
"""Writes the meshes under scenes/meshes/ (run once; the outputs are committed):
an icosphere (OBJ, subdivided icosahedron) and a torus (binary little-endian PLY)."""
import math, struct, os

out = os.path.join(os.path.dirname(__file__), "..", "scenes", "meshes")

def icosphere(level):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache, nf = {}, []
        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                p = [(x + y) / 2 for x, y in zip(v[a], v[b])]
                n = math.sqrt(sum(c * c for c in p))
                v.append(tuple(c / n for c in p))
                cache[key] = len(v) - 1
            return cache[key]
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return v, f

v, f = icosphere(3)
with open(os.path.join(out, "icosphere.obj"), "w") as fh:
    fh.write(f"# icosphere, level 3: {len(v)} vertices, {len(f)} triangles, unit radius\n")
    for p in v:
        fh.write("v %.6f %.6f %.6f\n" % p)
    for a, b, c in f:
        fh.write(f"f {a + 1} {b + 1} {c + 1}\n")

R, r, nu, nv = 1.0, 0.35, 48, 24
verts = []
for i in range(nu):
    for j in range(nv):
        u, w = 2 * math.pi * i / nu, 2 * math.pi * j / nv
        verts.append(((R + r * math.cos(w)) * math.cos(u), r * math.sin(w), (R + r * math.cos(w)) * math.sin(u)))
faces = []
for i in range(nu):
    for j in range(nv):
        a, b = i * nv + j, ((i + 1) % nu) * nv + j
        c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
        faces.append((a, b, c, d))
with open(os.path.join(out, "torus.ply"), "wb") as fh:
    fh.write((f"ply\nformat binary_little_endian 1.0\ncomment torus R={R} r={r}, quads\n"
              f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
    for p in verts:
        fh.write(struct.pack("<3f", *p))
    for q in faces:
        fh.write(struct.pack("<B4i", 4, *q))
