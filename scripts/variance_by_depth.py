"""Where the Cornell image's error comes from: the variance part of relMSE of renders truncated
after 1, 2, 3, 4 path vertices and untruncated, for both samplers.

A render's relMSE against an exact image is bias^2 + variance; two renders with different seeds
differ by noise only, so half their mean squared difference, divided like relMSE by
(reference^2 + 0.01), estimates the variance part without needing a reference per depth.
Usage (from scripts/variance_by_depth.sh): python variance_by_depth.py TWINPATH REF.exr SPP
"""

import os
import subprocess
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def box5(x):
    """Mean over each pixel's 5x5 neighbourhood (edges clamped)."""
    p = np.pad(x, 2, mode="edge")
    h, w = x.shape
    return sum(p[i:i + h, j:j + w] for i in range(5) for j in range(5)) / 25.0


def allocation_bound(per_pixel):
    """Efficiency gain of spending samples in proportion to each pixel's noise (sigma) rather
    than evenly: mean(sigma^2) / mean(sigma)^2, from the 5x5-smoothed variance (the raw
    two-render estimate is too noisy: its own spread would inflate the bound)."""
    v = np.maximum(box5(per_pixel), 0.0)
    return v.mean() / np.sqrt(v).mean() ** 2


def main():
    twinpath, ref_path, spp = sys.argv[1], sys.argv[2], sys.argv[3]
    ref = load(ref_path)
    scene = open("scenes/cornell.toml").read()
    with tempfile.TemporaryDirectory() as tmp:
        print("sampler,max_depth,spp,variance_relmse,seconds_per_render")
        for sampler in ["independent", "sobol"]:
            for depth in ["1", "2", "3", "4", "unlimited"]:
                text = scene
                if depth != "unlimited":
                    assert "[render]\n" in text, "scenes/cornell.toml has no [render] table"
                    text = text.replace("[render]\n", f"[render]\nmax_depth = {depth}\n", 1)
                path = os.path.join(tmp, f"d{depth}.toml")
                open(path, "w").write(text)
                images, seconds = [], 0.0
                for seed in ["1", "2"]:
                    out = os.path.join(tmp, f"{sampler}_{depth}_{seed}.exr")
                    log = subprocess.run(
                        [twinpath, "render", path, "--backend", "cpu", "--spp", spp,
                         "--roulette", "throughput", "--sampler", sampler, "--seed", seed,
                         "-o", out],
                        check=True, capture_output=True, text=True).stderr
                    seconds += float(log.split("render ")[1].split(" s")[0])
                    images.append(load(out))
                d = (images[0] - images[1]) ** 2 / 2 / (ref ** 2 + 0.01)
                print(f"{sampler},{depth},{spp},{d.mean():.5f},{seconds / 2:.2f}")
                if depth == "unlimited":
                    bound = allocation_bound(d.mean(axis=2))
                    print(f"# {sampler}: best per-pixel sample allocation would gain {bound:.2f}x")


main()
