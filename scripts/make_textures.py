#!/usr/bin/env python3
"""Writes the textures under scenes/textures/ (pure Python, no dependencies; the outputs are
committed):
  checker.png    64 x 64 sRGB colour map, 8 x 8 squares of 8 texels (a floor's kd)
  roughness.png  64 x 64 linear grey map, GGX alpha from 0.05 to 1 in 8 bands (alpha_map)
  emission.png   32 x 16 sRGB colour map, warm left half and cool right half (emission_map)
Usage: scripts/make_textures.py [OUT_DIR]"""
import os, struct, sys, zlib

out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "textures")
os.makedirs(out, exist_ok=True)


def png(path, width, height, texel):
    """An 8-bit RGB PNG of texel(i, j) -> (r, g, b) bytes, row 0 at the top."""
    raw = b"".join(
        b"\x00" + bytes(c for i in range(width) for c in texel(i, j)) for j in range(height)
    )
    chunk = lambda kind, data: (struct.pack(">I", len(data)) + kind + data
                                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    with open(path, "wb") as fh:
        fh.write(b"\x89PNG\r\n\x1a\n")
        fh.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        fh.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        fh.write(chunk(b"IEND", b""))


png(os.path.join(out, "checker.png"), 64, 64,
    lambda i, j: (225, 215, 190) if (i // 8 + j // 8) % 2 == 0 else (70, 50, 40))
png(os.path.join(out, "roughness.png"), 64, 64,
    lambda i, j: (round(255 * (0.05 + 0.95 * (i // 8) / 7)),) * 3)
png(os.path.join(out, "emission.png"), 32, 16,
    lambda i, j: (255, 170, 80) if i < 16 else (90, 160, 255))
