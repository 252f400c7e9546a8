#!/usr/bin/env python3
"""Blender's Cycles (CPU) on the Cornell scene: time against error, in the CSV columns of
`twinpath bench`, the peer of scripts/peer_mitsuba.py.

Builds the scene of tests/reference/cornell_spheres/scene.md through bpy with the same numbers
as scenes/cornell.toml, in twinpath's frame (y up) under an empty turned +90 degrees about x
(Blender's z up): the walls as two-triangle meshes, the two spheres as exact spheres (a point
cloud of one point each, which Cycles intersects as a sphere, not a tessellation), Diffuse BSDF
materials (Lambertian, both sides). The light, a sphere of radius 0.3 and radiance 10 that
reflects nothing, is a Cycles point light of that radius with `use_soft_falloff` off (a sphere
light, sampled in the cone it subtends: Cycles' best for it), power P = L 4 pi^2 r^2 = 35.53 W,
visible to the camera. Cycles' lights are transparent to the rays that hit them, so a black
sphere 0.1% smaller sits inside it: what twinpath's and Mitsuba's emitting sphere blocks, it
blocks. Unbiased settings: no clamping, no denoising, no adaptive sampling, no glossy filter,
bounce limits 1024, box pixel filter of width 1, black world, view transform Standard; the
image is Cycles' linear result, read back as float.

It renders at 1, 2, 4, ... spp, several seeds per point at low spp, and writes the CSV columns
of `twinpath bench`: set-up seconds (a 1-spp render of a 1%-size image: the scene's sync and
BVH build, which every render call repeats) and render seconds (the render call's wall time
less that set-up), relMSE and RMSE against the reference with the definitions of
`twinpath diff`: relMSE = mean over pixels and channels of (a - b)^2 / (b^2 + 0.01).

Usage: peer_cycles.py REFERENCE.exr OUT.csv [--max-spp 1024] [--max-seconds 60]
       [--pattern AUTOMATIC] [--scene cornell|materials|textured] [--mesh KNOT.ply]
       [--once SPP] [--validate SPP] [--export-gltf PATH [--size W H]]
--scene materials: scenes/cornell_materials.toml, the left sphere rough gold (GGX alpha 0.2,
Au's RGB eta and k, Cycles' Metallic BSDF as a physical conductor) and the right smooth glass
of index 1.5 (Glass BSDF, roughness 0).
--scene textured: scripts/textured_room.py's Blender scene, whose glTF export twinpath renders;
with --export-gltf PATH (and --size W H, default 256 256) it only writes that file (REFERENCE
and OUT are then not read or written).
--pattern picks Cycles' sampling pattern (its name is added to the variant column unless
AUTOMATIC, the default). --mesh replaces the two spheres by a PLY mesh in white, flat-shaded
(scripts/knot_scenes.py's and scripts/bunny_scene.py's scenes). --once SPP renders once (seed
1), writes the image to OUT (EXR) and prints its relMSE, for timing whole processes.
--validate SPP renders two independent halves (seeds 1 and 2) of SPP samples each and prints
how far their mean is from the reference against the noise the halves show (16 x 16 blocks of
pixels: z-scores of the block means), so that a scene built differently shows before it is
timed; OUT is then the mean image (EXR).
Install: Python 3.13 and `pip install bpy numpy` (scripts/peer_cycles.sh does it in a venv).
"""

import argparse
import math
import os
import sys
import tempfile
import time

import bpy
import numpy as np

import cycles_fixtures
import textured_room
from cornell_scene import (BLUE, EYE, GOLD_ALPHA, GOLD_ETA, GOLD_K, GREEN, LIGHT_CENTER,
                           LIGHT_RADIANCE, LIGHT_RADIUS, LOOK_AT, RED, SPHERES, UP, VFOV, WALLS,
                           WHITE)
from peer_rows import relmse, sweep, variant_name, write_csv

# The black sphere inside the light: smaller by this fraction of its radius.
OCCLUDER_SHRINK = 1e-3


def settings(width, height):
    """A new scene with Cycles' unbiased settings (`cycles_fixtures.reset`: no clamping, no
    denoising, no adaptive sampling, no glossy filter, bounce limits 1024, box filter of width 1,
    view transform Standard, black world), at `width` x `height`, on the CPU with all its
    threads, saving linear 32-bit EXR."""
    scene = cycles_fixtures.reset()
    scene.render.threads_mode = "AUTO"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "NONE"
    return scene


