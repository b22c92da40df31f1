#!/usr/bin/env python3
# SPDX-License-Identifier: ISC
"""A PNG reader and a Radiance RGBE reader/writer of our own (zlib and struct
only), the peer the picture tests check the project's files against.

  pngpeer.py info FILE.png            width height depth colour, chunks, text
  pngpeer.py pixel FILE.png X Y       R G B of one pixel
  pngpeer.py uniq FILE.png X0 Y0 X1 Y1  the distinct colours in a rectangle
  pngpeer.py flat OUT.hdr W H R G B E [VIEW]   a flat-scanline RGBE picture of one pixel
  pngpeer.py stripes OUT.hdr E0 N     N grey pixels in a row, exponents E0..E0+N-1
  pngpeer.py hdrsum FILE.hdr          the sum of every pixel's decoded R (any scanline form)
"""
import signal
import struct
import sys
import zlib


def read_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise SystemExit(f'{path}: not a PNG signature')
    pos, chunks, idat, text = 8, [], b'', {}
    width = height = depth = ctype = None
    while pos < len(data):
        (n,) = struct.unpack('>I', data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        (crc,) = struct.unpack('>I', data[pos + 8 + n:pos + 12 + n])
        if zlib.crc32(kind + body) & 0xffffffff != crc:
            raise SystemExit(f'{path}: bad CRC in {kind!r}')
        chunks.append(kind.decode())
        if kind == b'IHDR':
            width, height, depth, ctype, comp, filt, inter = struct.unpack('>IIBBBBB', body)
            if (comp, filt, inter) != (0, 0, 0):
                raise SystemExit(f'{path}: unexpected IHDR {comp} {filt} {inter}')
        elif kind == b'IDAT':
            idat += body
        elif kind == b'tEXt':
            k, v = body.split(b'\0', 1)
            text[k.decode()] = v.decode('latin-1')
        elif kind == b'gAMA':
            text['(gAMA)'] = str(struct.unpack('>I', body)[0])
        pos += 12 + n
    if depth != 8 or ctype != 2:
        raise SystemExit(f'{path}: depth {depth} colour {ctype}, want 8-bit RGB')
    raw = zlib.decompress(idat)
    stride = width * 3
    rows, prev, at = [], bytearray(stride), 0
    for _ in range(height):
        f = raw[at]
        line = bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else b if pb <= pc else c
                line[i] = (line[i] + pr) & 255
            elif f != 0:
                raise SystemExit(f'{path}: filter {f}')
        rows.append(bytes(line))
        prev = line
    return width, height, chunks, text, rows


def write_hdr(path, width, height, pixel_of, view=None):
    with open(path, 'wb') as fp:
        fp.write(b'#?RADIANCE\n')
        if view:
            fp.write(f'VIEW= {view}\n'.encode())
        fp.write(f'FORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n'.encode())
        for y in range(height):
            for x in range(width):
                fp.write(bytes(pixel_of(x, y)))


def read_hdr_sum(path):
    data = open(path, 'rb').read()
    head, _, rest = data.partition(b'\n\n')
    res, _, body = rest.partition(b'\n')
    words = res.split()
    assert words[0] == b'-Y' and words[2] == b'+X', res
    height, width = int(words[1]), int(words[3])
    total, at = 0.0, 0
    for _ in range(height):
        if body[at] == 2 and body[at + 1] == 2 and (body[at + 2] << 8 | body[at + 3]) == width:
            at += 4
            planes = []
            for _c in range(4):
                plane = bytearray()
                while len(plane) < width:
                    n = body[at]
                    if n > 128:
                        plane += bytes([body[at + 1]]) * (n - 128)
                        at += 2
                    else:
                        plane += body[at + 1:at + 1 + n]
                        at += 1 + n
                planes.append(plane)
            pix = list(zip(*planes))
        else:
            pix = [tuple(body[at + 4 * i:at + 4 * i + 4]) for i in range(width)]
            at += 4 * width
        for r, _g, _b, e in pix:
            if e:
                total += (r + 0.5) * 2.0 ** (e - 136)
    return total


def main(argv):
    cmd = argv[1]
    if cmd == 'info':
        w, h, chunks, text, _ = read_png(argv[2])
        print(w, h, ' '.join(chunks))
        for k, v in text.items():
            print(f'{k}: {v}')
    elif cmd == 'pixel':
        w, h, _, _, rows = read_png(argv[2])
        x, y = int(argv[3]), int(argv[4])
        print(*rows[y][3 * x:3 * x + 3])
    elif cmd == 'uniq':
        _, _, _, _, rows = read_png(argv[2])
        x0, y0, x1, y1 = map(int, argv[3:7])
        seen = sorted({rows[y][3 * x:3 * x + 3] for y in range(y0, y1) for x in range(x0, x1)})
        for s in seen:
            print(*s)
    elif cmd == 'flat':
        w, h, r, g, b, e = map(int, argv[3:9])
        write_hdr(argv[2], w, h, lambda x, y: (r, g, b, e), argv[9] if len(argv) > 9 else None)
    elif cmd == 'stripes':
        e0, n = int(argv[3]), int(argv[4])
        write_hdr(argv[2], n, 1, lambda x, y: (128, 128, 128, e0 + x))
    elif cmd == 'hdrsum':
        print(repr(read_hdr_sum(argv[2])))
    else:
        raise SystemExit(__doc__)


if __name__ == '__main__':
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    main(sys.argv)
