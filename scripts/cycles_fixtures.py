"""Blender feature scenes, exported by Blender's own glTF exporter and rendered by Cycles: the
fixtures of tests/tests/cycles.rs (tests/reference/cycles/<scene>/).

Each scene is built through bpy the way a user builds it in Blender (Principled BSDF materials,
light objects in Watts, a 35 mm camera), exported with `bpy.ops.export_scene.gltf` at its
defaults plus cameras and lights (scene.glb), and rendered by Cycles with unbiased settings (no
clamping, no denoising, no glossy filter, bounce limits 1024, box pixel filter, no adaptive
sampling, black world) as two independent halves (seeds 1 and 2), linear EXR; the reference is
their mean (the tests take it; meta.json records its channel means).

Run with Python 3.13 and `bpy` from PyPI (scripts/cycles_fixtures.sh sets that up and writes
tests/reference/cycles):
    python scripts/cycles_fixtures.py OUT_DIR [SCENE ...]
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np

WIDTH, HEIGHT = 32, 24
HALF_SPP = 16384


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.blur_glossy = 0.0
    for bounce in (
        "max_bounces",
        "diffuse_bounces",
        "glossy_bounces",
        "transmission_bounces",
        "volume_bounces",
        "transparent_max_bounces",
    ):
        setattr(scene.cycles, bounce, 1024)
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    scene.render.resolution_x = WIDTH
    scene.render.resolution_y = HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    # A black world (a new world's Background node is grey 0.05, which the floor would reflect).
    world = bpy.data.worlds.new("black")
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is not None:
        for node in world.node_tree.nodes:
            if node.type == "BACKGROUND":
                node.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
                node.inputs["Strength"].default_value = 0.0
    scene.world = world
    return scene


def principled(name, base=(0.8, 0.8, 0.8), specular_level=0.0, roughness=0.5, emission=None):
    """A Principled BSDF material (specular IOR level 0: a Lambertian surface in both renderers,
    so a fixture about lights measures the lights alone)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Specular IOR Level"].default_value = specular_level
    if emission is not None:
        colour, strength = emission
        bsdf.inputs["Emission Color"].default_value = (*colour, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return mat


def floor(size=8.0, material=None):
    bpy.ops.mesh.primitive_plane_add(size=size, location=(0.0, 0.0, 0.0))
    plane = bpy.context.object
    plane.data.materials.append(material or principled("floor"))
    return plane


def camera(scene, location=(0.0, -4.0, 3.0), target=(0.0, 0.0, 0.0)):
    data = bpy.data.cameras.new("camera")
    data.lens = 35.0
    cam = bpy.data.objects.new("camera", data)
    scene.collection.objects.link(cam)
    cam.location = location
    direction = np.subtract(target, location)
    # Track -Z to the target, Y up.
    from mathutils import Vector

    cam.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam
    return cam


def light(scene, kind, energy, location, rotation=(0.0, 0.0, 0.0), **props):
    data = bpy.data.lights.new(kind.lower(), kind)
    data.energy = energy
    for key, value in props.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(kind.lower(), data)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


def scene_point():
    """A 100 W point light (radius 0) 1.5 m above a Lambertian floor of base colour 0.8."""
    scene = reset()
    floor()
    light(scene, "POINT", 100.0, (0.3, 0.2, 1.5), shadow_soft_size=0.0)
    camera(scene)
    return scene


def scene_spot():
    """A 200 W spot light (60 degrees, blend 0.3, radius 0) 2.5 m above the floor, tilted."""
    scene = reset()
    floor()
    light(
        scene,
        "SPOT",
        200.0,
        (0.0, 0.0, 2.5),
        rotation=(math.radians(10.0), 0.0, 0.0),
        spot_size=math.radians(60.0),
        spot_blend=0.3,
        shadow_soft_size=0.0,
    )
    camera(scene)
    return scene


def scene_sun():
    """A sun of strength 3 (W/m^2), 30 degrees from the zenith, angle 0."""
    scene = reset()
    floor()
    light(scene, "SUN", 3.0, (0.0, 0.0, 3.0), rotation=(math.radians(30.0), 0.0, 0.0), angle=0.0)
    camera(scene)
    return scene


def scene_emission():
    """A 1 m square emitter (Principled, black base, emission strength 5) 1 m above the floor,
    facing down, seen by the camera too."""
    scene = reset()
    floor()
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.5, 1.0), rotation=(math.pi, 0.0, 0.0))
    lamp = bpy.context.object
    lamp.data.materials.append(
        principled("lamp", base=(0.0, 0.0, 0.0), emission=((1.0, 0.9, 0.7), 5.0))
    )
    camera(scene, location=(0.0, -4.0, 1.2), target=(0.0, 0.0, 0.6))
    return scene


