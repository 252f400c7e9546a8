"""The numbers of scenes/cornell.toml (tests/reference/cornell_spheres/scene.md) and of the gold
of scenes/cornell_materials.toml, once, for the peers that rebuild the scene in their own
formats (peer_mitsuba.py through mi.load_dict, peer_cycles.py through bpy). Twinpath's frame:
right-handed, y up. Plain Python."""

# Diffuse reflectances.
WHITE, RED, GREEN, BLUE = (0.73, 0.73, 0.73), (0.65, 0.05, 0.05), (0.12, 0.45, 0.15), \
    (0.25, 0.35, 0.75)
# The walls as scenes/cornell.toml writes them: (name, corner, edge1, edge2, material); the
# quad's corners are corner, + edge1, + edge1 + edge2, + edge2, its front normal edge1 x edge2.
WALLS = [
    ("floor", (-1, 0, 1), (2, 0, 0), (0, 0, -2), "white"),
    ("ceiling", (-1, 2, -1), (2, 0, 0), (0, 0, 2), "white"),
    ("back", (-1, 0, -1), (2, 0, 0), (0, 2, 0), "white"),
    ("left", (-1, 0, 1), (0, 0, -2), (0, 2, 0), "red"),
    ("right", (1, 0, -1), (0, 0, 2), (0, 2, 0), "green"),
]
# The two spheres: (name, center, radius, material).
SPHERES = [
    ("sphere_left", (-0.45, 0.4, -0.3), 0.4, "white"),
    ("sphere_right", (0.5, 0.3, 0.35), 0.3, "blue"),
]
# The light: a sphere of radiance 10 that reflects nothing.
LIGHT_CENTER, LIGHT_RADIUS, LIGHT_RADIANCE = (0.0, 1.6, 0.0), 0.3, 10.0
# The camera: eye, look-at, up, full vertical field of view in degrees; the image's size.
EYE, LOOK_AT, UP, VFOV = (0.0, 1.0, 3.8), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), 40.0
WIDTH = HEIGHT = 256
# scenes/cornell_materials.toml's "gold": Mitsuba's RGB eta and k of Au (as twinpath's named
# metal), GGX alpha 0.2.
GOLD_ETA = (0.143036, 0.375307, 1.44205)
GOLD_K = (3.983, 2.38556, 1.60336)
GOLD_ALPHA = 0.2
