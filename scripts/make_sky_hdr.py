#!/usr/bin/env python3
# make_sky_hdr.py — writes assets/env/sun-sky.hdr: a small equirectangular sky (256 x 128 texels,
# Radiance RGBE, uncompressed) with a gradient from a blue zenith to a pale horizon, a dim ground and
# a small warm sun, for the bundled scene sun-glass (docs/lighting.md). Standard library only;
# deterministic. Map convention: column u = 0.5 + atan2(z, x) / 2pi, row v = acos(y) / pi (y up).
"""Usage: python3 scripts/make_sky_hdr.py   (writes into the repository this script lives in)"""

import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "assets", "env", "sun-sky.hdr")
WIDTH, HEIGHT = 256, 128

SUN_DIR = (-0.8, 0.0, -0.4)      # azimuth (x, z) of the sun: left of and in front of a camera looking down -z
SUN_ELEVATION = 35.0             # degrees above the horizon
SUN_RADIUS = 2.0                 # degrees (the real sun: 0.27); larger so the map resolves it as a disc
SUN_RADIANCE = (3000.0, 2700.0, 2250.0)  # warm; its irradiance is a few times the sky's
ZENITH = (0.20, 0.38, 0.85)
HORIZON = (0.85, 0.88, 0.92)
GROUND = (0.12, 0.11, 0.10)


def sun_direction():
    e = math.radians(SUN_ELEVATION)
    x, _, z = SUN_DIR
    n = math.hypot(x, z)
    return (math.cos(e) * x / n, math.sin(e), math.cos(e) * z / n)


def radiance(d, sun):
    cos_sun = sum(a * b for a, b in zip(d, sun))
    if cos_sun >= math.cos(math.radians(SUN_RADIUS)):
        return SUN_RADIANCE
    y = d[1]
    if y < 0.0:
        return GROUND
    t = (1.0 - y) ** 3  # pale near the horizon, blue above
    glow = 0.6 * max(0.0, cos_sun) ** 24  # a soft brightening around the sun
    return tuple(z * (1.0 - t) + h * t + glow for z, h in zip(ZENITH, HORIZON))


def rgbe(c):
    m = max(c)
    if m < 1e-32:
        return bytes(4)
    mant, exp = math.frexp(m)
    s = mant * 256.0 / m
    return bytes([min(255, int(c[0] * s)), min(255, int(c[1] * s)), min(255, int(c[2] * s)), exp + 128])


def main():
    sun = sun_direction()
    rows = []
    for y in range(HEIGHT):
        theta = math.pi * (y + 0.5) / HEIGHT
        row = bytearray()
        for x in range(WIDTH):
            phi = 2.0 * math.pi * ((x + 0.5) / WIDTH - 0.5)
            d = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            row += rgbe(radiance(d, sun))
        rows.append(bytes(row))
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "wb") as f:
        f.write(b"#?RADIANCE\n# caustica scripts/make_sky_hdr.py\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(b"-Y %d +X %d\n" % (HEIGHT, WIDTH))
        for r in rows:
            f.write(r)
    print("wrote %s (%d bytes), sun direction (%.4f, %.4f, %.4f)" % (os.path.relpath(OUT, ROOT),
                                                                     os.path.getsize(OUT), *sun))


if __name__ == "__main__":
    main()