def png_image(name, size, colour, path):
    """A `size` x `size` RGB image whose texel (i, j) is `colour(i, j)`, written as PNG to
    `path` and loaded back (as an exported file reads it)."""
    image = bpy.data.images.new(name, size, size, alpha=False)
    pixels = []
    for j in range(size):
        for i in range(size):
            pixels += [*colour(i, j), 1.0]
    image.pixels = pixels
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    return bpy.data.images.load(path)


def checker_image(path):
    """An 8 x 8 image of saturated colours (bytes 0 and 255: sRGB-decoded exactly to 0 and 1 in
    both renderers), neighbours all different, written as PNG and loaded back."""
    palette = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1), (0, 0, 0)]
    return png_image("checker", 8, lambda i, j: palette[(3 * i + 5 * j) % 8], path)


def scene_mapping():
    """A floor whose base colour is an image texture through a Mapping node (location 0.1,
    0.2; rotation 30 degrees; scale 2, 1.5), Specular IOR Level 0, under a 300 W point light.
    Set SRGB_TEXTURE=1 to read the image as sRGB instead (the filtering difference)."""
    scene = reset()
    mat = principled("mapped")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    coords = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Location"].default_value = (0.1, 0.2, 0.0)
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(30.0))
    mapping.inputs["Scale"].default_value = (2.0, 1.5, 1.0)
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = checker_image(os.path.join(bpy.app.tempdir, "checker.png"))
    texture.interpolation = "Linear"
    texture.extension = "REPEAT"
    # Cycles filters an sRGB byte image before decoding it (twinpath, pbrt and Mitsuba decode,
    # then filter: docs/gltf.md). With texels 0 and 1 (exact either way) read as linear,
    # Cycles filters the same values twinpath does, so this fixture measures the mapping.
    if not os.environ.get("SRGB_TEXTURE"):
        texture.image.colorspace_settings.name = "Linear Rec.709"
    links.new(coords.outputs["UV"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    floor(material=mat)
    light(scene, "POINT", 300.0, (0.3, 0.2, 2.0), shadow_soft_size=0.0)
    camera(scene)
    return scene


def scene_colour():
    """A floor whose base colour is a Color Attribute (float, per corner: red, green, blue and
    white at its four corners), Specular IOR Level 0, under a 300 W point light."""
    scene = reset()
    mat = principled("coloured")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    attribute = nodes.new("ShaderNodeVertexColor")
    attribute.layer_name = "Col"
    links.new(attribute.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    plane = floor(material=mat)
    colours = plane.data.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    corners = [(0.9, 0.1, 0.1, 1.0), (0.1, 0.8, 0.2, 1.0), (0.2, 0.3, 0.9, 1.0), (1.0, 1.0, 1.0, 1.0)]
    for k, value in enumerate(corners):
        colours.data[k].color = value
    light(scene, "POINT", 300.0, (0.3, 0.2, 2.0), shadow_soft_size=0.0)
    camera(scene)
    return scene


def scene_glowing_wall():
    """A wall whose Principled BSDF both emits (strength 1, warm) and reflects (base colour 0.7,
    Specular IOR Level 0), beside a floor, under a 200 W point light."""
    scene = reset()
    floor()
    bpy.ops.mesh.primitive_plane_add(
        size=2.0, location=(0.0, 1.0, 1.0), rotation=(math.pi / 2, 0.0, 0.0)
    )
    wall = bpy.context.object
    wall.data.materials.append(
        principled("glowing", base=(0.7, 0.7, 0.7), emission=((1.0, 0.8, 0.6), 1.0))
    )
    light(scene, "POINT", 200.0, (0.5, -1.0, 2.0), shadow_soft_size=0.0)
    camera(scene, location=(0.0, -4.0, 2.0), target=(0.0, 0.5, 0.6))
    return scene


def scene_rough_metal():
    """Two smooth-shaded spheres of Principled metal (Metallic 1): roughness 0.5 in a gold base
    colour and roughness 0.9 in a light grey, on a grey floor under a 300 W point light. Cycles'
    multiscatter GGX keeps the energy the single-scattering lobe loses between microfacets."""
    scene = reset()
    floor()
    for x, roughness, base in ((-0.75, 0.5, (0.9, 0.6, 0.3)), (0.75, 0.9, (0.9, 0.9, 0.9))):
        bpy.ops.mesh.primitive_uv_sphere_add(
            radius=0.6, location=(x, 0.0, 0.6), segments=48, ring_count=24
        )
        ball = bpy.context.object
        bpy.ops.object.shade_smooth()
        metal = principled(f"metal_{roughness}", base=base, roughness=roughness)
        metal.node_tree.nodes["Principled BSDF"].inputs["Metallic"].default_value = 1.0
        ball.data.materials.append(metal)
    light(scene, "POINT", 300.0, (1.0, -2.0, 3.0), shadow_soft_size=0.0)
    camera(scene, location=(0.0, -4.0, 2.2), target=(0.0, 0.0, 0.5))
    return scene


def scene_coat():
    """Two smooth-shaded spheres of red Principled plastic (base colour (0.8, 0.1, 0.1),
    roughness 0.5, Specular IOR Level 0: a Lambertian base) under a Coat of weight 1: roughness
    0.6 on the left, 0 (a mirror) on the right; a grey floor,
    a 300 W point light."""
    scene = reset()
    floor()
    for x, coat_roughness in ((-0.75, 0.6), (0.75, 0.0)):
        bpy.ops.mesh.primitive_uv_sphere_add(
            radius=0.6, location=(x, 0.0, 0.6), segments=48, ring_count=24
        )
        ball = bpy.context.object
        bpy.ops.object.shade_smooth()
        coated = principled(f"coated_{coat_roughness}", base=(0.8, 0.1, 0.1), roughness=0.5)
        inputs = coated.node_tree.nodes["Principled BSDF"].inputs
        inputs["Coat Weight"].default_value = 1.0
        inputs["Coat Roughness"].default_value = coat_roughness
        ball.data.materials.append(coated)
    light(scene, "POINT", 300.0, (1.0, -2.0, 3.0), shadow_soft_size=0.0)
    camera(scene, location=(0.0, -4.0, 2.2), target=(0.0, 0.0, 0.5))
    return scene


def scene_sheen():
    """Two smooth-shaded spheres under a Sheen of weight 1 over a Lambertian base (Specular IOR
    Level 0): on the left a white sheen of roughness 0.5 over dark blue (0.05, 0.1, 0.4), on
    the right an orange sheen (1, 0.6, 0.3) of roughness 1 over grey 0.5; a grey floor, a 300 W
    point light behind them on the left, so that the sheen's grazing light shows."""
    scene = reset()
    floor()
    for x, base, tint, roughness in (
        (-0.75, (0.05, 0.1, 0.4), (1.0, 1.0, 1.0), 0.5),
        (0.75, (0.5, 0.5, 0.5), (1.0, 0.6, 0.3), 1.0),
    ):
        bpy.ops.mesh.primitive_uv_sphere_add(
            radius=0.6, location=(x, 0.0, 0.6), segments=48, ring_count=24
        )
        ball = bpy.context.object
        bpy.ops.object.shade_smooth()
        velvet = principled(f"sheen_{roughness}", base=base, roughness=0.5)
        inputs = velvet.node_tree.nodes["Principled BSDF"].inputs
        inputs["Sheen Weight"].default_value = 1.0
        inputs["Sheen Roughness"].default_value = roughness
        inputs["Sheen Tint"].default_value = (*tint, 1.0)
        ball.data.materials.append(velvet)
    light(scene, "POINT", 300.0, (-1.5, 2.0, 2.5), shadow_soft_size=0.0)
    camera(scene, location=(0.0, -4.0, 2.2), target=(0.0, 0.0, 0.5))
    return scene


def alpha_checker_image(path):
    """A 4 x 4 image of one colour, green (bytes 0 and 255: sRGB-decoded exactly to 0 and 1, so
    the same texels in both renderers, read as linear as in the mapping scene), whose alpha
    alternates 0 and 1 as a checkerboard, written as PNG and loaded back: the leaf texture of a
    cut-out."""
    image = bpy.data.images.new("leaf", 4, 4, alpha=True)
    pixels = []
    for j in range(4):
        for i in range(4):
            pixels += [0.0, 1.0, 0.0, float((i + j) % 2)]
    image.pixels = pixels
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    loaded = bpy.data.images.load(path)
    loaded.colorspace_settings.name = "Linear Rec.709"
    return loaded


def scene_cutout():
    """A 2 m square 1 m above the floor whose alpha is clipped at 0.5, as a leaf texture is: the
    image's alpha through Math "Less Than" 0.5 and "Subtract" from 1 into the Principled BSDF's
    Alpha (the set-up Blender's exporter writes as alphaMode MASK), its colour into Base Color,
    Specular IOR Level 0; under a 300 W point light, so the holes show the floor and let light
    through to it."""
    scene = reset()
    floor()
    mat = principled("leaf")
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = alpha_checker_image(os.path.join(bpy.app.tempdir, "leaf.png"))
    texture.interpolation = "Linear"
    texture.extension = "REPEAT"
    less = nodes.new("ShaderNodeMath")
    less.operation = "LESS_THAN"
    less.inputs[1].default_value = 0.5
    one_minus = nodes.new("ShaderNodeMath")
    one_minus.operation = "SUBTRACT"
    one_minus.inputs[0].default_value = 1.0
    bsdf = nodes["Principled BSDF"]
    links.new(texture.outputs["Color"], bsdf.inputs["Base Color"])
    links.new(texture.outputs["Alpha"], less.inputs[0])
    links.new(less.outputs["Value"], one_minus.inputs[1])
    links.new(one_minus.outputs["Value"], bsdf.inputs["Alpha"])
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.3, 1.0))
    bpy.context.object.data.materials.append(mat)
    light(scene, "POINT", 300.0, (0.3, 0.2, 2.5), shadow_soft_size=0.0)
    camera(scene)
    return scene


def scene_blend():
    """A 2 m square 1 m above the floor whose Principled BSDF has Alpha 0.4 (base colour 0.2,
    0.5, 0.8; Specular IOR Level 0), which Blender's exporter writes as alphaMode BLEND; under
    a 300 W point light: the camera sees the floor through it, and light reaches the floor
    through it, 60% of the time."""
    scene = reset()
    floor()
    mat = principled("veil", base=(0.2, 0.5, 0.8))
    mat.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.4
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.3, 1.0))
    bpy.context.object.data.materials.append(mat)
    light(scene, "POINT", 300.0, (0.3, 0.2, 2.5), shadow_soft_size=0.0)
    camera(scene)
    return scene


