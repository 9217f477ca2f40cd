"""Small equirectangular HDR images for the Blender tests, without numpy or OpenImageIO.

write_hdr(path, width, height, texel) writes a Radiance .hdr file (flat, not run-length
encoded, 32-bit RGBE scanlines, top row first as the format stores it) whose pixel (x, y),
y = 0 the TOP row, is texel(x, y) -> (r, g, b) with finite values >= 0. RGBE keeps 8 bits of
mantissa per channel relative to the pixel's largest one (about 1 % precision); values below
1e-32 become 0. Blender and hairis both read it through OpenImageIO.

In Cycles' equirectangular mapping, x = 0 .. width-1 runs from the -X direction at the left
edge through -Y, +X (the image centre) and +Y back to -X; the top row looks at +Z.

Inside Blender, an image can also be made directly:
    img = bpy.data.images.new("env", width, height, float_buffer=True)
    img.pixels.foreach_set(rgba_floats_bottom_row_first)
    img.filepath_raw = path; img.file_format = "OPEN_EXR"; img.save()
"""

import math


def _rgbe(r, g, b):
    m = max(r, g, b)
    if not (m >= 1e-32):
        return bytes((0, 0, 0, 0))
    f, e = math.frexp(m)  # m = f * 2**e, f in [0.5, 1)
    scale = f * 256.0 / m
    return bytes((int(r * scale), int(g * scale), int(b * scale), e + 128))


def write_hdr(path, width, height, texel):
    """Writes texel(x, y) for x < width, y < height (y = 0 the top row) to path."""
    if width < 1 or height < 1:
        raise ValueError("width and height must be >= 1")
    rows = []
    for y in range(height):
        row = bytearray()
        for x in range(width):
            r, g, b = (float(c) for c in texel(x, y))
            if not all(math.isfinite(c) and c >= 0.0 for c in (r, g, b)):
                raise ValueError("pixel (%d, %d) must be finite and >= 0" % (x, y))
            row += _rgbe(r, g, b)
        rows.append(bytes(row))
    header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (height, width)
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        for row in rows:
            f.write(row)


def sky_world(width=64, height=32, sun=(44, 9), sun_value=(60.0, 55.0, 45.0)):
    """texel(x, y) of a blue sky brightening towards the zenith, a brown ground and a 2 × 2
    "sun" of ``sun_value`` whose top-left texel is ``sun`` (x, y from the top)."""
    def texel(x, y):
        if sun[0] <= x <= sun[0] + 1 and sun[1] <= y <= sun[1] + 1:
            return sun_value
        elevation = 0.5 - (y + 0.5) / height  # +0.5 at the zenith, -0.5 at the nadir
        if elevation < 0.0:
            return (0.08, 0.06, 0.04)
        return (0.25 + 0.3 * elevation, 0.35 + 0.4 * elevation, 0.6 + 0.5 * elevation)
    return texel


def spot_world(width=64, height=32, spot=(40, 12), spot_value=50.0, background=0.05):
    """texel(x, y) of a dim grey world with one bright texel at `spot` (x, y from the top)."""
    def texel(x, y):
        v = spot_value if (x, y) == tuple(spot) else background
        return (v, v, v)
    return texel


if __name__ == "__main__":
    import sys
    write_hdr(sys.argv[1] if len(sys.argv) > 1 else "spot.hdr", 64, 32, spot_world())