def one_bsdf(name, node_type, **inputs):
    """A material of one BSDF node of `node_type`, its inputs set from `inputs` (an input name
    with spaces written with underscores; `distribution` and `fresnel_type` are the node's
    properties)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    for node in list(nodes):
        nodes.remove(node)
    bsdf = nodes.new(node_type)
    for key, value in inputs.items():
        if key in ("distribution", "fresnel_type"):
            setattr(bsdf, key, value)
        else:
            bsdf.inputs[key.replace("_", " ")].default_value = value
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def diffuse(name, rgb):
    """One Diffuse BSDF (roughness 0: Lambertian) of reflectance `rgb`."""
    return one_bsdf(name, "ShaderNodeBsdfDiffuse", Color=(*rgb, 1.0), Roughness=0.0)


def gold_ggx():
    """scenes/cornell_materials.toml's gold: GGX alpha 0.2 (Blender's roughness is sqrt(alpha))
    with Mitsuba's RGB eta and k of Au (twinpath's named "gold"), Cycles' Metallic BSDF as a
    physical conductor, single scattering."""
    return one_bsdf("gold", "ShaderNodeBsdfMetallic", fresnel_type="PHYSICAL_CONDUCTOR",
                    distribution="GGX", IOR=GOLD_ETA, Extinction=GOLD_K,
                    Roughness=math.sqrt(GOLD_ALPHA))


def glass():
    """scenes/cornell_materials.toml's glass: a smooth dielectric of index 1.5 (Glass BSDF,
    roughness 0: Cycles' singular glass; white)."""
    return one_bsdf("glass", "ShaderNodeBsdfGlass", distribution="GGX", Roughness=0.0,
                    Color=(1.0, 1.0, 1.0, 1.0), IOR=1.5)


def link(scene, obj, parent):
    scene.collection.objects.link(obj)
    obj.parent = parent


def quad(scene, parent, name, corner, edge1, edge2, material):
    """scenes/cornell.toml's quad: corner, corner + edge1, corner + edge1 + edge2, corner + edge2
    (front normal edge1 x edge2), two triangles."""
    c, e1, e2 = (np.array(v, dtype=float) for v in (corner, edge1, edge2))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(c), tuple(c + e1), tuple(c + e1 + e2), tuple(c + e2)], [],
                     [(0, 1, 2), (0, 2, 3)])
    mesh.materials.append(material)
    link(scene, bpy.data.objects.new(name, mesh), parent)


def sphere(scene, parent, name, center, radius, material):
    """An exact sphere: a point cloud of one point, which Cycles intersects as a sphere."""
    cloud = bpy.data.pointclouds.new(name)
    cloud.resize(1)
    cloud.attributes["position"].data[0].vector = center
    radius_attribute = cloud.attributes.get("radius") or \
        cloud.attributes.new("radius", "FLOAT", "POINT")
    radius_attribute.data[0].value = radius
    cloud.materials.append(material)
    link(scene, bpy.data.objects.new(name, cloud), parent)


def mesh_sphere(scene, parent, name, center, radius, material, segments=512, rings=256):
    """A smooth-shaded UV sphere of `segments` x `rings` (512 x 256: 262k triangles, whose flat
    facets stay within 2e-5 of the radius from the exact sphere, and whose normals are the
    exact sphere's at the vertices). For glass: Cycles' point-cloud spheres report where a ray
    enters them, not where it leaves, so a refracted ray would not find the way out. Built
    from arrays (Blender's primitive operator takes seconds at this size)."""
    theta = np.linspace(0.0, np.pi, rings + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)
    ring = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                     np.repeat(np.cos(theta)[:, None], segments, axis=1)], axis=-1)
    points = np.concatenate([[[0.0, 0.0, 1.0]], ring.reshape(-1, 3), [[0.0, 0.0, -1.0]]])
    points = np.asarray(center) + radius * points
    r, j = np.meshgrid(np.arange(rings - 2), np.arange(segments), indexing="ij")
    a = 1 + r * segments + j
    b = 1 + r * segments + (j + 1) % segments
    c, d = b + segments, a + segments
    quads = np.stack([a, d, c, b], axis=-1).reshape(-1, 4)
    j = np.arange(segments)
    top = np.stack([np.zeros_like(j), 1 + j, 1 + (j + 1) % segments], axis=-1)
    last = len(points) - 1
    first_of_bottom = 1 + (rings - 2) * segments
    bottom = np.stack([np.full_like(j, last), first_of_bottom + (j + 1) % segments,
                       first_of_bottom + j], axis=-1)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(points.tolist(), [], quads.tolist() + top.tolist() + bottom.tolist())
    mesh.shade_smooth()
    mesh.materials.append(material)
    link(scene, bpy.data.objects.new(name, mesh), parent)


