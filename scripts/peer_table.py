#!/usr/bin/env python3
"""The one table of scripts/peer_table.sh: per scene, each renderer's seconds per sample, error
per sample and time to relMSE 0.002, and twinpath's ratios to the best peer.

Usage: scripts/peer_table.py OUTDIR SCENE...

Reads OUTDIR/SCENE/{bench/bench.csv, mitsuba_*.csv, cycles.csv, whole.csv, triangles}. For each
renderer (the variants of the CSVs):
- seconds per sample: render seconds per sample per pixel (full image, set-up left out) at the
  measurement nearest relMSE 0.002;
- error per sample: relMSE x spp there (Monte Carlo relMSE falls as 1/spp, so this is the
  relMSE one sample per pixel would have at that rate; lower is better);
- render to 0.002: their product over 0.002 (scripts/time_to_error.py's rule: the nearest
  measurement moved to the target at constant efficiency);
- whole process to 0.002: the wall time of one process as a user runs it (load, build,
  kernel compilation included) times its image's relMSE over 0.002.
The ratios divide twinpath's time by the best peer's (the smaller of the peers' times), render
and whole process apart. A peer whose whole-process image is another image (the z of its mean
difference from the reference beyond 4, the fourth column of whole.csv: Mitsuba's `ldsampler`,
docs/performance.md) is listed but is no peer: the best is chosen among the others. Plain
Python, no packages.
"""

import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from time_to_error import load, time_to  # noqa: E402

TARGET = 0.002


def short(name):
    """The renderer of a variant name: twinpath, mitsuba-SAMPLER or cycles."""
    if name.startswith("mitsuba"):
        return "mitsuba-" + ("ldsampler" if "ldsampler" in name else "independent")
    return "cycles" if name.startswith("cycles") else name


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__.splitlines()[2])
    out, scenes = sys.argv[1], sys.argv[2:]
    print("| scene | triangles | renderer | s per spp | error per spp | render to 0.002 | "
          "whole process to 0.002 |")
    print("|---|---|---|---|---|---|---|")
    summary = []
    for key in scenes:
        d = os.path.join(out, key)
        files = [os.path.join(d, "bench", "bench.csv")] + sorted(
            os.path.join(d, f) for f in os.listdir(d)
            if f.endswith(".csv") and f != "whole.csv")
        loaded = {short(k): v for k, v in load([f for f in files if os.path.exists(f)]).items()}
        # twinpath first, then the peers by name.
        variants = {k: loaded[k] for k in sorted(loaded, key=lambda k: (k != "twinpath", k))}
        whole, another_image = {}, set()
        if os.path.exists(os.path.join(d, "whole.csv")):
            with open(os.path.join(d, "whole.csv")) as f:
                # Rows written before the z column have three fields.
                for label, seconds, rel, *z in csv.reader(f):
                    whole[label] = float(seconds) * float(rel) / TARGET
                    if z and abs(float(z[0])) >= 4:
                        another_image.add(label)
        with open(os.path.join(d, "triangles")) as f:
            triangles = int(f.read())
        render = {}
        for name, points in variants.items():
            secs, spp, t, e = time_to(points, TARGET)
            render[name] = secs
            w = f"{whole[name]:.2f} s" if name in whole else "-"
            label = f"{name} (another image)" if name in another_image else name
            print(f"| {key} | {triangles} | {label} | {t / spp:.4f} s | {e * spp:.4f} | "
                  f"{secs:.2f} s | {w} |")
        peers = [n for n in render if n != "twinpath" and n not in another_image]
        best = min(peers, key=render.get)
        best_whole = min((n for n in peers if n in whole), key=whole.get, default=None)
        ratio_whole = (f"{whole['twinpath'] / whole[best_whole]:.2f} ({best_whole})"
                       if best_whole and "twinpath" in whole else "-")
        summary.append((key, triangles, f"{render['twinpath'] / render[best]:.2f} ({best})",
                        ratio_whole))
    print()
    print("| scene | triangles | twinpath / best peer, render | twinpath / best peer, whole process |")
    print("|---|---|---|---|")
    for key, triangles, ratio, ratio_whole in summary:
        print(f"| {key} | {triangles} | **{ratio}** | {ratio_whole} |")


if __name__ == "__main__":
    main()
