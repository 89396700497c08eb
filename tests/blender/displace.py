# Runs inside Blender (blender -b --factory-startup --python displace.py -- ARGS): displaces a
# base cage with a dispex UV-space map the way a Blender user would, and writes the evaluated
# mesh as OBJ for `dispex verify --displaced`.
#
#   displace.py -- BASE.obj MAP.<UDIM>.exr OUT.obj [--levels L] [--direction normal|rgb]
#                  [--wrong KIND[,KIND...] --work DIR]
#
# The chain (docs/UV_MAPS.md): the cage built as it is in the OBJ (vertex and corner order
# kept, UVs per corner), a Subdivision Surface modifier (Catmull-Clark, L levels, limit
# surface on, quality 6, UV Smooth: None = OpenSubdiv's linear face-varying UVs, boundary
# corners kept sharp as OpenSubdiv's default edge-and-corner rule does), then a Displace
# modifier reading the UDIM tiles as one tiled image through the UVs (direction: normal, mid
# level 0, strength 1, texture clamping off so that negative values displace inward, bilinear
# interpolation, no mipmaps, tiles extended at their borders). `--direction rgb` reads an
# object-space vector map: Displace "RGB to XYZ" in local space, the tiles' R, G, B being x, y, z.
# --wrong: after OUT, the same object displaced by each map made wrong on purpose (its tiles
# saved under DIR/KIND/, the mesh written to DIR/KIND.obj), the texture's image swapped and
# nothing else changed: zero (every texel 0), x0.8 (every value scaled by 0.8), sign (negated),
# flip-v (rows upside down), transpose (u and v swapped within each tile), swap-tiles (each
# tile holding the next one's texels), swap-rg (a vector map's x and y exchanged); `copy`
# re-saves it as it is (the control: the same path of saving and loading, with the map right).
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


WRONG_KINDS = ("zero", "x0.8", "sign", "flip-v", "transpose", "swap-tiles", "swap-rg", "copy")


def wrong_map(pattern, kind, work):
    """The tiles made wrong, saved as EXR under `work`; returns the new pattern. (Python arrays
    and slices: Blender's Python may not find NumPy.)"""
    import os
    from array import array
    if kind not in WRONG_KINDS:
        sys.exit("displace.py: --wrong " + ", ".join(WRONG_KINDS))
    os.makedirs(work, exist_ok=True)
    tiles = tile_paths(pattern)
    for t, (udim, path) in enumerate(tiles):
        if kind == "swap-tiles":  # each tile holds the next one's texels
            path = tiles[(t + 1) % len(tiles)][1]
        img = bpy.data.images.load(path)
        n = img.size[0]
        row = 4 * n  # RGBA texels, row j (v up) at row * j
        px = array("f", bytes(4 * row * n))
        img.pixels.foreach_get(px)
        out = array("f", px)
        if kind == "zero":
            for c in range(3):
                out[c::4] = array("f", bytes(4 * n * n))
        elif kind in ("x0.8", "sign"):
            scale = 0.8 if kind == "x0.8" else -1.0
            out = array("f", (v * scale for v in px))
            out[3::4] = px[3::4]  # alpha kept
        elif kind == "flip-v":
            for j in range(n):
                out[j * row:(j + 1) * row] = px[(n - 1 - j) * row:(n - j) * row]
        elif kind == "transpose":  # texel (i, j) from (j, i)
            for j in range(n):
                for c in range(4):
                    out[j * row + c:(j + 1) * row:4] = px[4 * j + c::row]
        elif kind == "swap-rg":
            out[0::4], out[1::4] = px[1::4], px[0::4]
        new = bpy.data.images.new("wrong%d" % udim, n, n, alpha=True, float_buffer=True)
        new.colorspace_settings.name = "Non-Color"  # else saving encodes the values as sRGB
        new.pixels.foreach_set(out)
        new.filepath_raw = os.path.join(work, "wrong.%d.exr" % udim)
        new.file_format = "OPEN_EXR"
        new.save()
        bpy.data.images.remove(img)
        bpy.data.images.remove(new)
    return os.path.join(work, "wrong.<UDIM>.exr")


def load_tiles(pattern):
    """The UDIM tiles as one tiled image, read as data (no colour transform)."""
    tiles = tile_paths(pattern)
    if not tiles:
        sys.exit("displace.py: no tiles " + pattern)
    img = bpy.data.images.load(tiles[0][1])
    img.source = "TILED"
    img.colorspace_settings.name = "Non-Color"
    return img


def write_wrong(obj, texture, pattern, kinds, work, what):
    """For each kind: `texture` reading the map made wrong, `obj` written to WORK/KIND.obj."""
    import os
    for kind in kinds:
        wrong = wrong_map(pattern, kind, os.path.join(work, kind))
        texture.image = load_tiles(wrong)
        write_evaluated(obj, os.path.join(work, kind + ".obj"), "%s, the map made wrong: %s" % (
            what, kind))
        print("displace.py: %s -> %s" % (kind, os.path.join(work, kind + ".obj")))


def main():
    (base, pattern, out), opts = parse_args(sys.argv)
    kinds = [k for k in opts["wrong"].split(",") if k and k != "none"]
    if kinds and not opts["work"]:
        sys.exit("displace.py: --wrong needs --work DIR")
    img = load_tiles(pattern)
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

    what = "%s displaced in Blender %s by %s" % (base, bpy.app.version_string, pattern)
    write_evaluated(obj, out, what)
    print("displace.py: %d tiles -> %s" % (len(tile_paths(pattern)), out))
    write_wrong(obj, tex, pattern, kinds, opts["work"], what)


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