def build(width=256, height=256, mesh=None, materials=False):
    """The Cornell scene (or, with `mesh`, the room with that PLY in place of the spheres; with
    `materials`, scenes/cornell_materials.toml: the left sphere gold, the right glass)."""
    scene = settings(width, height)
    # twinpath's frame (y up) into Blender's (z up): (x, y, z) -> (x, -z, y).
    frame = bpy.data.objects.new("twinpath_frame", None)
    scene.collection.objects.link(frame)
    frame.rotation_euler = (math.pi / 2, 0.0, 0.0)
    palette = {name: diffuse(name, c) for name, c in (
        ("white", WHITE), ("red", RED), ("green", GREEN), ("blue", BLUE))}
    white = palette["white"]
    for name, corner, edge1, edge2, material in WALLS:
        quad(scene, frame, name, corner, edge1, edge2, palette[material])
    if mesh is None:
        # With `materials` the left sphere is gold and the right glass (on a mesh: see
        # `mesh_sphere`).
        kinds = [(gold_ggx(), sphere), (glass(), mesh_sphere)] if materials else \
            [(palette[m], sphere) for *_, m in SPHERES]
        for (name, center, radius, _), (material, make) in zip(SPHERES, kinds):
            make(scene, frame, name, center, radius, material)
    else:
        # The file's coordinates as they are (twinpath's frame), flat-shaded as twinpath and
        # Mitsuba (`face_normals`) shade it.
        bpy.ops.wm.ply_import(filepath=mesh, forward_axis="Y", up_axis="Z")
        obj = bpy.context.selected_objects[0]
        for polygon in obj.data.polygons:
            polygon.use_smooth = False
        obj.data.materials.clear()
        obj.data.materials.append(white)
        obj.parent = frame
    sphere(scene, frame, "light_occluder", LIGHT_CENTER,
           LIGHT_RADIUS * (1.0 - OCCLUDER_SHRINK), diffuse("black", (0.0, 0.0, 0.0)))
    light = bpy.data.lights.new("light", "POINT")
    light.shadow_soft_size = LIGHT_RADIUS
    light.use_soft_falloff = False
    light.energy = LIGHT_RADIANCE * 4.0 * math.pi ** 2 * LIGHT_RADIUS ** 2
    light_obj = bpy.data.objects.new("light", light)
    light_obj.location = LIGHT_CENTER
    light_obj.visible_camera = True
    link(scene, light_obj, frame)
    camera = bpy.data.cameras.new("camera")
    camera.sensor_fit = "VERTICAL"
    camera.angle_y = math.radians(VFOV)
    camera.clip_start = 1e-4
    camera_obj = bpy.data.objects.new("camera", camera)
    # Blender's camera looks down its -z with +y up: the scene's camera, which looks along -z
    # with y up, unturned in twinpath's frame.
    look = np.subtract(LOOK_AT, EYE)
    assert look[0] == look[1] == 0 and look[2] < 0 and tuple(UP) == (0, 1, 0)
    camera_obj.location = EYE
    link(scene, camera_obj, frame)
    scene.camera = camera_obj
    return scene


def render(scene, spp, seed, path=None):
    """One render: the image (height x width x 3, top row first, float64) and the render call's
    wall time."""
    scene.cycles.samples = spp
    scene.cycles.seed = seed
    t0 = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - t0
    return read_render_result(path), seconds


def read_render_result(path=None):
    """The last render, saved as EXR (to `path`, or a temporary file) and read back."""
    keep = path is not None
    if not keep:
        handle, path = tempfile.mkstemp(suffix=".exr")
        os.close(handle)
    bpy.data.images["Render Result"].save_render(path)
    img = read_exr(path)
    if not keep:
        os.remove(path)
    return img


def read_exr(path):
    """An EXR's RGB, top row first (`cycles_fixtures.read_exr` holds it bottom row first)."""
    return np.ascontiguousarray(cycles_fixtures.read_exr(path)[::-1, :, :3])


def write_exr(path, img):
    height, width = img.shape[:2]
    image = bpy.data.images.new("out", width, height, float_buffer=True, alpha=True)
    rgba = np.ones((height, width, 4))
    rgba[:, :, :3] = img
    image.pixels = rgba[::-1].ravel()
    image.filepath_raw = path
    image.file_format = "OPEN_EXR"
    image.save()
    bpy.data.images.remove(image)


