#!/usr/bin/env python3
"""A wrong copy of a Ptex map, for the negative controls of scripts/accuracy.sh and bench/run.

    scripts/scale-ptex.py IN OUT S

Writes the Ptex map IN with every texel (level 0, reductions, constant values, tiles)
multiplied by S (0: the zero map, -1: the sign flipped), float or half; face records, adjacency
and meta data kept (docs/ptex.md, "The file format", gives the layout).
"""
import struct, sys, zlib
src, dst, scale = sys.argv[1], sys.argv[2], float(sys.argv[3])
b = open(src, "rb").read()
head = bytearray(b[:64])  # sizes: extended header, face info, constant data, level info
dtype, nlev, ext, fiz, cz, lis = (struct.unpack_from("<I", b, 12)[0],
                                  struct.unpack_from("<H", b, 22)[0],
                                  *struct.unpack_from("<4I", b, 28))
code, size = {2: ("e", 2), 3: ("f", 4)}[dtype]  # half, float
xh = bytearray(b[64:64 + ext])
if ext >= 32 and struct.unpack_from("<Q", xh, 24)[0]:
    sys.exit("scale-ptex.py: %s has edit blocks" % src)


def values(raw):
    n = len(raw) // size
    return struct.pack("<%d%s" % (n, code), *(v * scale for v in struct.unpack(
        "<%d%s" % (n, code), raw)))


def blocks(data, fdhs):  # the blocks after a header of face data headers, rewritten
    out, at, headers = [], 0, []
    for fdh in fdhs:
        n, enc = fdh & 0x3FFFFFFF, fdh >> 30
        block = data[at:at + n]
        at += n
        if n and enc == 0:  # constant
            block = values(block)
        elif n and enc == 1:  # zipped
            block = zlib.compress(values(zlib.decompress(block)))
        elif n and enc == 3:  # tiled: u8 u8 tile log2s, u32 header size, header, tiles
            hz = struct.unpack_from("<I", block, 2)[0]
            raw = zlib.decompress(block[6:6 + hz])
            th, tiles = blocks(block[6 + hz:], struct.unpack("<%dI" % (len(raw) // 4), raw))
            th = zlib.compress(th)
            block = block[:2] + struct.pack("<I", len(th)) + th + tiles
        elif n:
            sys.exit("scale-ptex.py: %s: encoding %d" % (src, enc))
        headers.append(len(block) | enc << 30)
        out.append(block)
    return struct.pack("<%dI" % len(headers), *headers), b"".join(out)


pos = 64 + ext + fiz
const = zlib.compress(values(zlib.decompress(b[pos:pos + cz])))
pos += cz
level_infos = [struct.unpack_from("<QII", b, pos + 16 * l) for l in range(nlev)]
pos += lis
infos, levels = b"", b""
for level_size, hz, entries in level_infos:
    h, data = blocks(b[pos + hz:pos + level_size],
                     struct.unpack("<%dI" % entries, zlib.decompress(b[pos:pos + hz])))
    h = zlib.compress(h)
    infos += struct.pack("<QII", len(h) + len(data), len(h), entries)
    levels += h + data
    pos += level_size
rest = b[pos:]  # meta data, kept
struct.pack_into("<I", head, 36, len(const))
struct.pack_into("<Q", head, 48, len(levels))
size = 64 + ext + fiz + len(const) + lis + len(levels) + len(rest)
if ext >= 40 and struct.unpack_from("<Q", xh, 32)[0]:  # editdatapos: the end of the file
    struct.pack_into("<Q", xh, 32, size)
open(dst, "wb").write(head + xh + b[64 + ext:64 + ext + fiz] + const + infos + levels + rest)
