#!/usr/bin/env python3
"""Writes the meshes under scenes/meshes/ (run once; the outputs are committed):
an icosphere (OBJ, subdivided icosahedron), a torus (binary little-endian PLY), and the same
torus and a UV sphere with vertex normals and texture coordinates (PLY nx ny nz u v; OBJ vn vt)
for smooth shading and textures."""
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

# The torus again, with its exact normals and (u, v) = (around the ring, around the tube).
with open(os.path.join(out, "torus_smooth.ply"), "wb") as fh:
    fh.write((f"ply\nformat binary_little_endian 1.0\ncomment torus R={R} r={r}, quads, normals, uv\n"
              f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
    for i in range(nu):
        for j in range(nv):
            u, w = 2 * math.pi * i / nu, 2 * math.pi * j / nv
            p = verts[i * nv + j]
            n = (math.cos(w) * math.cos(u), math.sin(w), math.cos(w) * math.sin(u))
            fh.write(struct.pack("<8f", *p, *n, i / nu, j / nv))
    for q in faces:
        fh.write(struct.pack("<B4i", 4, *q))

# A unit UV sphere: 64 segments around, 32 from pole to pole; normals = positions, u around
# the axis (+y), v from the south pole (0) to the north pole (1).
seg, rings = 64, 32
with open(os.path.join(out, "uv_sphere.obj"), "w") as fh:
    fh.write(f"# UV sphere, {seg} x {rings}, unit radius, normals and texture coordinates\n")
    for k in range(rings + 1):
        theta = math.pi * k / rings
        for i in range(seg + 1):
            phi = 2 * math.pi * i / seg
            p = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            fh.write("v %.7f %.7f %.7f\n" % p)
            fh.write("vn %.7f %.7f %.7f\n" % p)
            fh.write("vt %.7f %.7f\n" % (i / seg, 1 - k / rings))
    idx = lambda k, i: k * (seg + 1) + i + 1
    for k in range(rings):
        for i in range(seg):
            a, b, c, d = idx(k, i), idx(k + 1, i), idx(k + 1, i + 1), idx(k, i + 1)
            if k > 0:
                fh.write(f"f {a}/{a}/{a} {b}/{b}/{b} {d}/{d}/{d}\n")
            if k < rings - 1:
                fh.write(f"f {b}/{b}/{b} {c}/{c}/{c} {d}/{d}/{d}\n")
