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
import sys
import time

import mitsuba as mi
import numpy as np

from cornell_scene import (BLUE, EYE, GOLD_ALPHA, GOLD_ETA, GOLD_K, GREEN, HEIGHT, LIGHT_CENTER,
                           LIGHT_RADIANCE, LIGHT_RADIUS, LOOK_AT, RED, SPHERES, UP, VFOV, WALLS,
                           WHITE, WIDTH)
from peer_rows import relmse, sweep, variant_name, write_csv


def quad(corner, edge1, edge2, material):
    """The parallelogram corner, + edge1, + edge1 + edge2, + edge2 (front normal edge1 x edge2)."""
    p0, e1, e2 = (np.array(p, dtype=float) for p in (corner, edge1, edge2))
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n)
    center = p0 + 0.5 * (e1 + e2)
    # Mitsuba's rectangle spans [-1, 1]^2 in x, y with normal +z.
    m = np.eye(4)
    m[:3, 0] = 0.5 * e1
    m[:3, 1] = 0.5 * e2
    m[:3, 2] = n
    m[:3, 3] = center
    return {"type": "rectangle", "to_world": mi.ScalarTransform4f(m.tolist()),
            "bsdf": {"type": "ref", "id": material}}


def cornell_materials_dict(spp, seed, sampler="independent"):
    """scenes/cornell_materials.toml: the Cornell scene with a rough gold left sphere (GGX alpha
    0.2, Mitsuba's RGB eta and k of Au, as twinpath's named "gold") and a smooth glass right
    sphere (index 1.5)."""
    d = scene_dict(spp, seed, sampler)
    d["sphere_left"]["bsdf"] = {"type": "roughconductor", "distribution": "ggx",
                                "alpha": GOLD_ALPHA,
                                "eta": {"type": "rgb", "value": GOLD_ETA},
                                "k": {"type": "rgb", "value": GOLD_K}}
    d["sphere_right"]["bsdf"] = {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}
    return d


def cornell_fog_dict(spp, seed, sampler="independent"):
    """scenes/cornell_fog.toml: cornell_materials filled with a scattering fog (sigma_a, sigma_s
    RGB, Henyey-Greenstein g 0.5) around everything, the camera included, the glass sphere
    holding an absorbing juice; Mitsuba's volpath, each surface's both sides in the fog (the
    glass's inside in the juice), 128 x 128, Mitsuba's volpathmis."""
    d = cornell_materials_dict(spp, seed, sampler)
    fog_a, fog_s = np.array([0.03, 0.04, 0.06]), np.array([0.25, 0.3, 0.4])

    def medium(sigma_a, sigma_s, g):
        # An "rgb" value above 1 is refused (a reflectance): sigma_t over its largest channel,
        # times the medium's scale.
        t = sigma_a + sigma_s
        return {"type": "homogeneous", "scale": float(t.max()),
                "sigma_t": {"type": "rgb", "value": (t / t.max()).tolist()},
                "albedo": {"type": "rgb", "value": (sigma_s / t).tolist()},
                "phase": {"type": "hg", "g": g}}

    # volpathmis, Mitsuba's spectral-MIS volumetric path tracer: its plain volpath reads 0.83x
    # the closed form exp(-sigma_t d) through a chromatic absorbing medium (docs/media.md).
    d["integrator"] = {"type": "volpathmis", "max_depth": -1, "rr_depth": 5,
                       "hide_emitters": False}
    d["fog"] = medium(fog_a, fog_s, 0.5)
    fog = {"type": "ref", "id": "fog"}
    d["sensor"]["medium"] = fog
    # Mitsuba's camera rays start at the near clip plane (0.01 by default), which in a medium
    # skips that much of it: exp(0.01 sigma_t) brighter, measured +0.3% here.
    d["sensor"]["near_clip"] = 1e-6
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = 128
    for key in ["floor", "ceiling", "back", "left", "right", "sphere_left", "light"]:
        d[key]["exterior"] = fog
        d[key]["interior"] = fog
    d["sphere_right"]["exterior"] = fog
    d["sphere_right"]["interior"] = medium(np.array([0.3, 2.0, 4.0]), np.zeros(3), 0.0)
    return d


def cornell_smoke_dict(spp, seed, sampler="independent"):
    """scenes/cornell_smoke.toml: the Cornell walls and sphere light with a puff of smoke filling
    the scene, a heterogeneous medium of density grid scenes/smoke.vol times sigma_t 3.2 in every
    channel and albedo sigma_s / sigma_t (0.8125, 0.875, 0.9375), Henyey-Greenstein g 0.4;
    Mitsuba's plain volpath (unbiased where sigma_t is grey, and in a closed furnace with fog,
    where volpathmis reads 1.2% low: docs/media.md), gridvolume reading the file's box with
    use_grid_bbox, trilinear and clamped to the edge as twinpath's grid; 128 x 128."""
    import os
    here = os.path.dirname(os.path.abspath(__file__))
    d = scene_dict(spp, seed, sampler)
    for key in ["sphere_left", "sphere_right"]:
        del d[key]
    sigma_a, sigma_s = np.array([0.6, 0.4, 0.2]), np.array([2.6, 2.8, 3.0])
    t = sigma_a + sigma_s
    assert np.allclose(t, t[0]), "Mitsuba's volpath is unbiased for a grey extinction only"
    d["integrator"] = {"type": "volpath", "max_depth": -1, "rr_depth": 5,
                       "hide_emitters": False}
    d["smoke"] = {"type": "heterogeneous", "scale": float(t[0]),
                  "sigma_t": {"type": "gridvolume",
                              "filename": os.path.join(here, "..", "scenes", "smoke.vol"),
                              "use_grid_bbox": True, "filter_type": "trilinear",
                              "wrap_mode": "clamp"},
                  "albedo": {"type": "rgb", "value": (sigma_s / t).tolist()},
                  "phase": {"type": "hg", "g": 0.4}}
    smoke = {"type": "ref", "id": "smoke"}
    d["sensor"]["medium"] = smoke
    d["sensor"]["near_clip"] = 1e-6
    d["sensor"]["film"]["width"] = d["sensor"]["film"]["height"] = 128
    for key in ["floor", "ceiling", "back", "left", "right", "light"]:
        d[key]["exterior"] = smoke
        d[key]["interior"] = smoke
    return d

def scene_dict(spp, seed, sampler="independent"):
    def diffuse(rgb):
        return {"type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}}

    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False},
        "sensor": {
            "type": "perspective",
            "fov": VFOV,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=list(EYE), target=list(LOOK_AT),
                                                       up=list(UP)),
            "sampler": {"type": sampler, "sample_count": spp, "seed": seed},
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
        },
        "white": diffuse(WHITE), "red": diffuse(RED), "green": diffuse(GREEN),
        "blue": diffuse(BLUE),
        "light": {"type": "sphere", "center": list(LIGHT_CENTER), "radius": LIGHT_RADIUS,
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}},
                  "emitter": {"type": "area",
                              "radiance": {"type": "rgb", "value": LIGHT_RADIANCE}}},
    }
    for name, corner, edge1, edge2, material in WALLS:
        d[name] = quad(corner, edge1, edge2, material)
    for name, center, radius, material in SPHERES:
        d[name] = {"type": "sphere", "center": list(center), "radius": radius,
                   "bsdf": {"type": "ref", "id": material}}
    return d


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
