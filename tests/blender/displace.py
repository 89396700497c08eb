# Runs inside Blender (blender -b --factory-startup --python displace.py -- ARGS): displaces a
# base cage with a dispex UV-space map the way a Blender user would, and writes the evaluated
# mesh as OBJ for `dispex verify --displaced`.
#
#   displace.py -- BASE.obj MAP.<UDIM>.exr OUT.obj [--levels L] [--direction normal|rgb]
#                  [--wrong KIND --work DIR]
#
# The chain (docs/UV_MAPS.md): the cage built as it is in the OBJ (vertex and corner order
# kept, UVs per corner), a Subdivision Surface modifier (Catmull-Clark, L levels, limit
# surface on, quality 6, UV Smooth: None = OpenSubdiv's linear face-varying UVs, boundary
# corners kept sharp as OpenSubdiv's default edge-and-corner rule does), then a Displace
# modifier reading the UDIM tiles as one tiled image through the UVs (direction: normal, mid
# level 0, strength 1, texture clamping off so that negative values displace inward, bilinear
# interpolation, no mipmaps, tiles extended at their borders). `--direction rgb` reads an
# object-space vector map: Displace "RGB to XYZ" in local space, the tiles' R, G, B being x, y, z.
# --wrong makes the map wrong on purpose before it is read: zero (every texel 0), flip-v
# (rows upside down), transpose (u and v swapped within each tile), swap-tiles (each tile
# holding the next one's texels), swap-rg (a vector map's x and y exchanged); `copy` re-saves it
# as it is
# (the control: the same path of saving and loading, with the map right).
import sys

import bpy


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    opts = {"levels": 4, "wrong": "none", "work": None, "direction": "normal"}
    pos = []
    i = 0
    while i < len(args):
        if args[i] in ("--levels", "--wrong", "--work", "--direction"):
            opts[args[i][2:]] = args[i + 1]
            i += 2
        else:
            pos.append(args[i])
            i += 1
    if len(pos) != 3:
        sys.exit("displace.py: BASE.obj MAP.<UDIM>.exr OUT.obj expected")
    opts["levels"] = int(opts["levels"])
    return pos, opts


def read_obj(path):
    verts, uvs, faces, face_uvs = [], [], [], []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                verts.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "vt":
                uvs.append((float(t[1]), float(t[2])))
            elif t[0] == "f":
                corners = [c.split("/") for c in t[1:]]
                faces.append([int(c[0]) - 1 for c in corners])
                if all(len(c) > 1 and c[1] for c in corners):
                    face_uvs.append([int(c[1]) - 1 for c in corners])
    return verts, uvs, faces, face_uvs


def build_object(path, name="base"):
    verts, uvs, faces, face_uvs = read_obj(path)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    if face_uvs and len(face_uvs) == len(faces):
        layer = mesh.uv_layers.new(name="UVMap")
        loop = 0
        for poly_uvs in face_uvs:
            for k in poly_uvs:
                layer.data[loop].uv = uvs[k]
                loop += 1
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def tile_paths(pattern):
    import glob
    import re
    prefix = pattern[: pattern.index("<UDIM>")]
    found = []
    for p in sorted(glob.glob(prefix + "[0-9][0-9][0-9][0-9].exr")):
        m = re.match(re.escape(prefix) + r"(\d{4})\.exr$", p)
        if m:
            found.append((int(m.group(1)), p))
    return found


def wrong_map(pattern, kind, work):
    """The tiles made wrong, saved as EXR under `work`; returns the new pattern."""
    import os
    os.makedirs(work, exist_ok=True)
    tiles = tile_paths(pattern)
    for t, (udim, path) in enumerate(tiles):
        if kind == "swap-tiles":  # each tile holds the next one's texels
            path = tiles[(t + 1) % len(tiles)][1]
        img = bpy.data.images.load(path)
        n = img.size[0]
        px = list(img.pixels[:])
        out = [0.0] * len(px)
        for j in range(n):
            for i in range(n):
                if kind == "zero":
                    src = None
                elif kind in ("copy", "swap-tiles"):
                    src = j * n + i
                elif kind == "flip-v":
                    src = (n - 1 - j) * n + i
                elif kind == "transpose":
                    src = i * n + j
                elif kind == "swap-rg":
                    src = j * n + i
                else:
                    sys.exit("displace.py: --wrong zero, flip-v, transpose, swap-tiles, swap-rg "
                             "or copy")
                d = 4 * (j * n + i)
                if src is None:
                    out[d:d + 4] = [0.0, 0.0, 0.0, 1.0]
                elif kind == "swap-rg":
                    r, g, b, a = px[4 * src:4 * src + 4]
                    out[d:d + 4] = [g, r, b, a]
                else:
                    out[d:d + 4] = px[4 * src:4 * src + 4]
        new = bpy.data.images.new("wrong%d" % udim, n, n, alpha=True, float_buffer=True)
        new.colorspace_settings.name = "Non-Color"  # else saving encodes the values as sRGB
        new.pixels[:] = out
        new.filepath_raw = os.path.join(work, "wrong.%d.exr" % udim)
        new.file_format = "OPEN_EXR"
        new.save()
    return os.path.join(work, "wrong.<UDIM>.exr")


def main():
    (base, pattern, out), opts = parse_args(sys.argv)
    if opts["wrong"] != "none":
        pattern = wrong_map(pattern, opts["wrong"], opts["work"])
    tiles = tile_paths(pattern)
    if not tiles:
        sys.exit("displace.py: no tiles " + pattern)
    obj = build_object(base)

    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.subdivision_type = "CATMULL_CLARK"
    sub.levels = opts["levels"]
    sub.render_levels = opts["levels"]
    sub.use_limit_surface = True
    sub.quality = 6
    sub.uv_smooth = "NONE"
    sub.boundary_smooth = "PRESERVE_CORNERS"
    sub.use_creases = True

    img = bpy.data.images.load(tiles[0][1])
    img.source = "TILED"
    img.colorspace_settings.name = "Non-Color"
    tex = bpy.data.textures.new("dispex", "IMAGE")
    tex.image = img
    tex.use_interpolation = True
    tex.use_mipmap = False
    tex.filter_type = "BOX"
    tex.use_clamp = False
    tex.extension = "EXTEND"

    disp = obj.modifiers.new("Displace", "DISPLACE")
    disp.texture = tex
    disp.texture_coords = "UV"
    disp.uv_layer = "UVMap"
    if opts["direction"] not in ("normal", "rgb"):
        sys.exit("displace.py: --direction normal or rgb")
    disp.direction = "NORMAL" if opts["direction"] == "normal" else "RGB_TO_XYZ"
    disp.space = "LOCAL"
    disp.mid_level = 0.0
    disp.strength = 1.0

    write_evaluated(obj, out, "%s displaced in Blender %s by %s" % (
        base, bpy.app.version_string, pattern))
    print("displace.py: %d tiles -> %s" % (len(tiles), out))


def write_evaluated(obj, out, comment):
    """The object with its modifiers applied, as OBJ."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    with open(out, "w") as f:
        f.write("# %s\n" % comment)
        f.write("".join("v %.9g %.9g %.9g\n" % tuple(v.co) for v in mesh.vertices))
        f.write("".join("f " + " ".join(str(i + 1) for i in p.vertices) + "\n"
                        for p in mesh.polygons))
    evaluated.to_mesh_clear()


if __name__ == "__main__":
    main()
