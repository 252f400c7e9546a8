"""The most that splitting and Russian roulette at path vertices 1 and 2 could gain, with each
pixel's variances known (from scripts/split_oracle.sh, which says how the images are made).

Images a_s (seed s), b1_s (a_s's paths up to vertex 1, continued independently from its BRDF
sample on) and b2_s (likewise from vertex 2's). With L a pixel's one-sample estimate and X_v
what a path has drawn up to vertex v's continuation, two continuations of one prefix are
independent given it, so Cov(a, b_v) = Var(E[L | X_v]) (the law of total variance). Hence
V_a = Cov(a, b1) (the camera sample, vertex 1 and its light sample), V_b = Cov(a, b2) - V_a
(vertex 1's continuation up to vertex 2's light sample) and V_c = Var(a) - Cov(a, b2) (the
rest). Taking n1 continuations from vertex 1 and n2 from each vertex 2 (n < 1: roulette),
a sample's variance is V_a + V_b / n1 + V_c / (n1 n2) at cost C1 + n1 C2 + n1 n2 C3, with C1,
C1 + C2 and C1 + C2 + C3 the render times cut after vertex 1, after vertex 2 and whole. The
efficiency gain of a choice is E0 T0 / (E T), E the relMSE-weighted variance (weights
1 / (reference^2 + 0.01), as `twinpath diff`), T the time; variances are smoothed over 5 x 5
pixels. Per pixel, the best split minimises e_p t_p (a grid search) and the best spp per pixel
is proportional to sqrt(e_p / t_p), giving E T = (mean sqrt(e_p t_p))^2 (Cauchy-Schwarz): the
gain adaptive sampling could reach at most. These are the independent sampler's variances;
Sobol's points gain less from splitting (docs/performance.md).
Usage: python split_oracle.py IMAGES K T1 T2 T REFERENCE.exr
"""

import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def box5(x):
    """Mean over each pixel's 5x5 neighbourhood (edges clamped), per channel."""
    p = np.pad(x, ((2, 2), (2, 2), (0, 0)), mode="edge")
    h, w = x.shape[:2]
    return sum(p[i:i + h, j:j + w] for i in range(5) for j in range(5)) / 25.0


def covariance(x, y):
    return ((x - x.mean(0)) * (y - y.mean(0))).sum(0) / (len(x) - 1)


def main():
    images, k = sys.argv[1], int(sys.argv[2])
    t1, t2, t = (float(v) for v in sys.argv[3:6])
    reference = load(sys.argv[6])
    a, b1, b2 = (np.stack([load(f"{images}/{n}_{s}.exr") for s in range(1, k + 1)])
                 for n in ("a", "b1", "b2"))
    weight = 1.0 / (reference * reference + 0.01)
    total, c1, c2 = covariance(a, a), covariance(a, b1), covariance(a, b2)
    va = np.maximum(box5(c1), 0.0)
    vb = np.maximum(box5(c2 - c1), 0.0)
    vc = np.maximum(box5(total - c2), 0.0)
    cost = np.array([t1, t2 - t1, t - t2]) / t
    e0 = (weight * (va + vb + vc)).mean()
    print(f"variance shares: up to vertex 1's light sample {(weight * va).mean() / e0:.3f}, "
          f"vertex 1's continuation to vertex 2's light sample {(weight * vb).mean() / e0:.3f}, "
          f"the rest {(weight * vc).mean() / e0:.3f}")
    print(f"cost shares: {cost[0]:.3f}, {cost[1]:.3f}, {cost[2]:.3f}")

    def product(n1, m):
        """E T for n1 continuations from vertex 1 and m = n1 n2 from vertex 2 per pixel."""
        e = weight * (va + vb / n1 + vc / m)
        return e, cost[0] + cost[1] * n1 + cost[2] * m

    grid = np.exp(np.linspace(-4.0, 4.0, 161))
    best1 = min((np.mean(e) * np.mean(c), n) for n in grid for e, c in [product(n, n)])
    best2 = min((np.mean(e) * np.mean(c), n1, m)
                for n1 in grid for m in grid for e, c in [product(n1, m)])
    print(f"one split for the image, at vertex 1: gain {e0 / best1[0]:.3f} (n1 = {best1[1]:.2f})")
    print(f"one split for the image, at vertices 1 and 2: gain {e0 / best2[0]:.3f} "
          f"(n1 = {best2[1]:.2f}, n1 n2 = {best2[2]:.2f})")
    plain = weight * (va + vb + vc)
    allocation = np.sqrt(plain).mean() ** 2
    per_pixel_1 = np.minimum.reduce([np.multiply(*product(n, n)) for n in grid])
    coarse = grid[::2]
    per_pixel_2 = np.minimum.reduce(
        [np.multiply(*product(n1, m)) for n1 in coarse for m in coarse])
    g_alloc = e0 / allocation
    g1 = e0 / np.sqrt(per_pixel_1).mean() ** 2
    g2 = e0 / np.sqrt(per_pixel_2).mean() ** 2
    print(f"spp per pixel (adaptive sampling's ceiling): gain {g_alloc:.3f}")
    print(f"spp and split at vertex 1 per pixel: gain {g1:.3f} ({g1 / g_alloc:.3f} over the spp alone)")
    print(f"spp and splits at vertices 1 and 2 per pixel: gain {g2:.3f} "
          f"({g2 / g_alloc:.3f} over the spp alone)")


if __name__ == "__main__":
    main()
