# Runs inside Blender: the add-on (blender/dispex_displacement.py) as a user drives it. The add-on
# is enabled as an installed one is (addon_utils, with its preferences), the base and the sculpt
# are built from their OBJ files, the sculpt selected and the base active, "Extract
# Displacement" pressed (it finds dispex on PATH), and the base with the modifiers the add-on
# set up is written as OBJ for `dispex verify --displaced`. Then, as negative controls, the
# image of the add-on's Displace texture is swapped for the maps made wrong (KINDS, comma
# separated, as displace.py --wrong makes them; nothing else of the add-on's set-up changed),
# each result written to WRONG_DIR/KIND.obj.
#
# With `checks`, before that result: the add-on's own one-line errors (a wrong program path in
# its preferences, a relative output folder in an unsaved file, an error of dispex naming the
# Blender objects, not its temporary files), a run on UVs folded onto each other (dispex's
# overlap warning in the operator's reports; 3 of the 6 tiles), an extraction cancelled while
# it runs (the process ended, the output folder made for it removed), and the run whose result
# is measured is then a rerun: one texture and one tiled image (no .001 copies) holding all 6
# tiles, 3 of them new, reloaded from disk (its first tile holds the new file's texels).
# After every step no temporary folder of the add-on is left (run with TMPDIR a folder of its
# own: dispex_* entries there are the add-on's).
#
#   addon_test.py -- ADDON_DIR BASE.obj SCULPT.obj MAPS_DIR OUT.obj KINDS WRONG_DIR
#                    [vector] [checks]
import os
import re
import sys
import tempfile
import time

import addon_utils
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import displace  # noqa: E402  (build_object, write_evaluated, write_wrong)

args = sys.argv[sys.argv.index("--") + 1:]
addon_dir, base_path, sculpt_path, maps_dir, out, kinds, wrong_dir = args[:7]
vector = "vector" in args[7:]
checks = "checks" in args[7:]
sys.path.insert(0, addon_dir)
addon = addon_utils.enable("dispex_displacement", default_set=True)
if addon is None:
    sys.exit("addon_test.py: the add-on could not be enabled")
prefs = bpy.context.preferences.addons["dispex_displacement"].preferences
import dispex_displacement  # noqa: E402
assert addon is dispex_displacement

base = displace.build_object(base_path, "base")
sculpt = displace.build_object(sculpt_path, "sculpt")
view_layer = bpy.context.view_layer


def select(sculpt_object, base_object):
    for o in view_layer.objects:
        o.select_set(False)
    sculpt_object.select_set(True)
    base_object.select_set(True)
    view_layer.objects.active = base_object


def fail(message):
    sys.exit("addon_test.py: FAILED: " + message)


def reports(kind):
    return [m for k, m in dispex_displacement.last_reports if k == kind]


def no_temporary_folder(after):
    left = [e for e in os.listdir(tempfile.gettempdir()) if e.startswith("dispex_")]
    if left:
        fail("after %s, temporary folders left in %s: %s" % (after, tempfile.gettempdir(), left))


def expect_error(what, needles, shunned=()):
    """The operator refuses with one line of its own holding every needle and none of the
    shunned strings (no Python traceback)."""
    try:
        result = bpy.ops.dispex.extract_displacement()
    except RuntimeError as e:
        raised = str(e)
    else:
        fail("%s: the operator returned %s, not an error" % (what, result))
    errors = reports("ERROR")
    if len(errors) != 1 or "\n" in errors[0]:
        fail("%s: not one error line: %r" % (what, errors))
    for text in (raised, errors[0]):
        if "Traceback" in text or "Python:" in text:
            fail("%s: a Python error, not the add-on's message: %s" % (what, text))
    for needle in needles:
        if needle not in errors[0]:
            fail("%s: %r not in the message: %s" % (what, needle, errors[0]))
    for s in shunned:
        if s in errors[0]:
            fail("%s: %r in the message: %s" % (what, s, errors[0]))
    no_temporary_folder(what)
    print("addon_test.py: %s: %s" % (what, errors[0]))


def run_operator(what):
    result = bpy.ops.dispex.extract_displacement()
    print("addon_test.py: %s: operator %s" % (what, result))
    if result != {"FINISHED"}:
        fail("%s: operator %s: %s" % (what, result, dispex_displacement.last_reports))
    no_temporary_folder(what)


def tile_texels(image):
    """The texels of the image's first tile (1001) as it holds them."""
    return list(image.pixels[:])


def image_tiles():
    image = base.modifiers["dispex Displace"].texture.image
    return sorted(t.number for t in image.tiles)


settings = bpy.context.scene.dispex
settings.output_dir = maps_dir
settings.resolution = 256
settings.vector = vector
select(sculpt, base)

