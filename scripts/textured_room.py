"""The textured glTF scene of issue 36's peer table (scripts/peer_table.sh's `textured`), built
in Blender through bpy the way a user builds one and exported by Blender's own glTF exporter:
twinpath renders the exported file, Cycles the Blender scene it came from.

A floor and a back wall of 8 m, a UV sphere (64 x 32, smooth-shaded) and a cube, each with an
image texture on its Principled BSDF's base colour (Specular IOR Level 0: Lambertian in both
renderers), under a 300 W point light and a warm 1 m emitter; the camera of
`cycles_fixtures.camera`. The textures hold only the bytes 0 and 255, which decode to exactly 0
and 1 as sRGB or linear: Cycles filters an image's bytes before decoding them and twinpath
decodes, then filters (docs/gltf.md), which agree on such texels, so the comparison measures the
renderers, not that choice. The images are read as linear in Blender, as the `mapping`
fixture's are.

Used by scripts/peer_cycles.py (`--scene textured`, with `--export-gltf PATH` to write the
file); Python 3.13 with `bpy` from PyPI.
"""

import math
import os

import bpy

from cycles_fixtures import camera, checker_image, light, png_image, principled

# Saturated colours only (see above).
PALETTE = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1)]


def stripes_image(path, size=16):
    """A `size` x `size` image of diagonal stripes three texels wide in four palette colours,
    written as PNG and loaded back."""
    colours = [PALETTE[3], PALETTE[0], PALETTE[3], PALETTE[2]]
    return png_image("stripes", size, lambda i, j: colours[((i + j) // 3) % 4], path)


def textured(name, image):
    """A Principled BSDF (Specular IOR Level 0) whose base colour is `image` through the
    object's UV map, filtered linearly and repeated, its bytes read as linear values."""
    mat = principled(name)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.interpolation = "Linear"
    texture.extension = "REPEAT"
    image.colorspace_settings.name = "Linear Rec.709"
    links.new(texture.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def build(scene):
    """The scene's objects, lights and camera, added to `scene` (a new one with the caller's
    render settings: `peer_cycles.settings`)."""
    checker = checker_image(os.path.join(bpy.app.tempdir, "checker.png"))
    stripes = stripes_image(os.path.join(bpy.app.tempdir, "stripes.png"))
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, 0.0))
    bpy.context.object.data.materials.append(textured("floor", checker))
    bpy.ops.mesh.primitive_plane_add(
        size=8.0, location=(0.0, 2.0, 4.0), rotation=(math.pi / 2, 0.0, 0.0)
    )
    bpy.context.object.data.materials.append(textured("wall", stripes))
    bpy.ops.mesh.primitive_uv_sphere_add(
        segments=64, ring_count=32, radius=0.6, location=(-0.7, 0.3, 0.6)
    )
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(textured("ball", checker))
    bpy.ops.mesh.primitive_cube_add(
        size=0.8, location=(0.8, -0.2, 0.4), rotation=(0.0, 0.0, math.radians(25.0))
    )
    bpy.context.object.data.materials.append(textured("box", stripes))
    light(scene, "POINT", 300.0, (0.3, -0.5, 2.5), shadow_soft_size=0.0)
    bpy.ops.mesh.primitive_plane_add(
        size=1.0, location=(-1.5, 0.5, 2.2), rotation=(math.pi, 0.0, 0.0)
    )
    bpy.context.object.data.materials.append(
        principled("lamp", base=(0.0, 0.0, 0.0), emission=((1.0, 0.8, 0.6), 5.0))
    )
    camera(scene)
    return scene


def export(path):
    """The current scene as glTF binary, with its camera and lights (the exporter's defaults
    otherwise), as `cycles_fixtures.make` exports its fixtures."""
    bpy.ops.export_scene.gltf(
        filepath=path, export_format="GLB", export_cameras=True, export_lights=True
    )
