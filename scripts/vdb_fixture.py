#!/usr/bin/env python3
"""Writes tests/fixtures/grid_ramp.vdb, the OpenVDB file tests/tests/media_grids.rs reads: a
float grid named "density" written by the OpenVDB library Blender ships (the `openvdb` module
inside the `bpy` wheel), so that twinpath's reader is checked against files made the way
Blender makes them. Its voxels: index (i, j, k) for i in -2..4, j in 1..6, k in 3..7 holds
0.1 + 0.01 i + 0.02 j + 0.03 k; the aligned block 8..16 x 0..8 x 0..8 is filled with 0.5 (the
library stores it as one tile, not 512 voxels); the transform is voxel size 0.1 and translation
(0.3, -0.2, 0.5) (a voxel's centre in world space is 0.1 (i, j, k) + translation).

Usage: target/cycles-venv/bin/python scripts/vdb_fixture.py [OUT]   (scripts/cycles_venv.sh
makes the virtualenv)
"""

import os
import sys

import bpy  # noqa: F401  (puts Blender's bundled Python modules, openvdb among them, on the path)

# bpy/<version>/scripts/modules/bpy/__init__.py -> bpy/<version>/python/lib/python3.X/site-packages
_version_dir = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(bpy.__file__))))
sys.path.insert(0, os.path.join(_version_dir, "python", "lib",
                                f"python{sys.version_info.major}.{sys.version_info.minor}",
                                "site-packages"))
import openvdb as vdb  # noqa: E402


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "tests", "fixtures", "grid_ramp.vdb")
    grid = vdb.FloatGrid()
    grid.name = "density"
    acc = grid.getAccessor()
    for i in range(-2, 4):
        for j in range(1, 6):
            for k in range(3, 7):
                acc.setValueOn((i, j, k), 0.1 + 0.01 * i + 0.02 * j + 0.03 * k)
    grid.fill((8, 0, 0), (15, 7, 7), 0.5, True)
    grid.transform = vdb.createLinearTransform(
        [[0.1, 0, 0, 0], [0, 0.1, 0, 0], [0, 0, 0.1, 0], [0.3, -0.2, 0.5, 1]])
    vdb.write(out, grids=[grid])
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
