# Renders the demo asset in Blender (Cycles, CPU): Spot's limit surface, the same displaced by
# dispex's UV-space map through Blender's own modifiers (the add-on's set-up), and the sculpt.
# Run by scripts/make-images.sh:
#   blender -b --factory-startup --python scripts/blender-render.py -- \
#       BASE.obj MAPS/<name>.<UDIM>.exr SCULPT.obj OUT.png
import math
import os
import sys

import bpy

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(root, "blender"))
sys.path.insert(0, os.path.join(root, "tests", "blender"))
import dispex_displacement  # noqa: E402  (apply_modifiers: the add-on's modifiers)
import displace  # noqa: E402  (build_object: the OBJ as it is)

base_path, pattern, sculpt_path, out = sys.argv[sys.argv.index("--") + 1:]

scene = bpy.context.scene
for o in list(scene.objects):
    bpy.data.objects.remove(o)

material = bpy.data.materials.new("clay")
material.diffuse_color = (0.8, 0.75, 0.7, 1)
material.use_nodes = True
material.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.75, 0.7, 1)
material.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 0.6


def place(obj, x):
    obj.rotation_euler = (math.pi / 2, 0, math.pi / 2)  # OBJ's y up -> z up, side on
    obj.location = (x, 0, 0)
    obj.data.materials.append(material)
    for p in obj.data.polygons:
        p.use_smooth = True


limit = displace.build_object(base_path, "limit surface")
sub = limit.modifiers.new("Subdivision", "SUBSURF")
sub.levels = sub.render_levels = 5
sub.use_limit_surface = True
sub.uv_smooth = "NONE"
place(limit, -1.65)
displaced = displace.build_object(base_path, "displaced")
dispex_displacement.apply_modifiers(displaced, pattern, 5)
place(displaced, 0)
sculpt = displace.build_object(sculpt_path, "sculpt")
place(sculpt, 1.65)

# Objects side by side along x, 10% apart; the orthographic camera frames them all.
bpy.context.view_layer.update()
corners = [limit.matrix_world @ v.co for v in limit.data.vertices]
lo = [min(c[k] for c in corners) for k in range(3)]
hi = [max(c[k] for c in corners) for k in range(3)]
step = 1.1 * (hi[0] - lo[0])
origin = limit.location.copy()
for obj, x in ((limit, -step), (displaced, 0.0), (sculpt, step)):
    obj.location = (x - 0.5 * (lo[0] + hi[0]) + origin.x, 0, origin.z - lo[2])
camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
camera.data.type = "ORTHO"
camera.data.ortho_scale = 3.1 * step
camera.location = (0, -10, 0.5 * (hi[2] - lo[2]) + 0.6)
camera.rotation_euler = (math.radians(86), 0, 0)
scene.collection.objects.link(camera)
scene.camera = camera
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 3.0
sun.rotation_euler = (math.radians(40), math.radians(25), math.radians(60))
scene.collection.objects.link(sun)
scene.world = bpy.data.worlds.new("world")
scene.world.color = (0.22, 0.22, 0.25)

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 32
scene.cycles.use_denoising = False
scene.render.resolution_x = 960
scene.render.resolution_y = 300
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "BW"  # the scene is grey: a third of the bytes
scene.render.image_settings.compression = 100
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print("blender-render.py: wrote", out)