def block_means(img, block=16):
    h, w = img.shape[0] // block, img.shape[1] // block
    return img[:h * block, :w * block].reshape(h, block, w, block, 3).mean(axis=(1, 3))


def validate(scene, spp, ref, out):
    """Two halves against the reference: each 16 x 16 block's mean of the halves' mean, against
    the reference's, in units of its standard error. Per pixel, (a - b)^2 / 4 estimates the
    variance of the halves' mean (one degree of freedom); a block's mean of them over n pixels,
    divided by n, that of the block's mean (n degrees). The reference's own noise is left out
    (it has many more samples)."""
    a, _ = render(scene, spp, 1)
    b, _ = render(scene, spp, 2)
    mean = 0.5 * (a + b)
    write_exr(out, mean)
    n = 16 * 16
    se = np.sqrt(block_means((a - b) ** 2 / 4.0) / n)
    # Blocks without noise (inside the light, where both halves read the light's radiance):
    # single precision's rounding instead.
    se = np.maximum(se, 1e-6 * np.abs(block_means(ref)) + 1e-12)
    z = (block_means(mean) - block_means(ref)) / se
    channel = mean.mean(axis=(0, 1)) / ref.mean(axis=(0, 1))
    print(f"validate {spp} spp x 2: channel means / reference {np.round(channel, 5).tolist()}")
    print(f"  relMSE(half 1, half 2) / 4 = {relmse(a, b) / 4:.3e} (the mean's own noise), "
          f"relMSE(mean, reference) = {relmse(mean, ref):.3e}")
    print(f"  block z-scores ({z.size}): mean {z.mean():+.3f}, rms {np.sqrt(np.mean(z ** 2)):.3f}, "
          f"max |z| {np.abs(z).max():.2f}, |z| > 4: {int(np.sum(np.abs(z) > 4))}")
    for row, col, ch in np.argwhere(np.abs(z) > 4):
        print(f"  block at pixel row {16 * row}, column {16 * col}, channel {ch}: "
              f"z {z[row, col, ch]:+.2f}, mean {block_means(mean)[row, col, ch]:.5f} "
              f"against {block_means(ref)[row, col, ch]:.5f}")


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("out")
    ap.add_argument("--max-spp", type=int, default=1024)
    ap.add_argument("--max-seconds", type=float, default=60.0)
    ap.add_argument("--pattern", default="AUTOMATIC")
    ap.add_argument("--mesh", help="a PLY mesh in place of the spheres")
    ap.add_argument("--scene", default="cornell", choices=["cornell", "materials", "textured"])
    ap.add_argument("--size", type=int, nargs=2, default=(256, 256), metavar=("W", "H"))
    ap.add_argument("--export-gltf", metavar="PATH")
    ap.add_argument("--once", type=int, metavar="SPP")
    ap.add_argument("--validate", type=int, metavar="SPP")
    args = ap.parse_args(argv)

    if args.export_gltf:
        # The textured scene as a glTF file (the reference is rendered from it afterwards).
        textured_room.build(settings(*args.size))
        textured_room.export(args.export_gltf)
        return
    ref = read_exr(args.reference)
    height, width = ref.shape[:2]
    if args.scene == "textured":
        scene = textured_room.build(settings(width, height))
    else:
        scene = build(width, height, args.mesh, args.scene == "materials")
    scene.cycles.sampling_pattern = args.pattern
    if args.validate:
        validate(scene, args.validate, ref, args.out)
        return
    if args.once:
        img, seconds = render(scene, args.once, 1, args.out)
        print(f"relmse {relmse(img, ref):.6e}")
        print(f"samples {width * height * args.once}")
        return
    # Set-up: what every render call repeats before its samples (sync, BVH), measured on a
    # 1%-size image at 1 spp; the first call also loads Cycles' kernels (a warm-up).
    scene.render.resolution_percentage = 1
    render(scene, 1, 1000)
    _, setup = render(scene, 1, 1000)
    scene.render.resolution_percentage = 100

    def measure(spp, seed):
        img, seconds = render(scene, spp, seed)
        return img, setup, max(seconds - setup, 1e-6)

    rows = sweep(measure, ref, args.max_spp, args.max_seconds, f"cycles {args.pattern}")
    base = "cycles" if args.pattern == "AUTOMATIC" else f"cycles-{args.pattern.lower()}"
    write_csv(args.out, variant_name(base, args.mesh, args.scene), rows)


if __name__ == "__main__":
    main()
