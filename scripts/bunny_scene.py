#!/usr/bin/env python3
"""The Cornell room with the Stanford bunny, Loop-subdivided, in place of its two spheres.

Usage: scripts/bunny_scene.py OUTDIR LEVELS

Issue 21's mesh of our choice, beside the generated knots of scripts/knot_scenes.py: a scanned
mesh, with the uneven triangle sizes and holes of a scan. The bunny is the npm package `bunny`
(1.0.1: the Stanford 3D Scanning Repository's bunny at 1,839 vertices and 3,674 triangles,
fetched with `npm pack` into OUTDIR unless OUTDIR/package/index.js is already there). Each
level of Loop subdivision (Loop 1987; Warren's weights, beta = 3 / (8 n) for valence n > 3 and
3 / 16 for n = 3; boundary edges and vertices by the boundary curve's rules) splits every
triangle in four and smooths the surface: 3 levels give 235,136 triangles. The bunny stands
on the floor, 1.0 high, its profile to the camera, white. Writes OUTDIR/bunny_T.ply and .toml
(T: the triangle count) as knot_scenes.py writes its scenes, and prints bunny_T;
scripts/peer_mitsuba.py --mesh takes the PLY. Plain Python and npm, no packages.
"""

import json
import pathlib
import re
import subprocess
import sys
from collections import defaultdict

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from knot_scenes import scene_toml, write_ply  # noqa: E402

HEIGHT = 1.0


def fetch(out):
    """The bunny's positions and faces from the npm package (downloaded once into `out`)."""
    index = out / "package" / "index.js"
    if not index.exists():
        subprocess.run(["npm", "pack", "--silent", "bunny@1.0.1"], cwd=out, check=True,
                       stdout=subprocess.DEVNULL)
        subprocess.run(["tar", "xzf", "bunny-1.0.1.tgz"], cwd=out, check=True)
    text = index.read_text()
    arrays = {name: json.loads(m) for name, m in
              re.findall(r"exports\.(\w+)\s*=\s*(\[.*?\]\])", text, re.S)}
    return [tuple(p) for p in arrays["positions"]], [tuple(c) for c in arrays["cells"]]


def loop_subdivide(verts, faces):
    """One level of Loop subdivision: four triangles per triangle, smoothed positions."""
    opposite = defaultdict(list)  # edge (a < b) -> the third vertex of each face on it
    neighbours = defaultdict(set)
    for a, b, c in faces:
        for u, v, w in ((a, b, c), (b, c, a), (c, a, b)):
            opposite[(min(u, v), max(u, v))].append(w)
            neighbours[u].update((v, w))
    boundary = defaultdict(list)  # vertex -> its neighbours along boundary edges
    for (u, v), third in opposite.items():
        if len(third) == 1:
            boundary[u].append(v)
            boundary[v].append(u)

    def mix(weights):
        return tuple(sum(w * verts[i][k] for i, w in weights) for k in range(3))

    new_verts = []
    for i, p in enumerate(verts):
        if i in boundary:
            a, b = boundary[i][0], boundary[i][-1]
            new_verts.append(mix([(i, 0.75), (a, 0.125), (b, 0.125)]))
        else:
            n = len(neighbours[i])
            beta = 3.0 / 16.0 if n == 3 else 3.0 / (8.0 * n)
            new_verts.append(mix([(i, 1.0 - n * beta)] + [(j, beta) for j in neighbours[i]]))
    edge_vertex = {}
    for (u, v), third in opposite.items():
        edge_vertex[(u, v)] = len(new_verts)
        if len(third) == 2:
            new_verts.append(mix([(u, 0.375), (v, 0.375), (third[0], 0.125), (third[1], 0.125)]))
        else:
            new_verts.append(mix([(u, 0.5), (v, 0.5)]))

    def mid(u, v):
        return edge_vertex[(min(u, v), max(u, v))]

    new_faces = []
    for a, b, c in faces:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        new_faces += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return new_verts, new_faces


def place(verts):
    """Scaled to HEIGHT, standing on the floor at the room's centre, its profile to the camera."""
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    s = HEIGHT / (hi[1] - lo[1])
    cx, cz = (lo[0] + hi[0]) / 2, (lo[2] + hi[2]) / 2
    # A quarter turn about y: the camera (on +z) sees the familiar profile, head to the left.
    return [(s * (v[2] - cz), s * (v[1] - lo[1]), -s * (v[0] - cx)) for v in verts]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    verts, faces = fetch(out)
    for _ in range(int(sys.argv[2])):
        verts, faces = loop_subdivide(verts, faces)
    name = f"bunny_{len(faces)}"
    write_ply(out / f"{name}.ply", place(verts), faces)
    (out / f"{name}.toml").write_text(
        scene_toml(f"{name}.ply").replace("the torus knot (scripts/knot_scenes.py)",
                                          "the Stanford bunny (scripts/bunny_scene.py)"))
    print(name)


if __name__ == "__main__":
    main()
