#!/usr/bin/env python3
"""Rewrites attributes of a single-part scanline EXR header, for hand-made table_reader seeds
whose header claims what its data does not hold (e.g. a huge resolution in a tiny file).

Usage: exr_header.py [--offsets N] IN OUT name=type:value ...   (type: int, box2i
"x0,y0,x1,y1", floats "a,b,...", string). The offset table and chunks are copied as they are;
--offsets N first inserts N zero offsets, so that a header claiming many scanline chunks gets
past OpenEXR's end-of-file check on the offset table.
"""
import struct
import sys


def parse(data):
    pos, attrs = 8, []
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        pos = end + 1
        if not name:
            return attrs, pos
        end = data.index(b"\0", pos)
        kind = data[pos:end].decode()
        pos = end + 1
        (size,) = struct.unpack_from("<i", data, pos)
        pos += 4
        attrs.append([name, kind, data[pos:pos + size]])
        pos += size


def encode(kind, text):
    if kind == "int":
        return "int", struct.pack("<i", int(text))
    if kind == "box2i":
        return "box2i", struct.pack("<4i", *[int(v) for v in text.split(",")])
    if kind == "floats":
        values = [float(v) for v in text.split(",")]
        return "floatvector", struct.pack("<%df" % len(values), *values)
    return "string", text.encode()


def main():
    args = sys.argv[1:]
    offsets = 0
    if args[0] == "--offsets":
        offsets, args = int(args[1]), args[2:]
    src, dst, edits = args[0], args[1], args[2:]
    data = open(src, "rb").read()
    attrs, body = parse(data)
    for edit in edits:
        name, rest = edit.split("=", 1)
        kind, text = rest.split(":", 1)
        new_kind, value = encode(kind, text)
        for a in attrs:
            if a[0] == name:
                a[1], a[2] = new_kind, value
                break
        else:
            attrs.append([name, new_kind, value])
    out = bytearray(data[:8])
    for name, kind, value in attrs:
        out += name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value
    out += b"\0" + bytes(8 * offsets) + data[body:]
    open(dst, "wb").write(bytes(out))


if __name__ == "__main__":
    main()
