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
gain adaptive sampling could reach at most. The same per tile of 16 x 16 pixels; then as a
rule would learn it, each tile's choice made from the first 16 seeds' variances and judged by
the others', with and without per-tile spp (without, the split minimising e + lambda t per
tile). These are the independent sampler's variances; Sobol's points gain less from splitting
(docs/performance.md).
Usage: python split_oracle.py IMAGES K T1 T2 T REFERENCE.exr [TILE_MAP]
(TILE_MAP: where to write the learned whole splits at vertex 1 per tile, for split_sobol.py.)
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
    def least(values):
        """The elementwise minimum of arrays given one at a time (a list of them all would
        not fit in memory)."""
        out = None
        for v in values:
            out = v if out is None else np.minimum(out, v)
        return out

    per_pixel_1 = least(np.multiply(*product(n, n)) for n in grid)
    coarse = grid[::2]
    per_pixel_2 = least(np.multiply(*product(n1, m)) for n1 in coarse for m in coarse)
    g_alloc = e0 / allocation
    g1 = e0 / np.sqrt(per_pixel_1).mean() ** 2
    g2 = e0 / np.sqrt(per_pixel_2).mean() ** 2
    print(f"spp per pixel (adaptive sampling's ceiling): gain {g_alloc:.3f}")
    print(f"spp and split at vertex 1 per pixel: gain {g1:.3f} ({g1 / g_alloc:.3f} over the spp alone)")
    print(f"spp and splits at vertices 1 and 2 per pixel: gain {g2:.3f} "
          f"({g2 / g_alloc:.3f} over the spp alone)")
    # The same, chosen per tile of 16 x 16 pixels (what a rule learned at that resolution
    # could reach): each tile's mean e_p in place of a pixel's.
    def tiles(x):
        h, w = x.shape[:2]
        return x[:h - h % 16, :w - w % 16].reshape(h // 16, 16, w // 16, 16, -1).mean((1, 3))

    tile_alloc = np.sqrt(tiles(plain)).mean() ** 2
    tile_best = least(tiles(e) * c for n1 in coarse for m in coarse for e, c in [product(n1, m)])
    t_alloc, t2 = e0 / tile_alloc, e0 / np.sqrt(tile_best).mean() ** 2
    print(f"per tile of 16 x 16 pixels: spp {t_alloc:.3f}, spp and splits at vertices 1 and 2 "
          f"{t2:.3f} ({t2 / t_alloc:.3f} over the spp alone)")

    # Learned: each tile's spp and splits chosen from the variances of the first `pilots`
    # seeds only, and judged by those of the others (held out, so the choice cannot fit
    # their noise).
    pilots = 16

    def parts(lo, hi):
        t_, c1_, c2_ = (covariance(x[lo:hi], y[lo:hi]) for x, y in ((a, a), (a, b1), (a, b2)))
        return [tiles(weight * np.maximum(box5(v), 0.0)) for v in (c1_, c2_ - c1_, t_ - c2_)]

    learn, judge = parts(0, pilots), parts(pilots, k)

    def chosen(n1, m):
        return np.argmin(np.stack([(learn[0] + learn[1] / x + learn[2] / y) * (
            cost[0] + cost[1] * x + cost[2] * y) for x in n1 for y in m]), axis=0)


    pairs = [(x, y) for x in coarse for y in coarse]
    best = chosen(coarse, coarse)
    n1 = np.array([x for x, _ in pairs])[best]
    m = np.array([y for _, y in pairs])[best]
    e_learn = learn[0] + learn[1] / n1 + learn[2] / m
    c_learn = cost[0] + cost[1] * n1 + cost[2] * m
    e_judge = judge[0] + judge[1] / n1 + judge[2] / m
    plain_learn, plain_judge = sum(learn), sum(judge)
    e0_judge = plain_judge.mean()
    # spp per tile proportional to sqrt(e / t), from the pilots' numbers, and at least an
    # eighth of the mean (a tile whose pilots saw no variance must still be sampled).
    def floored(x):
        return np.maximum(x, x.mean() / 8.0)

    spp_plain = floored(np.sqrt(plain_learn))
    spp_split = floored(np.sqrt(e_learn / c_learn))
    g_spp = e0_judge / ((plain_judge / spp_plain).mean() * spp_plain.mean())
    g_split = e0_judge / ((e_judge / spp_split).mean() * (spp_split * c_learn).mean())
    print(f"learned per tile from {pilots} samples, judged on the other {k - pilots}: "
          f"spp {g_spp:.3f}, spp and splits {g_split:.3f} ({g_split / g_spp:.3f} over the spp alone)")
    # Splits alone, every pixel the same spp (so the pilots' samples may stay in the image
    # unbiased: no sample count depends on them): per tile the split minimising e + lambda t,
    # lambda the best for the image, all from the pilots, judged on the rest.
    learned_e = np.stack([learn[0] + learn[1] / x + learn[2] / y for x, y in pairs])
    learned_c = np.stack([np.full(learn[0].shape, cost[0] + cost[1] * x + cost[2] * y)
                          for x, y in pairs])
    judged_e = np.stack([judge[0] + judge[1] / x + judge[2] / y for x, y in pairs])
    best_splits = None
    for lam in np.exp(np.linspace(-8.0, 8.0, 321)) * plain_learn.mean():
        pick = np.argmin(learned_e + lam * learned_c, axis=0)[None]
        e = np.take_along_axis(learned_e, pick, 0).mean()
        c = np.take_along_axis(learned_c, pick, 0).mean()
        if best_splits is None or e * c < best_splits[0]:
            best_splits = (e * c, pick)
    pick = best_splits[1]
    g_splits = e0_judge / (np.take_along_axis(judged_e, pick, 0).mean()
                           * np.take_along_axis(learned_c, pick, 0).mean())
    print(f"learned splits alone per tile, the same spp everywhere: gain {g_splits:.3f}")

    # The tile map scripts/split_sobol.py renders with Sobol's numbers: whole splits at vertex 1
    # only (n1 = 1 to 4, n2 = 1), learned from the pilots as above.
    counts = np.array([1.0, 2.0, 3.0, 4.0])
    learned_e = np.stack([learn[0] + (learn[1] + learn[2]) / n for n in counts])
    judged_e = np.stack([judge[0] + (judge[1] + judge[2]) / n for n in counts])
    unit_cost = cost[0] + (cost[1] + cost[2]) * counts
    best_map = None
    for lam in np.exp(np.linspace(-8.0, 8.0, 641)) * plain_learn.mean():
        pick = np.argmin((learned_e + lam * unit_cost[:, None, None, None]).sum(-1), axis=0)
        e = np.take_along_axis(learned_e.sum(-1), pick[None], 0).mean()
        c = unit_cost[pick].mean()
        if best_map is None or e * c < best_map[0]:
            best_map = (e * c, pick)
    pick = best_map[1]
    g_map = judged_e.sum(-1).mean(axis=(1, 2))[0] / (
        np.take_along_axis(judged_e.sum(-1), pick[None], 0).mean() * unit_cost[pick].mean())
    print(f"whole splits at vertex 1 per tile (1 to 4), learned: gain {g_map:.3f}, "
          f"mean cost {unit_cost[pick].mean():.3f}, tiles with 1, 2, 3, 4: "
          f"{[int((pick == i).sum()) for i in range(4)]}")
    if len(sys.argv) > 7:
        with open(sys.argv[7], "w") as f:
            f.write(" ".join(str(int(counts[i])) for i in pick.ravel()) + "\n")


if __name__ == "__main__":
    main()
