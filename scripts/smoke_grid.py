#!/usr/bin/env python3
"""Writes scenes/smoke.vol, the density grid of scenes/cornell_smoke.toml: a 32 x 32 x 32 puff
of smoke (a soft ball whose density a few sines make lumpy, zero at its rim) in the box
(-0.7, 0.05, -0.7) to (0.7, 1.25, 0.7), as a Mitsuba .vol file (twinpath's grid format,
docs/media.md). Deterministic: the committed file is this script's output, byte for byte.

Usage: scripts/smoke_grid.py [OUT]   (default scenes/smoke.vol)
"""

import math
import os
import struct
import sys

N = 32
LO = (-0.7, 0.05, -0.7)
HI = (0.7, 1.25, 0.7)


def density(u, v, w):
    """The density at unit-box point (u, v, w): a ball of radius 0.48 about the centre,
    falling to zero at its rim, modulated by three products of sines."""
    x, y, z = u - 0.5, v - 0.5, w - 0.5
    r = math.sqrt(x * x + y * y + z * z) / 0.48
    if r >= 1.0:
        return 0.0
    lumps = (1.0 + 0.45 * math.sin(11.0 * u + 1.3) * math.sin(9.0 * v + 0.4)
             + 0.35 * math.sin(13.0 * w + 2.1) * math.sin(7.0 * u + 0.9)
             + 0.25 * math.sin(17.0 * v + 0.2) * math.sin(15.0 * w + 1.7))
    return max(0.0, (1.0 - r * r) * lumps)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "scenes", "smoke.vol")
    data = bytearray(b"VOL\x03")
    data += struct.pack("<5i", 1, N, N, N, 1)
    data += struct.pack("<6f", *LO, *HI)
    for k in range(N):
        for j in range(N):
            for i in range(N):
                data += struct.pack("<f", density((i + 0.5) / N, (j + 0.5) / N, (k + 0.5) / N))
    with open(out, "wb") as f:
        f.write(data)
    print(f"wrote {out} ({len(data)} bytes)")


if __name__ == "__main__":
    main()
