#!/usr/bin/env python3
"""Tiles PNG images into one contact sheet: contact_sheet.py OUT.png IN1.png IN2.png ... [--columns N].

Reads 8-bit RGB/RGBA PNGs (any filter) with the standard library and numpy, writes through eyerender's atomic
PNG writer. For looking at renders side by side (docs, reviews)."""
import argparse
import struct
import zlib

import numpy as np


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", chunk[:10])
            if depth != 8 or color not in (2, 6):
                raise SystemExit(f"{path}: only 8-bit RGB or RGBA PNGs")
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    bpp = 3 if color == 2 else 4
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), np.int32)
    prev = np.zeros(stride, np.int32)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        cur = np.zeros(stride, np.int32)
        if kind in (0, 2):
            cur = (line + (prev if kind == 2 else 0)) & 255
        else:
            for x in range(stride):  # Sub, Average, Paeth depend on the left neighbour: sequential
                a = cur[x - bpp] if x >= bpp else 0
                b, c = prev[x], (prev[x - bpp] if x >= bpp else 0)
                if kind == 1:
                    pred = a
                elif kind == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (line[x] + pred) & 255
        out[y], prev = cur, cur
    return out.reshape(height, width, bpp)[:, :, :3].astype(np.uint8)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("output")
    parser.add_argument("inputs", nargs="+")
    parser.add_argument("--columns", type=int, default=0, help="images per row (default: all in one row)")
    args = parser.parse_args()
    images = [read_png(p) for p in args.inputs]
    columns = args.columns or len(images)
    height = max(i.shape[0] for i in images)
    width = max(i.shape[1] for i in images)
    rows = (len(images) + columns - 1) // columns
    sheet = np.zeros((rows * height, columns * width, 3), np.uint8)
    for k, image in enumerate(images):
        r, c = divmod(k, columns)
        sheet[r * height:r * height + image.shape[0], c * width:c * width + image.shape[1]] = image
    import eyerender

    # The writer takes linear values and sRGB-encodes them: decode first so the sheet keeps the inputs' pixels.
    v = sheet / 255.0
    linear = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4).astype(np.float32)
    eyerender.write_png_preview(args.output, np.ascontiguousarray(linear))


if __name__ == "__main__":
    main()
