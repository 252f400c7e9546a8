# Usage: python3 scripts/torus_scenes.py OUTDIR N [N ...]
# For docs/gpu.md (lavapipe and GPU cost against triangle count). Writes the Cornell room of scenes/meshes.toml with one generated rippled torus of about N
# triangles in place of its two meshes, for N given on the command line: OUTDIR/mesh_N.toml.
import math, sys, pathlib, re
root = pathlib.Path(__file__).resolve().parent.parent
out = pathlib.Path(sys.argv[1]); out.mkdir(parents=True, exist_ok=True)
base = (root / "scenes/meshes.toml").read_text()
head = base[: base.index("[[mesh]]")]
light = base[base.index("[[sphere]]"):]
for n in map(int, sys.argv[2:]):
    nv = max(3, int(round(math.sqrt(n / 2 / 4))))
    nu = max(3, n // (2 * nv))
    R, r = 0.45, 0.15
    lines = []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            rr = r * (1 + 0.08 * math.sin(17 * a) * math.cos(5 * b))
            x = (R + rr * math.cos(b)) * math.cos(a)
            z = (R + rr * math.cos(b)) * math.sin(a)
            y = rr * math.sin(b)
            lines.append(f"v {x:.7f} {y:.7f} {z:.7f}")
    for i in range(nu):
        for j in range(nv):
            p = i * nv + j + 1
            q = ((i + 1) % nu) * nv + j + 1
            p2 = i * nv + (j + 1) % nv + 1
            q2 = ((i + 1) % nu) * nv + (j + 1) % nv + 1
            lines.append(f"f {p} {p2} {q2}")
            lines.append(f"f {p} {q2} {q}")
    (out / f"torus_{n}.obj").write_text("\n".join(lines) + "\n")
    mesh = f'[[mesh]] # generated torus, {2*nu*nv} triangles\nfile = "torus_{n}.obj"\nmaterial = "blue"\nscale = 1.0\ntranslate = [0.0, 0.6, 0.0]\n\n'
    (out / f"mesh_{n}.toml").write_text(head + mesh + light)
    print(n, 2 * nu * nv)
