#!/usr/bin/env python3
"""Writes an equirectangular HDR sky (Radiance RGBE .hdr) in twinpath's map convention
(kernel/src/environment.rs): row 0 looks straight up (+y), column 0 along +x, columns turning
toward +z. A blue gradient above the horizon, a brown ground below it, and a small sun disk.
Pure Python, no dependencies.

    python3 scripts/make_sky.py scenes/sky.hdr [--width 512] [--height 256]
        [--sun-elevation 35] [--sun-azimuth 60] [--sun-radius 2.5] [--sun-radiance 4000]
"""

import argparse
import math
import struct


def sky_radiance(d, sun, sun_cos, sun_radiance):
    """Linear RGB radiance arriving from unit direction d = (x, y, z)."""
    x, y, z = d
    if y >= 0.0:
        # Deep blue overhead, pale at the horizon.
        t = math.sqrt(y)
        rgb = [0.85 - 0.55 * t, 0.95 - 0.45 * t, 1.1 - 0.2 * t]
        rgb = [c * 1.2 for c in rgb]
    else:
        rgb = [0.25, 0.2, 0.15]
    if x * sun[0] + y * sun[1] + z * sun[2] >= sun_cos:
        rgb = [sun_radiance, 0.95 * sun_radiance, 0.85 * sun_radiance]
    return rgb


def rgbe(rgb):
    """Radiance's shared-exponent encoding of one linear RGB value."""
    v = max(rgb)
    if v < 1e-32:
        return bytes([0, 0, 0, 0])
    mantissa, exponent = math.frexp(v)
    scale = mantissa * 256.0 / v
    return bytes([min(255, int(c * scale)) for c in rgb] + [exponent + 128])


def rle_scanline(pixels):
    """One scanline in the run-length format: a header, then each channel as literal runs."""
    width = len(pixels)
    out = bytearray([2, 2, width >> 8, width & 0xFF])
    for channel in range(4):
        values = bytes(p[channel] for p in pixels)
        for start in range(0, width, 128):
            chunk = values[start:start + 128]
            out.append(len(chunk))
            out.extend(chunk)
    return bytes(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out")
    parser.add_argument("--width", type=int, default=512)
    parser.add_argument("--height", type=int, default=256)
    parser.add_argument("--sun-elevation", type=float, default=35.0, help="degrees above the horizon")
    parser.add_argument("--sun-azimuth", type=float, default=60.0, help="degrees from +x toward +z")
    parser.add_argument("--sun-radius", type=float, default=2.5, help="angular radius, degrees")
    parser.add_argument("--sun-radiance", type=float, default=4000.0)
    args = parser.parse_args()
    if not 8 <= args.width <= 32767:
        parser.error("width must be within 8..32767 (the run-length format's range)")

    el, az = math.radians(args.sun_elevation), math.radians(args.sun_azimuth)
    sun = (math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az))
    sun_cos = math.cos(math.radians(args.sun_radius))
    with open(args.out, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {args.height} +X {args.width}\n".encode())
        for j in range(args.height):
            theta = math.pi * (j + 0.5) / args.height
            row = []
            for i in range(args.width):
                phi = 2.0 * math.pi * (i + 0.5) / args.width
                d = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
                row.append(rgbe(sky_radiance(d, sun, sun_cos, args.sun_radiance)))
            f.write(rle_scanline(row))


if __name__ == "__main__":
    main()
