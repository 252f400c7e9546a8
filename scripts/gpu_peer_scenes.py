"""The GPU peer's scenes as the Python scripts read them (scripts/gpu_peer_scenes.txt, the one
list; scripts/gpu_machine_check.sh reads its first column)."""

import os

LIST = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gpu_peer_scenes.txt")


def scenes():
    """{name: (reference directory under tests/reference, builder in mitsuba_scenes.py)}."""
    out = {}
    for line in open(LIST):
        words = line.split("#", 1)[0].split()
        if words:
            name, reference, builder = words
            out[name] = (reference, builder)
    return out
