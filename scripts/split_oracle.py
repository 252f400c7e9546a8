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
    cost = np.array([t1, t2 - t1, t - t2]) / t

    def parts(lo, hi):
        """The weighted variance parts (V_a, V_b, V_c) of seeds lo..hi per pixel, the three
        channels summed: a split or a sample count applies to all of them at once."""
        total, c1, c2 = (covariance(x[lo:hi], y[lo:hi]) for x, y in ((a, a), (a, b1), (a, b2)))
        return [(weight * np.maximum(box5(v), 0.0)).sum(-1) for v in (c1, c2 - c1, total - c2)]

    def error(v, n1, m):
        """A sample's weighted variance with n1 continuations from vertex 1, m = n1 n2 from 2."""
        return v[0] + v[1] / n1 + v[2] / m

    def time(n1, m):
        return cost[0] + cost[1] * n1 + cost[2] * m

    v = parts(0, k)
    e0 = sum(v).mean()
    print(f"variance shares: up to vertex 1's light sample {v[0].mean() / e0:.3f}, "
          f"vertex 1's continuation to vertex 2's light sample {v[1].mean() / e0:.3f}, "
          f"the rest {v[2].mean() / e0:.3f}")
    print(f"cost shares: {cost[0]:.3f}, {cost[1]:.3f}, {cost[2]:.3f}")

    grid = np.exp(np.linspace(-4.0, 4.0, 161))
    coarse = grid[::2]
    pairs = [(n1, m) for n1 in coarse for m in coarse]
    best1 = min((error(v, n, n).mean() * time(n, n), n) for n in grid)
    best2 = min((error(v, n1, m).mean() * time(n1, m), n1, m) for n1 in grid for m in grid)
    print(f"one split for the image, at vertex 1: gain {e0 / best1[0]:.3f} (n1 = {best1[1]:.2f})")
    print(f"one split for the image, at vertices 1 and 2: gain {e0 / best2[0]:.3f} "
          f"(n1 = {best2[1]:.2f}, n1 n2 = {best2[2]:.2f})")

    def least(values):
        """The elementwise minimum of arrays given one at a time."""
        out = None
        for x in values:
            out = x if out is None else np.minimum(out, x)
        return out

    def allocated(e_t):
        """The gain of the best spp per pixel (or tile) given each one's E T: the least E T is
        (mean sqrt(e_p t_p))^2 (Cauchy-Schwarz)."""
        return e0 / np.sqrt(e_t).mean() ** 2

    g_alloc = allocated(sum(v))
    g1 = allocated(least(error(v, n, n) * time(n, n) for n in grid))
    g2 = allocated(least(error(v, n1, m) * time(n1, m) for n1, m in pairs))
    print(f"spp per pixel (adaptive sampling's ceiling): gain {g_alloc:.3f}")
    print(f"spp and split at vertex 1 per pixel: gain {g1:.3f} ({g1 / g_alloc:.3f} over the spp alone)")
    print(f"spp and splits at vertices 1 and 2 per pixel: gain {g2:.3f} "
          f"({g2 / g_alloc:.3f} over the spp alone)")

    # The same, chosen per tile of 16 x 16 pixels (what a rule learned at that resolution
    # could reach): each tile's mean in place of a pixel's.
    def tiles(x):
        h, w = x.shape
        return x[:h - h % 16, :w - w % 16].reshape(h // 16, 16, w // 16, 16).mean((1, 3))

    vt = [tiles(x) for x in v]
    t_alloc = allocated(sum(vt))
    t2 = allocated(least(error(vt, n1, m) * time(n1, m) for n1, m in pairs))
    print(f"per tile of 16 x 16 pixels: spp {t_alloc:.3f}, spp and splits at vertices 1 and 2 "
          f"{t2:.3f} ({t2 / t_alloc:.3f} over the spp alone)")

    # Learned: each tile's choice made from the variances of the first `pilots` seeds only,
    # and judged by those of the others (held out, so the choice cannot fit their noise).
    pilots = 16
    learn = [tiles(x) for x in parts(0, pilots)]
    judge = [tiles(x) for x in parts(pilots, k)]
    e0_judge = sum(judge).mean()
    index = np.argmin(np.stack([error(learn, n1, m) * time(n1, m) for n1, m in pairs]), axis=0)
    n1 = np.array([x for x, _ in pairs])[index]
    m = np.array([y for _, y in pairs])[index]

    # spp per tile proportional to sqrt(e / t), from the pilots' numbers, and at least an
    # eighth of the mean (a tile whose pilots saw no variance must still be sampled).
    def spp_of(e, c):
        x = np.sqrt(e / c)
        return np.maximum(x, x.mean() / 8.0)

    def judged(spp, e, c):
        return e0_judge / ((e / spp).mean() * (spp * c).mean())

    g_spp = judged(spp_of(sum(learn), 1.0), sum(judge), 1.0)
    g_split = judged(spp_of(error(learn, n1, m), time(n1, m)), error(judge, n1, m), time(n1, m))
    print(f"learned per tile from {pilots} samples, judged on the other {k - pilots}: "
          f"spp {g_spp:.3f}, spp and splits {g_split:.3f} ({g_split / g_spp:.3f} over the spp alone)")

    def learned_splits(candidates):
        """Splits alone, every pixel the same spp (so the pilots' samples may stay in the image
        unbiased: no sample count depends on them): per tile the candidate (n1, m) minimising
        e + lambda t, lambda the best for the image, all from the pilots; the gain judged on the
        rest, and each tile's pick."""
        learned = np.stack([error(learn, n1, m) for n1, m in candidates])
        held_out = np.stack([error(judge, n1, m) for n1, m in candidates])
        times = np.array([time(n1, m) for n1, m in candidates])
        best = None
        for lam in np.exp(np.linspace(-8.0, 8.0, 641)) * sum(learn).mean():
            pick = np.argmin(learned + lam * times[:, None, None], axis=0)
            score = np.take_along_axis(learned, pick[None], 0).mean() * times[pick].mean()
            if best is None or score < best[0]:
                best = (score, pick)
        pick = best[1]
        gain = e0_judge / (np.take_along_axis(held_out, pick[None], 0).mean() * times[pick].mean())
        return gain, pick, times[pick].mean()

    g_splits, _, _ = learned_splits(pairs)
    print(f"learned splits alone per tile, the same spp everywhere: gain {g_splits:.3f}")

    # The tile map scripts/split_sobol.py renders with Sobol's numbers: whole splits at vertex 1
    # only (n1 = 1 to 4, n2 = 1), learned from the pilots as above.
    counts = [1, 2, 3, 4]
    g_map, pick, mean_time = learned_splits([(n, n) for n in counts])
    print(f"whole splits at vertex 1 per tile (1 to 4), learned: gain {g_map:.3f}, "
          f"mean cost {mean_time:.3f}, tiles with 1, 2, 3, 4: "
          f"{[int((pick == i).sum()) for i in range(4)]}")
    if len(sys.argv) > 7:
        with open(sys.argv[7], "w") as f:
            f.write(" ".join(str(counts[i]) for i in pick.ravel()) + "\n")


if __name__ == "__main__":
    main()
