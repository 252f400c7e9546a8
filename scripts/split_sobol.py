"""Splits at vertex 1 with Sobol's numbers, at equal time (from scripts/split_oracle.sh).

For each seed, renders j = 0..3 at N spp whose paths continue after vertex 1 with the numbers of
sample index s n + j (n the pixel's tile's count from the tile map; scripts/split_oracle.patch),
so the mean of renders 0 to n - 1 is the render that splits each path into n continuations
there, and unsplit renders at N, 2N and 4N spp. A split sample costs C1 + n (1 - C1) of an
unsplit one (C1 the share of a sample up to vertex 1's light sample, measured by the script), so
the split render at N spp costs what an unsplit one does at N' = N mean(C1 + n (1 - C1)); the
unsplit relMSE at N' is interpolated in log-log between the unsplit renders, and the gain at
equal time is its ratio to the split render's relMSE (both against the reference, weights
1 / (reference^2 + 0.01) as `twinpath diff`).
Usage: python split_sobol.py IMAGES TILE_MAP REFERENCE.exr C1 N SEEDS (comma-separated)
"""

import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def main():
    images, tile_map, reference = sys.argv[1], sys.argv[2], load(sys.argv[3])
    c1, spp = float(sys.argv[4]), int(sys.argv[5])
    seeds = [int(s) for s in sys.argv[6].split(",")]
    h, w = reference.shape[:2]
    counts = np.array([int(v) for v in open(tile_map).read().split()])
    counts = counts.reshape((h + 15) // 16, (w + 15) // 16)
    per_pixel = np.repeat(np.repeat(counts, 16, 0), 16, 1)[:h, :w, None]
    cost = (c1 + (1.0 - c1) * counts).mean()

    def relmse(image):
        return ((image - reference) ** 2 / (reference ** 2 + 0.01)).mean()

    split, unsplit = [], {n: [] for n in (spp, 2 * spp, 4 * spp)}
    for seed in seeds:
        parts = [load(f"{images}/s{seed}_j{j}.exr") for j in range(4)]
        image = sum(np.where(per_pixel > j, parts[j], 0.0) for j in range(4)) / per_pixel
        split.append(relmse(image))
        for n in unsplit:
            unsplit[n].append(relmse(load(f"{images}/s{seed}_u{n}.exr")))
        # Continuation 0 of a tile that does not split is the unsplit render's path.
        alone = per_pixel[..., 0] == 1
        if alone.any():
            assert np.array_equal(parts[0][alone], load(f"{images}/s{seed}_u{spp}.exr")[alone])
    mean = {n: float(np.mean(v)) for n, v in unsplit.items()}
    for n, v in unsplit.items():
        print(f"unsplit {n} spp: relMSE " + ", ".join(f"{x:.4e}" for x in v))
    print(f"split {spp} spp: relMSE " + ", ".join(f"{x:.4e}" for x in split)
          + f" (a sample costs {cost:.3f} unsplit ones)")
    equal = spp * cost
    lo = spp if equal <= 2 * spp else 2 * spp
    slope = np.log(mean[2 * lo] / mean[lo]) / np.log(2.0)
    at_equal_time = mean[lo] * (equal / lo) ** slope
    print(f"unsplit at the split's cost ({equal:.1f} spp, log-log slope {slope:.3f}): "
          f"relMSE {at_equal_time:.4e}; gain at equal time {at_equal_time / np.mean(split):.3f}")


if __name__ == "__main__":
    main()
