#!/usr/bin/env python3
"""Time each variant of `twinpath bench` / `scripts/peer_mitsuba.py` CSVs needs to reach a relMSE.

Usage: scripts/time_to_error.py [--target E]... [--baseline VARIANT] FILE.csv...

For every variant and sample count it averages render time and relMSE over the seeds, takes the
sample count whose relMSE is nearest the target (in ratio), and moves it to the target at
constant efficiency: time = render_s x relMSE / target (Monte Carlo error falls as 1/time; the
nearest point keeps that extrapolation short). Ratios are against --baseline (default: the first
variant whose name starts with "mitsuba"). Plain Python, no packages.
"""

import argparse
import csv
import math
from collections import defaultdict


def load(paths):
    """{variant: {spp: (mean render_s, mean relmse)}} over the seeds, variants in file order."""
    sums = defaultdict(lambda: defaultdict(lambda: [0.0, 0.0, 0]))
    order = []
    for path in paths:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                name = row["variant"]
                if name not in sums:
                    order.append(name)
                point = sums[name][int(row["spp"])]
                point[0] += float(row["render_s"])
                point[1] += float(row["relmse"])
                point[2] += 1
    return {
        name: {spp: (t / n, e / n) for spp, (t, e, n) in sorted(sums[name].items())}
        for name in order
    }


def time_to(points, target):
    """(seconds at the target, the spp, render_s and relmse of the point it came from)."""
    spp, (t, e) = min(points.items(), key=lambda kv: abs(math.log(kv[1][1] / target)))
    return t * e / target, spp, t, e


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--target", type=float, action="append")
    ap.add_argument("--baseline")
    args = ap.parse_args()
    targets = args.target or [0.0075, 0.002]
    variants = load(args.csv)
    baseline = args.baseline or next((v for v in variants if v.startswith("mitsuba")), None)
    if baseline is not None and baseline not in variants:
        raise SystemExit(f"--baseline {baseline}: no such variant in {', '.join(variants)}")
    for target in targets:
        print(f"relMSE {target}:")
        base = time_to(variants[baseline], target)[0] if baseline else None
        for name, points in variants.items():
            secs, spp, t, e = time_to(points, target)
            ratio = f", {secs / base:.2f}x {baseline}" if base else ""
            print(f"  {name:40s} {secs:7.2f} s (from {spp} spp: {t:.2f} s, relMSE {e:.5f}){ratio}")


if __name__ == "__main__":
    main()