SCENES = {
    "point": scene_point,
    "spot": scene_spot,
    "sun": scene_sun,
    "emission": scene_emission,
    "mapping": scene_mapping,
    "colour": scene_colour,
    "glowing_wall": scene_glowing_wall,
    "cutout": scene_cutout,
    "blend": scene_blend,
    "rough_metal": scene_rough_metal,
    "coat": scene_coat,
    "sheen": scene_sheen,
}


def render(scene, seed, path):
    scene.cycles.seed = seed
    scene.cycles.samples = HALF_SPP
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.exr_codec = "ZIP"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)


def read_exr(path):
    """An image file's RGBA as Blender holds it (height x width x 4, bottom row first, float64);
    loaded afresh, not from Blender's cache of a path read before."""
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.array(image.pixels[:], dtype=np.float64).reshape(height, width, 4)
    bpy.data.images.remove(image)
    return pixels


def make(name, out_root):
    out = os.path.join(out_root, name)
    os.makedirs(out, exist_ok=True)
    scene = SCENES[name]()
    bpy.ops.export_scene.gltf(
        filepath=os.path.join(out, "scene.glb"),
        export_format="GLB",
        export_cameras=True,
        export_lights=True,
    )
    start = time.time()
    halves = []
    for seed, half in ((1, "a"), (2, "b")):
        path = os.path.join(out, f"cycles_half_{half}.exr")
        render(scene, seed, path)
        halves.append(read_exr(path))
    wall = time.time() - start
    mean = (halves[0] + halves[1]) / 2.0
    meta = {
        "scene": name,
        "blender": bpy.app.version_string,
        "spp": 2 * HALF_SPP,
        "halves": [{"seed": 1, "spp": HALF_SPP}, {"seed": 2, "spp": HALF_SPP}],
        "size": [WIDTH, HEIGHT],
        "render_wall_s": round(wall, 3),
        "mean_rgb": [float(mean[..., c].mean()) for c in range(3)],
        "doc": SCENES[name].__doc__,
    }
    with open(os.path.join(out, "meta.json"), "w") as f:
        json.dump(meta, f, indent=1)
    print(name, meta["mean_rgb"], f"{wall:.1f} s")


def main():
    argv = sys.argv[1:]
    if not argv:
        sys.exit(__doc__)
    out_root, names = argv[0], argv[1:] or list(SCENES)
    for name in names:
        make(name, out_root)


if __name__ == "__main__":
    main()
