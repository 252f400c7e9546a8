#!/usr/bin/env python3
"""Mitsuba 3 on the Cornell scene: time against error, in the CSV columns of `twinpath bench`.

Builds the scene of tests/reference/cornell_spheres/scene.md with mi.load_dict (the same
numbers as scenes/cornell.toml), renders it at 1, 2, 4, ... spp with the `path` integrator
(max_depth -1, rr_depth 5, independent sampler), several seeds per point at low spp, and
measures render seconds (mi.render plus the evaluation of the image) and relMSE / RMSE against
the reference EXR with the definitions of `twinpath diff`:
relMSE = mean over pixels and channels of (a - b)^2 / (b^2 + 0.01).

Usage: peer_mitsuba.py REFERENCE.exr OUT.csv [--variant llvm_ad_rgb] [--max-spp 1024]
       [--max-seconds 60] [--sampler independent] [--scene cornell|materials] [--mesh KNOT.ply]
       [--once SPP]
--sampler picks Mitsuba's sampler (the reference's is `independent`; `ldsampler` is its
low-discrepancy one, `multijitter` / `stratified` its stratified ones); names other than
independent are added to the variant column. --mesh replaces the two spheres by a PLY mesh in
white, flat-shaded (scripts/knot_scenes.py's scenes); its file name is added to the variant.
--scene materials builds scenes/cornell_materials.toml (cornell_materials_dict) instead.
--once SPP renders once (seed 1, no warm-up), writes the image to OUT and prints its relMSE and
its number of samples: scripts/peer_table.sh times whole processes with it, and
scripts/traversal_floor.sh counts its rays.
Install: pip install mitsuba numpy (scripts/peer_mitsuba.sh does it in a venv).
"""

import argparse
import time

import mitsuba as mi
import numpy as np

from mitsuba_scenes import cornell_materials_dict, scene_dict
from peer_rows import relmse, sweep, variant_name, write_csv


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("out")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--max-spp", type=int, default=1024)
    ap.add_argument("--max-seconds", type=float, default=60.0)
    ap.add_argument("--sampler", default="independent")
    ap.add_argument("--mesh", help="a PLY mesh in place of the spheres (scripts/knot_scenes.py)")
    ap.add_argument("--scene", default="cornell", choices=["cornell", "materials"],
                    help="materials: scenes/cornell_materials.toml (cornell_materials_dict)")
    ap.add_argument("--once", type=int, metavar="SPP",
                    help="render once at SPP (seed 1, no warm-up: what a user's process does), "
                         "write the image to OUT (EXR) and print its relMSE; for timing whole "
                         "processes")
    args = ap.parse_args()

    def make_dict(spp, seed):
        build = cornell_materials_dict if args.scene == "materials" else scene_dict
        d = build(spp, seed, args.sampler)
        if args.mesh:
            del d["sphere_left"], d["sphere_right"]
            d["mesh"] = {"type": "ply", "filename": args.mesh, "face_normals": True,
                         "bsdf": {"type": "ref", "id": "white"}}
        return d

    mi.set_variant(args.variant)
    ref = np.array(mi.Bitmap(args.reference).convert(
        mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32), dtype=np.float64)
    if args.once:
        scene = mi.load_dict(make_dict(args.once, 1))
        img = mi.render(scene, spp=args.once, seed=1)
        mi.Bitmap(img).write(args.out)
        print(f"relmse {relmse(np.array(img, dtype=np.float64), ref):.6e}")
        width, height = scene.sensors()[0].film().size()
        print(f"samples {width * height * scene.sensors()[0].sampler().sample_count()}")
        return
    def measure(spp, seed):
        t0 = time.perf_counter()
        scene = mi.load_dict(make_dict(spp, seed))
        setup = time.perf_counter() - t0
        # Warm-up render: the llvm variants compile a kernel for each new sample count (a
        # set-up cost, cached afterwards); it is timed as set-up, not render.
        if seed == 1:
            t0 = time.perf_counter()
            np.array(mi.render(scene, spp=spp, seed=1000))
            setup += time.perf_counter() - t0
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)
        return img, setup, time.perf_counter() - t0

    def sample_count(spp):
        # `ldsampler` rounds a count up to a power of 4 (2 -> 4, 8 -> 16, ...).
        return mi.load_dict(make_dict(spp, 1)).sensors()[0].sampler().sample_count()

    rows = sweep(measure, ref, args.max_spp, args.max_seconds,
                 f"mitsuba {args.variant} {args.sampler}", sample_count)
    base = args.variant if args.sampler == "independent" else f"{args.variant}-{args.sampler}"
    write_csv(args.out, variant_name(f"mitsuba-{base}", args.mesh, args.scene), rows)


if __name__ == "__main__":
    main()
