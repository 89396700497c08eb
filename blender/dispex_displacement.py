# dispex for Blender: "Extract Displacement" writes UV-space displacement maps (UDIM OpenEXR)
# of the active object (the base cage) from the selected sculpt with the dispex command line,
# and sets up the modifiers that displace the base with them: Subdivision Surface (limit
# surface, UV Smooth: None) and Displace (UV, normal, mid level 0, strength 1). With "Vector
# (object space)" the maps hold the whole vector sculpt - limit surface (the sculpt must be the
# base refined, as a Multires sculpt is) and Displace reads them "RGB to XYZ" in local space.
#
# Install: Edit > Preferences > Add-ons > Install..., pick this file, enable "dispex
# Displacement"; set the path of the dispex program in the add-on's preferences unless it is on
# PATH. Use: select the sculpt, then the base (active), and press "Extract Displacement" in the
# 3D view's sidebar (N), tab "dispex". Progress shows in the status bar; the maps land in the
# output folder as <base>.<UDIM>.exr beside <base>.ptx.
bl_info = {
    "name": "dispex Displacement",
    "author": "dispex",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D View > Sidebar > dispex",
    "description": "Extract displacement maps (UDIM OpenEXR) from a sculpt and apply them",
    "category": "Object",
}

import math
import os
import shutil
import subprocess
import tempfile
import time

import bpy


def write_obj(path, obj, to_local=None, with_uvs=False):
    """The object's mesh as OBJ in its own order (to_local: a matrix from its space to the
    base's); with_uvs: per-corner UVs of the active UV layer."""
    mesh = obj.data
    m = to_local
    with open(path, "w") as f:
        for v in mesh.vertices:
            co = m @ v.co if m is not None else v.co
            f.write("v %.9g %.9g %.9g\n" % (co.x, co.y, co.z))
        layer = mesh.uv_layers.active if with_uvs else None
        if layer is not None:
            for d in layer.data:
                f.write("vt %.9g %.9g\n" % (d.uv.x, d.uv.y))
        for p in mesh.polygons:
            if layer is not None:
                f.write("f " + " ".join("%d/%d" % (mesh.loops[l].vertex_index + 1, l + 1)
                                         for l in p.loop_indices) + "\n")
            else:
                f.write("f " + " ".join(str(i + 1) for i in p.vertices) + "\n")


def subdivision_levels(base, sculpt):
    """One level above the sculpt's density over the base, within 1..6."""
    ratio = max(1.0, len(sculpt.data.polygons) / max(1, len(base.data.polygons)))
    return max(1, min(6, int(math.ceil(math.log(ratio, 4))) + 1))


def apply_modifiers(base, pattern, levels, vector=False):
    for name in ("dispex Subdivision", "dispex Displace"):
        old = base.modifiers.get(name)
        if old is not None:
            base.modifiers.remove(old)
    sub = base.modifiers.new("dispex Subdivision", "SUBSURF")
    sub.subdivision_type = "CATMULL_CLARK"
    sub.levels = levels
    sub.render_levels = levels
    sub.use_limit_surface = True
    sub.quality = 6
    sub.uv_smooth = "NONE"
    sub.boundary_smooth = "PRESERVE_CORNERS"
    tiles = sorted(f for f in os.listdir(os.path.dirname(pattern))
                   if f.startswith(os.path.basename(pattern).split("<UDIM>")[0])
                   and f.endswith(".exr"))
    img = bpy.data.images.load(os.path.join(os.path.dirname(pattern), tiles[0]))
    img.source = "TILED"
    img.colorspace_settings.name = "Non-Color"
    tex = bpy.data.textures.new("dispex " + base.name, "IMAGE")
    tex.image = img
    tex.use_interpolation = True
    tex.use_mipmap = False
    tex.use_clamp = False  # negative values displace inward
    tex.extension = "EXTEND"
    disp = base.modifiers.new("dispex Displace", "DISPLACE")
    disp.texture = tex
    disp.texture_coords = "UV"
    disp.uv_layer = base.data.uv_layers.active.name
    disp.direction = "RGB_TO_XYZ" if vector else "NORMAL"
    disp.space = "LOCAL"
    disp.mid_level = 0.0
    disp.strength = 1.0


class DispexPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    executable: bpy.props.StringProperty(
        name="dispex program", subtype="FILE_PATH", default="",
        description="Path of the dispex command line (empty: found on PATH)")


