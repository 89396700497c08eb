# Blender's own displacement route, timed: bake the sculpt's positions onto the base's
# Catmull-Clark limit surface with Cycles (selected to active), one 64x64-texel grid cell of UV
# per base face. Run by bench/peers/run as
#   blender -b --factory-startup --python blender_bake.py -- BASE SCULPT OUT.exr CELL EXTRUSION THREADS
# Prints one JSON line: import and bake seconds, texels, texels the bake did not reach.
import json
import math
import sys
import time

import bpy
import numpy as np

base_path, sculpt_path, out_path, cell, extrusion, threads = sys.argv[sys.argv.index("--") + 1:]
cell, extrusion, threads = int(cell), float(extrusion), int(threads)
SENTINEL = 1.0e30

bpy.ops.wm.read_factory_settings(use_empty=True)
clock = time.perf_counter()
# The same axis conversion for both meshes keeps them aligned; faces keep the file's order.
bpy.ops.wm.obj_import(filepath=base_path)
base = bpy.context.selected_objects[0]
bpy.ops.wm.obj_import(filepath=sculpt_path)
sculpt = bpy.context.selected_objects[0]
t_import = time.perf_counter() - clock

# One grid cell of cell x cell texels per base face: corner k of a quad at the cell's corner k.
faces = len(base.data.polygons)
if any(p.loop_total != 4 for p in base.data.polygons):
    sys.exit("blender_bake.py: the base must be all quads")
per_row = math.ceil(math.sqrt(faces))
size = per_row * cell
uv = base.data.uv_layers.new(name="cells").data
corners = [(0, 0), (1, 0), (1, 1), (0, 1)]
for p in base.data.polygons:
    x, y = p.index % per_row, p.index // per_row
    for k, loop in enumerate(p.loop_indices):
        cx, cy = corners[k]
        uv[loop].uv = ((x + cx) / per_row, (y + cy) / per_row)

subsurf = base.modifiers.new("subdivision", "SUBSURF")
subsurf.subdivision_type = "CATMULL_CLARK"
subsurf.levels = subsurf.render_levels = 3
subsurf.use_limit_surface = True
subsurf.uv_smooth = "NONE"

image = bpy.data.images.new("position", size, size, float_buffer=True, alpha=True)
image.pixels.foreach_set(np.full(size * size * 4, SENTINEL, dtype=np.float32))
target = bpy.data.materials.new("target")
target.use_nodes = True
node = target.node_tree.nodes.new("ShaderNodeTexImage")
node.image = image
target.node_tree.nodes.active = node
base.data.materials.append(target)

emit = bpy.data.materials.new("position")
emit.use_nodes = True
tree = emit.node_tree
tree.nodes.clear()
geometry = tree.nodes.new("ShaderNodeNewGeometry")
emission = tree.nodes.new("ShaderNodeEmission")
output = tree.nodes.new("ShaderNodeOutputMaterial")
tree.links.new(geometry.outputs["Position"], emission.inputs["Color"])
tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
sculpt.data.materials.append(emit)

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.cycles.max_bounces = 0
scene.cycles.use_denoising = False
scene.cycles.use_auto_tile = False
scene.render.threads_mode = "FIXED"
scene.render.threads = threads
scene.render.bake.margin = 0

bpy.ops.object.select_all(action="DESELECT")
sculpt.select_set(True)
base.select_set(True)
bpy.context.view_layer.objects.active = base
clock = time.perf_counter()
bpy.ops.object.bake(type="EMIT", use_selected_to_active=True, cage_extrusion=extrusion,
                    max_ray_distance=2 * extrusion, margin=0, use_clear=False)
t_bake = time.perf_counter() - clock

pixels = np.empty(size * size * 4, dtype=np.float32)
image.pixels.foreach_get(pixels)
rgb = pixels.reshape(size, size, 4)[:, :, :3]
inside = np.zeros((size, size), dtype=bool)  # texels of cells that belong to a face
for f in range(faces):
    x, y = f % per_row, f // per_row
    inside[y * cell:(y + 1) * cell, x * cell:(x + 1) * cell] = True
unreached = int(np.count_nonzero(inside & (rgb[:, :, 0] >= SENTINEL)))
image.filepath_raw = out_path
image.file_format = "OPEN_EXR"
image.save()
print("BAKE " + json.dumps({"faces": faces, "texels": faces * cell * cell, "unreached": unreached,
                            "t_import": t_import, "t_bake": t_bake}), flush=True)
