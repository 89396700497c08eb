# Runs inside Blender: the add-on (blender/dispex_displacement.py) as a user drives it. The base
# and the sculpt are built from their OBJ files, the sculpt selected and the base active,
# "Extract Displacement" pressed (it finds dispex on PATH), and the base with the modifiers the
# add-on set up is written as OBJ for `dispex verify --displaced`. Then, as negative controls,
# the image of the add-on's Displace texture is swapped for the maps made wrong (KINDS, comma
# separated, as displace.py --wrong makes them; nothing else of the add-on's set-up changed),
# each result written to WRONG_DIR/KIND.obj.
#
#   addon_test.py -- ADDON_DIR BASE.obj SCULPT.obj MAPS_DIR OUT.obj KINDS WRONG_DIR [vector]
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import displace  # noqa: E402  (build_object, write_evaluated, write_wrong)

args = sys.argv[sys.argv.index("--") + 1:]
addon_dir, base_path, sculpt_path, maps_dir, out, kinds, wrong_dir = args[:7]
vector = args[7:] == ["vector"]
sys.path.insert(0, addon_dir)
import dispex_displacement  # noqa: E402

dispex_displacement.register()
base = displace.build_object(base_path, "base")
sculpt = displace.build_object(sculpt_path, "sculpt")
view_layer = bpy.context.view_layer
for o in view_layer.objects:
    o.select_set(False)
sculpt.select_set(True)
base.select_set(True)
view_layer.objects.active = base
bpy.context.scene.dispex.output_dir = maps_dir
bpy.context.scene.dispex.resolution = 256
bpy.context.scene.dispex.vector = vector
result = bpy.ops.dispex.extract_displacement()
print("addon_test.py: operator", result)
if result != {"FINISHED"}:
    sys.exit(1)
names = [m.name for m in base.modifiers]
if names != ["dispex Subdivision", "dispex Displace"]:
    sys.exit("addon_test.py: modifiers %s" % names)
direction = base.modifiers["dispex Displace"].direction
if direction != ("RGB_TO_XYZ" if vector else "NORMAL"):
    sys.exit("addon_test.py: Displace direction %s" % direction)
sculpt.hide_set(True)
displace.write_evaluated(base, out, "the add-on's result")
print("addon_test.py: wrote", out)
texture = base.modifiers["dispex Displace"].texture
displace.write_wrong(base, texture, os.path.join(maps_dir, "base.<UDIM>.exr"),
                     [k for k in kinds.split(",") if k], wrong_dir, "the add-on's result")
