#!/usr/bin/env python3
"""Mitsuba 3's `cuda_ad_rgb` for a lent GPU machine that reaches no package registry, small
enough to travel in .gpu/ (the device tool carries 64 MiB in all): the files of the mitsuba and
drjit wheels (downloaded into WHEELS by scripts/gpu_machine_prepare.sh for each CPython
version named, e.g. 312: the lent H200's python3 is 3.12) unpacked into OUT/pyXY/, each an
import path for that version, keeping only the variants cuda_ad_rgb and scalar_rgb, the plugins
that scripts/mitsuba_scenes.py's scenes instantiate, and no headers, stubs or spectral data. The
wheels are built per version, so their libraries differ; files that are the same across versions
are hard links, which tar stores once.

Usage: mitsuba_gpu_bundle.py WHEELS OUT VERSION...
"""

import glob
import hashlib
import os
import shutil
import sys
import zipfile

VARIANT_MODULES = {"mitsuba_ext", "mitsuba_alias", "cuda_ad_rgb", "scalar_rgb"}
# What the four Cornell scenes' dictionaries instantiate, directly or by default.
PLUGINS = set("""path volpath volpathmis diffuse twosided roughconductor dielectric rectangle
sphere ply obj merge area perspective hdrfilm box independent ldsampler multijitter stratified
homogeneous heterogeneous constvolume gridvolume hg isotropic uniform srgb d65 regular bitmap
""".split())
DROPPED_DIRS = {"include", "cmake", "pkgconfig", "mitsuba_stubs"}


def wanted(name):
    """Whether a wheel member is needed to render the scenes with cuda_ad_rgb."""
    parts = name.split("/")
    if name.endswith("/") or ".dist-info/" in name or name.endswith(".pyi"):
        return False
    if len(parts) > 2 and parts[1] in DROPPED_DIRS:
        return False
    if name.startswith(("mitsuba/python/test/", "mitsuba/data/sunsky")) or \
            name.endswith("srgb.coeff"):
        return False
    if len(parts) > 2 and parts[1] == "plugins":
        return parts[2].removesuffix(".so") in PLUGINS
    if parts[0] == "mitsuba" and ".cpython-" in parts[-1]:
        return parts[-1].split(".")[0] in VARIANT_MODULES
    return True


def main():
    wheels, out, versions = sys.argv[1], sys.argv[2], sys.argv[3:]
    shutil.rmtree(out, ignore_errors=True)
    first = {}
    for v in versions:
        found = sorted(glob.glob(os.path.join(wheels, f"mitsuba-*-cp{v}-*.whl")) +
                       glob.glob(os.path.join(wheels, f"drjit-*-cp{v}-*.whl")))
        if len(found) != 2:
            sys.exit(f"expected the mitsuba and drjit wheels for CPython {v} in {wheels}")
        if v == "310":  # Dr.Jit needs typing_extensions before Python 3.11
            found += glob.glob(os.path.join(wheels, "typing_extensions-*.whl"))
        for wheel in found:
            z = zipfile.ZipFile(wheel)
            for member in z.infolist():
                if not wanted(member.filename):
                    continue
                data = z.read(member)
                dst = os.path.join(out, f"py{v}", member.filename)
                os.makedirs(os.path.dirname(dst), exist_ok=True)
                key = hashlib.sha256(data).hexdigest()
                if key in first:
                    os.link(first[key], dst)
                    continue
                with open(dst, "wb") as f:
                    f.write(data)
                first[key] = dst
                if member.external_attr >> 16 & 0o111:
                    os.chmod(dst, 0o755)


if __name__ == "__main__":
    main()