if checks:
    work = os.path.dirname(os.path.abspath(out))
    # A wrong program path in the preferences.
    missing = os.path.join(work, "no-such-dispex")
    prefs.executable = missing
    expect_error("a wrong program path", [missing, "dispex program"])
    prefs.executable = ""
    # A relative output folder while the .blend file is not saved.
    settings.output_dir = "//addon_test_unsaved"
    expect_error("an unsaved file", ["output folder", "not saved"])
    if os.path.exists(os.path.join(os.getcwd(), "addon_test_unsaved")):
        fail("an unsaved file: the maps went into Blender's working directory")
    settings.output_dir = maps_dir
    # dispex refuses a sculpt with fewer faces than the base: its message names the objects.
    tiny = bpy.data.meshes.new("tiny")
    tiny.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    tiny_sculpt = bpy.data.objects.new("tiny sculpt", tiny)
    bpy.context.scene.collection.objects.link(tiny_sculpt)
    select(tiny_sculpt, base)
    expect_error("an error of dispex", ["tiny sculpt", "fewer than the base base"],
                 [".obj", tempfile.gettempdir()])
    bpy.data.objects.remove(tiny_sculpt)
    select(sculpt, base)
    # UVs of the sides in the upper row of tiles folded onto the lower row: overlapping UVs.
    uvs = base.data.uv_layers.active.data
    kept = [tuple(d.uv) for d in uvs]
    for d in uvs:
        if d.uv.y >= 1:
            d.uv.y -= 1
    run_operator("overlapping UVs")
    warnings = reports("WARNING")
    if not any("overlapping UVs" in w and w.startswith("dispex: warning: base: ")
               for w in warnings):
        fail("overlapping UVs: no overlap warning naming the base in %r" % warnings)
    if any(tempfile.gettempdir() in w or ".obj" in w for w in warnings):
        fail("overlapping UVs: a warning names a temporary file: %r" % warnings)
    print("addon_test.py: reported:", warnings)
    if image_tiles() != [1001, 1002, 1003]:
        fail("overlapping UVs: the image's tiles %s" % image_tiles())
    # The texels loaded, as a viewport loads them: the rerun must reload them.
    first_texels = tile_texels(base.modifiers["dispex Displace"].texture.image)
    for d, uv in zip(uvs, kept):
        d.uv = uv
    # Cancelled while it runs (the same steps Esc takes in the modal operator).
    cancel_dir = os.path.join(work, "cancelled")
    job = dispex_displacement.Extraction(dispex_displacement.dispex_program(bpy.context), base,
                                         sculpt, cancel_dir, resolution=2048)
    job.start()
    deadline = time.time() + 60
    while job.poll() and job.progress is None and time.time() < deadline:
        time.sleep(0.01)
    if not job.running():
        fail("cancel: dispex ended before it was cancelled (%s)" % job.messages)
    print("addon_test.py: cancelling at", job.status_text())
    job.cancel()
    if job.running() or os.path.exists(job.work):
        fail("cancel: dispex still running or its temporary folder left")
    if os.path.exists(cancel_dir):  # made for the run: removed with it
        fail("cancel: the output folder is left: %s" % os.listdir(cancel_dir))
    no_temporary_folder("a cancel")
    print("addon_test.py: cancelled, exit status", job.proc.returncode)

run_operator("the map" + (" (a rerun)" if checks else ""))
names = [m.name for m in base.modifiers]
if names != ["dispex Subdivision", "dispex Displace"]:
    fail("modifiers %s" % names)
direction = base.modifiers["dispex Displace"].direction
if direction != ("RGB_TO_XYZ" if vector else "NORMAL"):
    fail("Displace direction %s" % direction)
texture = base.modifiers["dispex Displace"].texture
if image_tiles() != [1001, 1002, 1003, 1011, 1012, 1013]:
    fail("the image's tiles %s" % image_tiles())
if [t.name for t in bpy.data.textures] != ["dispex base"] or texture.name != "dispex base":
    fail("textures %s" % [t.name for t in bpy.data.textures])
tiled = [i for i in bpy.data.images if i.source == "TILED"]
if tiled != [texture.image] or any(re.search(r"\.\d{3}$", i.name) for i in bpy.data.images):
    fail("images %s" % [(i.name, i.source) for i in bpy.data.images])
if checks:
    fresh = bpy.data.images.load(os.path.join(maps_dir, "base.1001.exr"))
    fresh.colorspace_settings.name = "Non-Color"
    texels = tile_texels(texture.image)
    if texels == first_texels or texels != tile_texels(fresh):
        fail("the image holds the first run's texels: not reloaded")
    bpy.data.images.remove(fresh)
print("addon_test.py: texture %s, image %s, tiles %s" % (texture.name, texture.image.name,
                                                         image_tiles()))
sculpt.hide_set(True)
displace.write_evaluated(base, out, "the add-on's result")
print("addon_test.py: wrote", out)
displace.write_wrong(base, texture, os.path.join(maps_dir, "base.<UDIM>.exr"),
                     [k for k in kinds.split(",") if k], wrong_dir, "the add-on's result")
