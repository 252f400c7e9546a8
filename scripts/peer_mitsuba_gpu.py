#!/usr/bin/env python3
"""Mitsuba 3 on an NVIDIA GPU (`cuda_ad_rgb`), the peer of twinpath's GPU backend: the scenes of
scripts/mitsuba_scenes.py rendered once more after a warm-up, timed, and written as EXR, so that
their error is measured afterwards against the converged references of tests/reference/
(scripts/gpu_peer_table.py). Needs only the mitsuba and drjit wheels, no numpy: a lent GPU
machine reaches no package registry (scripts/gpu_machine_prepare.sh carries the wheels' files).

Usage: peer_mitsuba_gpu.py OUTDIR [--spp 1024] [--variant cuda_ad_rgb]
       [--scenes cornell,cornell_materials,...] [--samplers independent,ldsampler]
(the scenes by default: scripts/gpu_peer_scenes.txt's)
Prints one line per timed render: `mitsuba SCENE SAMPLER spp N seconds S warmup W`, where S is
the render of N samples per pixel with the scene's kernels already compiled (mi.render, then the
image evaluated and the device synchronised) and W the first render's time (as many samples, another
seed, compiling them). Writes OUTDIR/mitsuba_SCENE_SAMPLER.exr.
"""

import argparse
import os
import time

import drjit as dr
import mitsuba as mi

from gpu_peer_scenes import scenes

SCENES = scenes()


def timed_render(scene, spp, seed):
    """Seconds of one render of `spp` samples per pixel, to the image evaluated on the device."""
    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    return img, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--variant", default="cuda_ad_rgb")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--samplers", default="independent,ldsampler")
    args = ap.parse_args()
    mi.set_variant(args.variant)
    import mitsuba_scenes
    build = {name: getattr(mitsuba_scenes, builder) for name, (_, builder) in SCENES.items()}
    os.makedirs(args.out, exist_ok=True)
    for name in args.scenes.split(","):
        for sampler in args.samplers.split(","):
            scene = mi.load_dict(build[name](args.spp, 1, sampler))
            # Kernels are compiled per sample count: the warm-up renders as many, with another seed.
            _, warmup = timed_render(scene, args.spp, 1000)
            img, seconds = timed_render(scene, args.spp, 1)
            mi.Bitmap(img).write(os.path.join(args.out, f"mitsuba_{name}_{sampler}.exr"))
            print(f"mitsuba {name} {sampler} spp {args.spp} seconds {seconds:.4f} "
                  f"warmup {warmup:.3f}", flush=True)


if __name__ == "__main__":
    main()
