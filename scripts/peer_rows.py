"""The measurements the peer scripts (peer_mitsuba.py, peer_cycles.py) write: `twinpath diff`'s
relMSE and RMSE of an image against the reference, and the CSV columns of `twinpath bench`.
Plain Python and numpy, so both peers' virtualenvs import it."""

import sys

import numpy as np

HEADER = "variant,backend,spp,seed,setup_s,render_s,relmse,rmse,efficiency\n"


def relmse(img, ref):
    """`twinpath diff`'s relMSE: mean of (img - ref)^2 / (ref^2 + 0.01) over pixels and channels."""
    d = img - ref
    return float(np.mean(d * d / (ref * ref + 0.01)))


def row(img, ref, spp, seed, setup_s, render_s):
    """One CSV row's numbers: (spp, seed, set-up s, render s, relMSE, RMSE, efficiency)."""
    rel = relmse(img, ref)
    rmse = float(np.sqrt(np.mean((img - ref) ** 2)))
    return spp, seed, setup_s, render_s, rel, rmse, 1.0 / (rel * render_s)


def write_csv(path, variant, rows):
    """The rows of `row` as `twinpath bench` writes its CSV, all under `variant`."""
    with open(path, "w") as f:
        f.write(HEADER)
        for spp, seed, setup, render_s, rel, rmse, eff in rows:
            f.write(f"{variant},Cpu,{spp},{seed},{setup:.6f},{render_s:.6f},"
                    f"{rel:.6e},{rmse:.6e},{eff:.6e}\n")


def seeds_at(spp):
    """Independent renders per sample count, as `twinpath bench` takes them: more where one
    render's error is itself noisy."""
    return 4 if spp <= 4 else (2 if spp <= 32 else 1)


def variant_name(base, mesh=None, scene="cornell"):
    """The CSV's variant: `base`, then the mesh file's stem and the scene unless it is Cornell."""
    name = base
    if mesh:
        name += "-" + mesh.rsplit("/", 1)[-1].removesuffix(".ply")
    if scene != "cornell":
        name += "-" + scene
    return name


def sweep(measure, ref, max_spp, max_seconds, label, sample_count=lambda spp: spp):
    """Renders at 1, 2, 4, ... spp up to `max_spp` (or until one render takes `max_seconds`),
    `seeds_at` seeds each: `measure(spp, seed)` gives (image, set-up s, render s). A count
    becomes `sample_count(spp)`, the samples the renderer really takes (Mitsuba's `ldsampler`
    rounds up to a power of 4); a count already measured is skipped. Returns the rows."""
    rows, measured, spp = [], set(), 1
    while spp <= max_spp:
        actual = sample_count(spp)
        spp *= 2
        if actual in measured:
            continue
        measured.add(actual)
        for seed in range(1, seeds_at(actual) + 1):
            img, setup_s, render_s = measure(actual, seed)
            rows.append(row(img, ref, actual, seed, setup_s, render_s))
            print(f"{label} spp {actual} seed {seed}: {render_s:.3f} s (+{setup_s:.3f} s set-up), "
                  f"relMSE {rows[-1][4]:.4e}", file=sys.stderr)
        if render_s > max_seconds:
            break
    return rows
