#!/usr/bin/env python3
"""A converged Mitsuba 3 reference of a scene of scripts/mitsuba_scenes.py, as the mean of two
independent halves (each rendered in chunks of samples with their own seeds), written as
OUT/mitsuba_ref.exr, OUT/mitsuba_ref_half_a.exr, OUT/mitsuba_ref_half_b.exr and
OUT/mitsuba_ref_meta.json: what tests/tests/mitsuba.rs compares twinpath with.

Usage: mitsuba_reference.py SCENE OUTDIR [--spp 8192] [--chunk 512] [--variant llvm_ad_rgb]
SCENE: cornell_materials (scenes/cornell_materials.toml), cornell_fog (scenes/cornell_fog.toml,
Mitsuba's volpathmis), cornell_smoke (scenes/cornell_smoke.toml, a density grid, volpathmis).
"""

import argparse
import json
import os
import time

import mitsuba as mi
import numpy as np

import mitsuba_scenes


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene", choices=["cornell_materials", "cornell_fog", "cornell_smoke"])
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--chunk", type=int, default=512)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()
    mi.set_variant(args.variant)
    build = {"cornell_materials": mitsuba_scenes.cornell_materials_dict,
             "cornell_fog": mitsuba_scenes.cornell_fog_dict,
             "cornell_smoke": mitsuba_scenes.cornell_smoke_dict}[args.scene]
    os.makedirs(args.out, exist_ok=True)
    chunks = max(2, args.spp // args.chunk)
    chunks += chunks % 2
    scene_dict = build(args.chunk, 1)
    scene = mi.load_dict(scene_dict)
    halves = [None, None]
    t0 = time.perf_counter()
    for c in range(chunks):
        img = np.array(mi.render(scene, spp=args.chunk, seed=7919 * (c + 1)), dtype=np.float64)
        h = c % 2
        halves[h] = img if halves[h] is None else halves[h] + img
        print(f"chunk {c + 1} / {chunks}: {time.perf_counter() - t0:.1f} s", flush=True)
    wall = time.perf_counter() - t0
    halves = [h / (chunks // 2) for h in halves]
    ref = (halves[0] + halves[1]) / 2
    for name, img in [("mitsuba_ref", ref), ("mitsuba_ref_half_a", halves[0]),
                      ("mitsuba_ref_half_b", halves[1])]:
        mi.Bitmap(img.astype(np.float32)).write(os.path.join(args.out, name + ".exr"))
    meta = {"scene": args.scene, "variant": args.variant, "spp": chunks * args.chunk,
            "chunk_spp": args.chunk, "chunks": chunks, "render_wall_s": round(wall, 3),
            "integrator": scene_dict["integrator"]["type"] + ", max_depth -1, rr_depth 5",
            "sampler": "independent",
            "mean_rgb": ref.reshape(-1, 3).mean(axis=0).tolist()}
    with open(os.path.join(args.out, "mitsuba_ref_meta.json"), "w") as f:
        json.dump(meta, f, indent=1)


if __name__ == "__main__":
    main()