class DispexSettings(bpy.types.PropertyGroup):
    output_dir: bpy.props.StringProperty(name="Output folder", subtype="DIR_PATH",
                                         default="//dispex_maps")
    resolution: bpy.props.IntProperty(name="Tile resolution", default=1024, min=16, max=16384)
    padding: bpy.props.IntProperty(name="Padding", default=16, min=0, max=256)
    half: bpy.props.BoolProperty(name="Half float", default=False)
    vector: bpy.props.BoolProperty(
        name="Vector (object space)", default=False,
        description="Maps of the whole displacement vector in object space, read by Displace "
                    "as RGB to XYZ; the sculpt must be the base refined (a Multires sculpt)")
    tolerance: bpy.props.FloatProperty(name="Tolerance (0: auto)", default=0.0, min=0.0,
                                       precision=6)


def dispex_program(context):
    prefs = context.preferences.addons[__name__].preferences if __name__ in \
        context.preferences.addons else None
    path = prefs.executable if prefs is not None and prefs.executable else ""
    return bpy.path.abspath(path) if path else shutil.which("dispex")


class DISPEX_OT_extract(bpy.types.Operator):
    """Extract displacement maps of the active object (the base) from the selected sculpt and
    displace the base with them"""
    bl_idname = "dispex.extract_displacement"
    bl_label = "Extract Displacement"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        base = context.active_object
        return (base is not None and base.type == "MESH" and
                any(o is not base and o.type == "MESH" for o in context.selected_objects))

    def execute(self, context):
        base = context.active_object
        sculpt = next(o for o in context.selected_objects if o is not base and o.type == "MESH")
        settings = context.scene.dispex
        program = dispex_program(context)
        if not program:
            self.report({"ERROR"}, "dispex: program not found (set it in the add-on's preferences)")
            return {"CANCELLED"}
        if not base.data.uv_layers:
            self.report({"ERROR"}, "dispex: %s has no UV map" % base.name)
            return {"CANCELLED"}
        out_dir = bpy.path.abspath(settings.output_dir)
        os.makedirs(out_dir, exist_ok=True)
        name = bpy.path.clean_name(base.name)
        work = tempfile.mkdtemp(prefix="dispex_")
        base_path = os.path.join(work, name + ".obj")
        sculpt_path = os.path.join(work, name + "_sculpt.obj")
        write_obj(base_path, base, with_uvs=True)
        write_obj(sculpt_path, sculpt, base.matrix_world.inverted() @ sculpt.matrix_world)
        cmd = [program, "extract", base_path, sculpt_path,
               "-o", os.path.join(out_dir, name + ".ptx"), "--uv-maps", out_dir,
               "--uv-resolution", str(settings.resolution), "--uv-padding", str(settings.padding),
               "--data-type", "half" if settings.half else "float"]
        if settings.vector:
            cmd += ["--vector", "object"]
        if settings.tolerance > 0:
            cmd += ["--tolerance", repr(settings.tolerance)]
        wm = context.window_manager
        wm.progress_begin(0, 100)
        status = context.workspace.status_text_set if context.workspace else (lambda t: None)
        status("dispex: extracting %s from %s ..." % (base.name, sculpt.name))
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        step = 0
        while proc.poll() is None:
            step = (step + 5) % 100
            wm.progress_update(step)
            time.sleep(0.1)
        out, err = proc.communicate()
        wm.progress_end()
        status(None)
        shutil.rmtree(work, ignore_errors=True)
        if proc.returncode != 0:
            self.report({"ERROR"}, (err.strip().splitlines() or ["dispex failed"])[-1])
            return {"CANCELLED"}
        apply_modifiers(base, os.path.join(out_dir, name + ".<UDIM>.exr"),
                        subdivision_levels(base, sculpt), settings.vector)
        self.report({"INFO"}, "dispex: maps in %s" % out_dir)
        return {"FINISHED"}


class DISPEX_PT_panel(bpy.types.Panel):
    bl_label = "dispex Displacement"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "dispex"

    def draw(self, context):
        s = context.scene.dispex
        col = self.layout.column()
        col.prop(s, "output_dir")
        col.prop(s, "resolution")
        col.prop(s, "padding")
        col.prop(s, "half")
        col.prop(s, "vector")
        col.prop(s, "tolerance")
        col.label(text="Select the sculpt, then the base (active)")
        col.operator(DISPEX_OT_extract.bl_idname)


classes = (DispexPreferences, DispexSettings, DISPEX_OT_extract, DISPEX_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.dispex = bpy.props.PointerProperty(type=DispexSettings)


def unregister():
    del bpy.types.Scene.dispex
    for c in reversed(classes):
        bpy.utils.unregister_class(c)


if __name__ == "__main__":
    register()
