"""The scenes of the Mitsuba 3 peer as mi.load_dict dictionaries, the numbers of
scenes/cornell.toml and its variants (scripts/cornell_scene.py): scene_dict (Cornell),
cornell_materials_dict, cornell_fog_dict, cornell_smoke_dict, each taking (spp, seed, sampler).
Plain Python besides mitsuba (no numpy), so that scripts/peer_mitsuba_gpu.py runs them on a lent
GPU machine from the wheels alone; mi.set_variant must have been called."""

import math
import os

import mitsuba as mi

from cornell_scene import (BLUE, EYE, GOLD_ALPHA, GOLD_ETA, GOLD_K, GREEN, HEIGHT, LIGHT_CENTER,
                           LIGHT_RADIANCE, LIGHT_RADIUS, LOOK_AT, RED, SPHERES, UP, VFOV, WALLS,
                           WHITE, WIDTH)


def quad(corner, edge1, edge2, material):
    """The parallelogram corner, + edge1, + edge1 + edge2, + edge2 (front normal edge1 x edge2)."""
    e1, e2 = edge1, edge2
    n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
         e1[0] * e2[1] - e1[1] * e2[0])
    length = math.sqrt(sum(c * c for c in n))
    n = [c / length for c in n]
    center = [p + 0.5 * (a + b) for p, a, b in zip(corner, e1, e2)]
    # Mitsuba's rectangle spans [-1, 1]^2 in x, y with normal +z: columns 0.5 e1, 0.5 e2, n and
    # the centre.
    m = [[0.5 * e1[r], 0.5 * e2[r], n[r], center[r]] for r in range(3)] + [[0, 0, 0, 1]]
    return {"type": "rectangle", "to_world": mi.ScalarTransform4f(m),
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
    fog_a, fog_s = [0.03, 0.04, 0.06], [0.25, 0.3, 0.4]

    def medium(sigma_a, sigma_s, g):
        # An "rgb" value above 1 is refused (a reflectance): sigma_t over its largest channel,
        # times the medium's scale.
        t = [a + s for a, s in zip(sigma_a, sigma_s)]
        return {"type": "homogeneous", "scale": max(t),
                "sigma_t": {"type": "rgb", "value": [c / max(t) for c in t]},
                "albedo": {"type": "rgb", "value": [s / c for s, c in zip(sigma_s, t)]},
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
    d["sphere_right"]["interior"] = medium([0.3, 2.0, 4.0], [0.0, 0.0, 0.0], 0.0)
    return d


def cornell_smoke_dict(spp, seed, sampler="independent"):
    """scenes/cornell_smoke.toml: the Cornell walls and sphere light with a puff of smoke filling
    the scene, a heterogeneous medium of density grid scenes/smoke.vol times sigma_t 3.2 in every
    channel and albedo sigma_s / sigma_t (0.8125, 0.875, 0.9375), Henyey-Greenstein g 0.4;
    Mitsuba's plain volpath (unbiased where sigma_t is grey, and in a closed furnace with fog,
    where volpathmis reads 1.2% low: docs/media.md), gridvolume reading the file's box with
    use_grid_bbox, trilinear and clamped to the edge as twinpath's grid; 128 x 128."""
    here = os.path.dirname(os.path.abspath(__file__))
    d = scene_dict(spp, seed, sampler)
    for key in ["sphere_left", "sphere_right"]:
        del d[key]
    sigma_a, sigma_s = [0.6, 0.4, 0.2], [2.6, 2.8, 3.0]
    t = [a + s for a, s in zip(sigma_a, sigma_s)]
    assert max(t) - min(t) < 1e-12, "Mitsuba's volpath is unbiased for a grey extinction only"
    d["integrator"] = {"type": "volpath", "max_depth": -1, "rr_depth": 5,
                       "hide_emitters": False}
    d["smoke"] = {"type": "heterogeneous", "scale": t[0],
                  "sigma_t": {"type": "gridvolume",
                              "filename": os.path.join(here, "..", "scenes", "smoke.vol"),
                              "use_grid_bbox": True, "filter_type": "trilinear",
                              "wrap_mode": "clamp"},
                  "albedo": {"type": "rgb", "value": [s / c for s, c in zip(sigma_s, t)]},
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
