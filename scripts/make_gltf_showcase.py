#!/usr/bin/env python3
"""Writes scenes/gltf/showcase.glb (pure Python, no dependencies; the output is committed): a
glTF 2.0 binary scene made to show what twinpath reads from glTF files:
  - a floor with a checker base colour texture (metallic 0, roughness 0.7), texture
    coordinates repeating it 16 x 16 (sampler REPEAT), and a normal map bevelling each square's
    edges (tangent space, green up; no TANGENT attribute, so the renderer derives the frame);
  - a UV sphere (64 x 32, smooth normals) whose base colour and metallic-roughness maps run in
    bands: polished gold metal (metallic 1, roughness 0.2) and blue dielectric (metallic 0,
    roughness 0.5), so one object is partly metallic;
  - a rough copper-coloured metal box placed by a rotated, scaled node;
  - a warm KHR_lights_punctual spot light above, and a perspective camera.
scenes/gltf_showcase.toml includes it under the HDR sky scenes/sky.hdr.
Usage: scripts/make_gltf_showcase.py [OUT.glb]"""
import json, math, os, struct, sys, zlib

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    os.path.dirname(__file__), "..", "scenes", "gltf", "showcase.glb")
os.makedirs(os.path.dirname(out), exist_ok=True)


def png(width, height, texel):
    """An 8-bit RGB PNG (bytes) of texel(i, j) -> (r, g, b), row 0 at the top."""
    raw = b"".join(
        b"\x00" + bytes(c for i in range(width) for c in texel(i, j)) for j in range(height))
    chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data
                                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


doc = {"asset": {"version": "2.0", "generator": "twinpath scripts/make_gltf_showcase.py"},
       "extensionsUsed": ["KHR_lights_punctual"],
       "buffers": [{"byteLength": 0}], "bufferViews": [], "accessors": [], "images": [],
       "textures": [], "samplers": [{"wrapS": 10497, "wrapT": 10497}], "materials": [],
       "meshes": [], "nodes": [], "cameras": [], "scenes": [{"nodes": []}], "scene": 0}
blob = bytearray()


def view(data):
    while len(blob) % 4:
        blob.append(0)
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    blob.extend(data)
    return len(doc["bufferViews"]) - 1


def accessor(values, kind, minmax=False):
    width = {"VEC2": 2, "VEC3": 3}[kind]
    flat = [x for v in values for x in v]
    a = {"bufferView": view(struct.pack("<%df" % len(flat), *flat)), "componentType": 5126,
         "count": len(values), "type": kind}
    if minmax:
        a["min"] = [min(v[k] for v in values) for k in range(width)]
        a["max"] = [max(v[k] for v in values) for k in range(width)]
    doc["accessors"].append(a)
    return len(doc["accessors"]) - 1


def indices(values):
    doc["accessors"].append({"bufferView": view(struct.pack("<%dI" % len(values), *values)),
                             "componentType": 5125, "count": len(values), "type": "SCALAR"})
    return len(doc["accessors"]) - 1


def texture(data):
    doc["images"].append({"bufferView": view(data), "mimeType": "image/png"})
    doc["textures"].append({"source": len(doc["images"]) - 1, "sampler": 0})
    return len(doc["textures"]) - 1


def material(name, pbr):
    doc["materials"].append({"name": name, "pbrMetallicRoughness": pbr})
    return len(doc["materials"]) - 1


def mesh(name, positions, normals, uvs, tris, mat):
    attributes = {"POSITION": accessor(positions, "VEC3", True), "NORMAL": accessor(normals, "VEC3")}
    if uvs is not None:
        attributes["TEXCOORD_0"] = accessor(uvs, "VEC2")
    doc["meshes"].append({"name": name, "primitives": [
        {"attributes": attributes, "indices": indices(tris), "material": mat}]})
    return len(doc["meshes"]) - 1


def node(**fields):
    doc["nodes"].append(fields)
    return len(doc["nodes"]) - 1


