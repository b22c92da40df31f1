#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""Count a PNG's pixels near each colour given (r,g,b 0-255, within 40 per
channel): pngcolours.py FILE R,G,B ...  prints one count a line; with
--columns first, the share (%) of the picture's columns holding the colour;
with --at first, FILE X,Y ... prints each pixel's r,g,b.  A plain
decoder (zlib and the five PNG filters) for 8-bit RGB or RGBA, not
interlaced, as cairo writes them: the tests need no imaging library."""
import struct
import sys
import zlib


def pixels(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        sys.exit('%s: not a PNG' % path)
    pos, idat, w = 8, b'', 0
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype, _, _, lace = struct.unpack('>IIBBBBB', body)
            if depth != 8 or ctype not in (2, 6) or lace:
                sys.exit('%s: not 8-bit RGB(A), or interlaced' % path)
            bpp = 3 if ctype == 2 else 4
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    raw, stride, prev, out = zlib.decompress(idat), w * bpp, bytearray(w * bpp), []
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out.append(line)
        prev = line
    return out, w, bpp


args = sys.argv[1:]
if args[0] == '--at':
    rows, w, bpp = pixels(args[1])
    for spec in args[2:]:
        x, y = (int(v) for v in spec.split(','))
        print(','.join(str(v) for v in rows[y][x * bpp:x * bpp + 3]))
    sys.exit(0)
columns = args[0] == '--columns'
if columns:
    args = args[1:]
rows, w, bpp = pixels(args[0])
for spec in args[1:]:
    want = [int(v) for v in spec.split(',')]
    n, cols = 0, set()
    for line in rows:
        for x in range(w):
            p = line[x * bpp:x * bpp + 3]
            if all(abs(p[k] - want[k]) <= 40 for k in range(3)):
                n += 1
                cols.add(x)
    print(round(100 * len(cols) / w) if columns else n)
