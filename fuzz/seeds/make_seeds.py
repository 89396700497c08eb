#!/usr/bin/env python3
"""Writes the hand-made seed files of fuzz/seeds/ (see README.md there).

The seeds reach reader paths that the files of tests/data/ do not: binary PLY files with
every value type, both byte orders, lists in the vertex element and extra elements, and a
Ptex file with edit blocks. Run from anywhere: python3 fuzz/seeds/make_seeds.py
"""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)


def ply_ascii():
    lines = ["ply", "format ascii 1.0", "comment a cube with normals, colours and edges",
             "obj_info made by fuzz/seeds/make_seeds.py", "element material 1",
             "property uchar r", "property list uchar float weights",
             "element vertex 8", "property float x", "property float y", "property float z",
             "property float nx", "property float ny", "property float nz",
             "property uchar red", "property uchar green", "property uchar blue",
             "element face 6", "property list uchar int vertex_indices", "property int flags",
             "element edge 2", "property int vertex1", "property int vertex2", "end_header",
             "255 2 0.5 0.25"]
    for x, y, z in CUBE_V:
        lines.append(f"{x} {y} {z} {x - 0.5:g} {y - 0.5:g} {z - 0.5:g} {x * 255} 128 0")
    for f in CUBE_F:
        lines.append(f"4 {' '.join(map(str, f))} 7")
    lines += ["0 1", "6 7"]
    return ("\n".join(lines) + "\n").encode()


def ply_binary_le():
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex 8\n"
            "property double x\nproperty double y\nproperty double z\nproperty uchar flag\n"
            "element face 7\nproperty list uchar uint vertex_indices\nproperty short tag\n"
            "end_header\n").encode()
    body = b"".join(struct.pack("<dddB", x, y, z, 1) for x, y, z in CUBE_V)
    faces = CUBE_F[:5] + [(3, 0, 4), (3, 4, 7)]
    body += b"".join(struct.pack("<B%dIh" % len(f), len(f), *f, -1) for f in faces)
    return head + body


def ply_binary_be_vertex_list():
    head = ("ply\nformat binary_big_endian 1.0\ncomment a list inside the vertex element\n"
            "element vertex 5\nproperty float x\nproperty list uchar float extra\n"
            "property int16 y\nproperty float32 z\n"
            "element face 2\nproperty list ushort short vertex_index\nend_header\n").encode()
    verts = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (1, 1, 1)]
    body = b""
    for i, (x, y, z) in enumerate(verts):
        extra = [0.5] * (i % 3)
        body += struct.pack(">fB%dfhf" % len(extra), x, len(extra), *extra, y, z)
    for f in [(0, 1, 4), (1, 2, 3, 4, 0)]:
        body += struct.pack(">H%dh" % len(f), len(f), *f)
    return head + body


def ptex_with_edits():
    """quad_float1.ptx (reference writer) plus a meta data edit and two face edits."""
    src = open(os.path.join(ROOT, "tests/data/ptex/quad_float1.ptx"), "rb").read()
    header = struct.unpack("<IIIIiHHIIIIIIQII", src[:64])
    ext_size, face_info_zip = header[8], header[9]
    assert ext_size == 40, "the seed expects the 40-byte extended header"
    face_info = zlib.decompress(src[64 + ext_size:64 + ext_size + face_info_zip])

    def block(kind, body):
        return struct.pack("<BI", kind, len(body)) + body

    records = b"\x07edited\x00" + struct.pack("<BI", 0, 4) + b"yes\x00"
    records += b"\x06scale\x00" + struct.pack("<BI", 5, 16) + struct.pack("<dd", 0.5, 2.0)
    zipped = zlib.compress(records)
    edits = block(1, struct.pack("<II", len(zipped), len(records)) + zipped)

    # Face 1 becomes 2x2 texels (zipped block), face 2 a constant face.
    info = bytearray(face_info[20:40])
    info[0], info[1] = 1, 1
    texels = struct.pack("<4f", 1.0, 2.0, 3.0, 4.0)
    data = zlib.compress(texels)
    fdh = len(data) | (1 << 30)
    edits += block(0, struct.pack("<I", 1) + bytes(info) + struct.pack("<If", fdh, 2.5) + data)
    info = bytearray(face_info[40:60])
    info[3] |= 1  # constant
    edits += block(0, struct.pack("<I", 2) + bytes(info) + struct.pack("<If", 0, -1.5))

    # The file has no meta data, so its writer left out the 8-byte barrier that readers
    # always skip (guide section 2): add it, then the edits right after it.
    barrier = bytes(8)
    out = bytearray(src + barrier + edits)
    edit_pos = len(src) + len(barrier)
    struct.pack_into("<QQ", out, 64 + 24, len(edits), edit_pos)  # editdatasize, editdatapos
    return bytes(out)


def main():
    write(os.path.join(HERE, "ply/cube_ascii_extra_elements.ply"), ply_ascii())
    write(os.path.join(HERE, "ply/cube_binary_le_double.ply"), ply_binary_le())
    write(os.path.join(HERE, "ply/pyramid_binary_be_vertex_list.ply"), ply_binary_be_vertex_list())
    write(os.path.join(HERE, "ptex/quad_float1_edits.ptx"), ptex_with_edits())


if __name__ == "__main__":
    main()