# Textures: the floor's checker; the sphere's bands (base colour, and metallic in blue with
# roughness in green).
checker = texture(png(64, 64, lambda i, j: (220, 210, 190) if (i // 8 + j // 8) % 2 == 0 else (80, 70, 60)))
band = lambda j: (j // 8) % 2 == 0
stripes = texture(png(8, 64, lambda i, j: (255, 200, 90) if band(j) else (40, 90, 200)))
stripes_mr = texture(png(8, 64, lambda i, j: (0, 51, 255) if band(j) else (0, 128, 0)))



def bevel(i, j):
    """The tangent-space normal of texel (i, j) of a square of 8 x 8 texels bevelled at its
    edges: tilted away from the square's centre on its outer texels (x right, y up the image,
    so row 0 of the square is its top edge), encoded as glTF's (n + 1) / 2 in bytes."""
    x = -0.6 if i % 8 == 0 else 0.6 if i % 8 == 7 else 0.0
    y = 0.6 if j % 8 == 0 else -0.6 if j % 8 == 7 else 0.0
    n = math.sqrt(x * x + y * y + 1.0)
    return tuple(round(255 * (c / n + 1) / 2) for c in (x, y, 1.0))


bevels = texture(png(64, 64, bevel))
floor_mat = material("floor", {"baseColorTexture": {"index": checker}, "metallicFactor": 0.0,
                               "roughnessFactor": 0.7})
doc["materials"][floor_mat]["normalTexture"] = {"index": bevels}
sphere_mat = material("banded", {"baseColorTexture": {"index": stripes},
                                 "metallicRoughnessTexture": {"index": stripes_mr}})
box_mat = material("copper", {"baseColorFactor": [0.95, 0.64, 0.54, 1.0], "metallicFactor": 1.0,
                              "roughnessFactor": 0.35})

# Floor: 24 x 24 at y = 0, uv 0..16 (the checker repeated: squares of 0.1875).
s = 12.0
floor = mesh("floor", [[-s, 0, s], [s, 0, s], [s, 0, -s], [-s, 0, -s]], [[0, 1, 0]] * 4,
             [[0, 0], [16, 0], [16, 16], [0, 16]], [0, 1, 2, 0, 2, 3], floor_mat)

# UV sphere, radius 0.5: rings j = 0..32 (v from the top), segments i = 0..64.
pos, nrm, uv, tri = [], [], [], []
rings, segs = 32, 64
for j in range(rings + 1):
    th = math.pi * j / rings
    for i in range(segs + 1):
        ph = 2 * math.pi * i / segs
        n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
        pos.append([0.5 * c for c in n])
        nrm.append(n)
        uv.append([i / segs, j / rings])
for j in range(rings):
    for i in range(segs):
        a, b = j * (segs + 1) + i, (j + 1) * (segs + 1) + i
        # Counter-clockwise seen from outside.
        if j > 0:
            tri += [a, b, a + 1]
        if j < rings - 1:
            tri += [a + 1, b, b + 1]
sphere = mesh("banded sphere", pos, nrm, uv, tri, sphere_mat)

# A unit box (flat faces: 24 vertices).
bp, bn, bt = [], [], []
for axis in range(3):
    for sign in (1, -1):
        n = [0, 0, 0]
        n[axis] = sign
        u = [0, 0, 0]
        u[(axis + 1) % 3] = 1
        v = [0, 0, 0]
        v[(axis + 2) % 3] = 1
        if sign < 0:
            u, v = v, u
        base = len(bp)
        for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            bp.append([0.5 * (n[k] + du * u[k] + dv * v[k]) for k in range(3)])
            bn.append(n)
        bt += [base, base + 1, base + 2, base, base + 2, base + 3]
box = mesh("box", bp, bn, None, bt, box_mat)

# Spot light straight down from y = 3 (a node's -z, rotated -90 degrees about x): 6 W/sr, in
# the extension's candela (x 683 lm/W, as Blender's exporter writes them).
h = math.sqrt(0.5)
doc["extensions"] = {"KHR_lights_punctual": {"lights": [
    {"type": "spot", "name": "warm spot", "color": [1.0, 0.85, 0.6], "intensity": 6.0 * 683,
     "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}}]}}
doc["cameras"].append({"name": "front", "type": "perspective",
                       "perspective": {"yfov": 0.7, "aspectRatio": 4 / 3, "znear": 0.05}})
yaw = math.radians(0.0)
roots = [
    node(name="floor", mesh=floor),
    node(name="sphere", mesh=sphere, translation=[-0.4, 0.5, 0.0]),
    node(name="box", mesh=box, translation=[0.65, 0.3, 0.2], scale=[0.6, 0.6, 0.6],
         rotation=[0.0, math.sin(math.radians(20)), 0.0, math.cos(math.radians(20))]),
    node(name="spot", translation=[0.0, 3.0, 0.0], rotation=[-h, 0.0, 0.0, h],
         extensions={"KHR_lights_punctual": {"light": 0}}),
    # The camera at (0, 1.1, 3) looking slightly down (-12 degrees about x).
    node(name="camera", camera=0, translation=[0.0, 1.1, 3.0],
         rotation=[math.sin(math.radians(-6)), 0.0, 0.0, math.cos(math.radians(-6))]),
]
doc["scenes"][0]["nodes"] = roots
while len(blob) % 4:
    blob.append(0)
doc["buffers"][0]["byteLength"] = len(blob)
js = json.dumps(doc, separators=(",", ":")).encode()
js += b" " * (-len(js) % 4)
total = 12 + 8 + len(js) + 8 + len(blob)
with open(out, "wb") as fh:
    fh.write(b"glTF" + struct.pack("<II", 2, total))
    fh.write(struct.pack("<I", len(js)) + b"JSON" + js)
    fh.write(struct.pack("<I", len(blob)) + b"BIN\x00" + bytes(blob))
print(f"wrote {out} ({total} bytes)")
