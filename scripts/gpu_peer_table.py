#!/usr/bin/env python3
"""The GPU peer table of a lent machine's run (scripts/gpu_machine_check.sh, issue 36): twinpath's
GPU backend against Mitsuba 3 `cuda_ad_rgb` on the Cornell scenes, time to the same error.

Reads DIR (the run's peer.tar.gz unpacked, with the run's log.txt copied into it):
twinpath_SCENE.exr with twinpath_SCENE.txt (its report, whose
"render S s" is the render's time), and mitsuba_SCENE_SAMPLER.exr with the lines of
scripts/peer_mitsuba_gpu.py in DIR/log.txt. Measures each image's relMSE against
tests/reference/<scene>/mitsuba_ref.exr with `twinpath diff`, and, since past the first samples
relMSE falls as 1 / samples (unbiased estimators, variance only), the time to relMSE 0.002 as
seconds x relMSE / 0.002. Prints a Markdown table; the ratio is each time to that of the fastest
Mitsuba configuration of the scene whose image agrees with the reference (`twinpath diff`'s z of
the mean difference within 4: a peer that renders another image is not a peer).

Usage: gpu_peer_table.py DIR [--twinpath target/debug/twinpath]
"""

import argparse
import os
import re
import subprocess

from gpu_peer_scenes import scenes

REFERENCE = {name: reference for name, (reference, _) in scenes().items()}
TARGET = 0.002
Z_AGREE = 4.0


def diff(twinpath, image, scene):
    """(relMSE, z of the mean difference) of `image` against the scene's converged reference."""
    ref = os.path.join("tests", "reference", REFERENCE[scene], "mitsuba_ref.exr")
    out = subprocess.run([twinpath, "diff", image, ref], capture_output=True, text=True,
                         check=True).stdout
    values = dict(line.split() for line in out.splitlines() if line.strip())
    return float(values["relmse"]), float(values["mean_diff_z"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--twinpath", default="target/debug/twinpath")
    args = ap.parse_args()
    rows = {}
    for name in REFERENCE:
        report = os.path.join(args.dir, f"twinpath_{name}.txt")
        if os.path.exists(report):
            m = re.search(r"render ([0-9.]+) s", open(report).read())
            if m:
                rows.setdefault(name, []).append(("twinpath gpu", f"twinpath_{name}.exr",
                                                  float(m.group(1))))
    log = os.path.join(args.dir, "log.txt")
    for line in open(log) if os.path.exists(log) else []:
        m = re.match(r"mitsuba (\S+) (\S+) spp (\d+) seconds ([0-9.]+)", line)
        if m:
            name, sampler, _, seconds = m.groups()
            rows.setdefault(name, []).append((f"mitsuba cuda_ad_rgb {sampler}",
                                              f"mitsuba_{name}_{sampler}.exr", float(seconds)))
    print("| scene | renderer | render s | relMSE | z of the mean difference "
          "| time to relMSE 0.002, s | / best Mitsuba |")
    print("|---|---|---|---|---|---|---|")
    for name, entries in rows.items():
        measured = []
        for label, image, seconds in entries:
            rel, z = diff(args.twinpath, os.path.join(args.dir, image), name)
            measured.append((label, seconds, rel, z, seconds * rel / TARGET))
        peers = [m[4] for m in measured if m[0].startswith("mitsuba") and abs(m[3]) < Z_AGREE]
        best = min(peers) if peers else None
        for label, seconds, rel, z, to_target in measured:
            ratio = f"{to_target / best:.2f}x" if best else ""
            if abs(z) >= Z_AGREE:
                ratio += " (another image)"
            print(f"| {name} | {label} | {seconds:.3f} | {rel:.3e} | {z:+.1f} "
                  f"| {to_target:.3f} | {ratio} |")


if __name__ == "__main__":
    main()
