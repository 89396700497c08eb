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
# 3D view's sidebar (N), tab "dispex".
#
# While dispex runs Blender stays responsive: the operator is modal, a timer polls the process,
# and the extraction's own progress (`dispex extract --progress-lines`: Ptex faces done of the
# total) drives the progress cursor and the status bar ("dispex: 40% of 252 faces"); Esc stops
# it (the process is ended, its temporary folder removed, the output folder left as it was).
# dispex writes into a temporary folder; only a run that succeeds moves its maps into the output
# folder, as <base>.<UDIM>.exr beside <base>.ptx (tiles of an earlier run that the UVs no longer
# touch are removed). dispex's warnings (overlapping UVs, faces outside the UDIM tiles, tiles
# not written) show in Blender's report, and its messages name the Blender objects, not the
# temporary OBJ files. Running it again re-uses the texture "dispex <base>" and the tiled image
# of the maps, reloaded from disk with every tile. A relative output folder (the default
# //dispex_maps) is relative to the .blend file: an unsaved file is refused until it is saved
# or given an absolute folder. Scripts and background mode (blender -b) run the same steps
# (the Extraction class below) in a blocking loop; `last_reports` keeps the last run's reports.
bl_info = {
    "name": "dispex Displacement",
    "author": "dispex",
    "version": (0, 2, 0),
    "blender": (3, 4, 0),
    "location": "3D View > Sidebar > dispex",
    "description": "Extract displacement maps (UDIM OpenEXR) from a sculpt and apply them",
    "category": "Object",
}

import errno
import json
import math
import os
import queue
import re
import shutil
import subprocess
import tempfile
import threading
import time

import bpy

POLL_SECONDS = 0.1  # the timer of the modal operator, and the wait of the blocking loop
PROGRESS_LINE = re.compile(r"^progress (\S+) (\d+)/(\d+)$")
TILE_NAME = re.compile(r"^(.*)\.(\d{4})\.exr$")

# The reports of the last run, oldest first, as (type, message): "ERROR", "WARNING" or "INFO".
last_reports = []
# The extraction running, if any (one at a time).
running = None


class ExtractionError(Exception):
    """A failure, its message one line fit for Blender's report."""


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


def tile_number(path):
    m = TILE_NAME.match(os.path.basename(path))
    return int(m.group(2)) if m else None


def tiled_image(pattern, tiles):
    """The tiled image of the maps `pattern` (.../<base>.<UDIM>.exr): the one already loaded
    from there, reloaded from disk, else a new one; every tile of `tiles` (UDIM numbers) known
    to it and no other."""
    path = os.path.normpath(pattern)
    image = next((i for i in bpy.data.images if i.source == "TILED" and i.library is None and
                  os.path.normpath(bpy.path.abspath(i.filepath)) == path), None)
    if image is None:
        first = path.replace("<UDIM>", str(min(tiles)))
        image = bpy.data.images.load(first)
        image.source = "TILED"  # Blender finds the other tiles beside it
        image.name = os.path.basename(pattern)
    else:
        image.reload()  # the new texels, and the tiles now on disk
    for number in sorted(tiles):
        if image.tiles.get(number) is None:
            image.tiles.new(tile_number=number)
    for tile in list(image.tiles):
        if tile.number not in tiles and len(image.tiles) > 1:
            image.tiles.remove(tile)
    if image.colorspace_settings.name != "Non-Color":  # setting it drops the loaded texels
        image.colorspace_settings.name = "Non-Color"
    return image


def apply_modifiers(base, pattern, tiles, levels, vector=False):
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
    img = tiled_image(pattern, tiles)
    name = "dispex " + base.name
    tex = bpy.data.textures.get(name)
    if tex is None or tex.type != "IMAGE" or tex.library is not None:
        tex = bpy.data.textures.new(name, "IMAGE")
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
    output_dir: bpy.props.StringProperty(
        name="Output folder", subtype="DIR_PATH", default="//dispex_maps",
        description="Where the maps go; a relative folder is relative to the .blend file, "
                    "which must then be saved")
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
    """The dispex program: the add-on's preference, else found on PATH (ExtractionError when
    neither gives one that can run)."""
    addon = context.preferences.addons.get(__name__)
    path = addon.preferences.executable if addon is not None and addon.preferences else ""
    where = "the add-on's preference \"dispex program\""
    if path:
        full = os.path.normpath(bpy.path.abspath(os.path.expanduser(path)))
        if not os.path.exists(full):
            raise ExtractionError("dispex: %s does not exist (%s)" % (full, where))
        if os.path.isdir(full):
            raise ExtractionError("dispex: %s is a folder, not the dispex program (%s)" % (
                full, where))
        if not os.access(full, os.X_OK):
            raise ExtractionError("dispex: %s is not an executable program (%s)" % (full, where))
        return full
    found = shutil.which("dispex")
    if not found:
        raise ExtractionError("dispex: the dispex program is not on PATH: give its path in %s"
                              % where)
    return found


def output_folder(setting):
    """The absolute output folder of the setting: a relative one is relative to the .blend
    file (ExtractionError while that is not saved: never Blender's working directory)."""
    path = os.path.expanduser(setting.strip())
    if not path:
        raise ExtractionError("dispex: give an output folder")
    if path.startswith("//") or not os.path.isabs(path):
        if not bpy.data.filepath:
            raise ExtractionError(
                "dispex: the output folder %s is relative to the .blend file, which is not "
                "saved: save the file or give an absolute output folder" % setting)
        path = bpy.path.abspath(path if path.startswith("//") else "//" + path)
    return os.path.normpath(path)


def _read_lines(stream, sink, tag):
    """A reader thread: each line of `stream` into `sink` as (tag, line), then (tag, None)."""
    try:
        for line in stream:
            sink.put((tag, line.rstrip("\r\n")))
    finally:
        stream.close()
        sink.put((tag, None))


def _move_into(src, folder):
    """`src` into `folder` under its own name, replacing what is there; across file systems
    copied beside the target first, so that the target only ever holds a whole file."""
    dst = os.path.join(folder, os.path.basename(src))
    try:
        os.replace(src, dst)
    except OSError as e:
        if e.errno != errno.EXDEV:
            raise
        part = dst + ".dispex-part"
        try:
            shutil.copyfile(src, part)
            os.replace(part, dst)
        finally:
            if os.path.exists(part):
                os.remove(part)
    return dst


class Extraction:
    """One run of `dispex extract` for a base and its sculpt, in steps that the modal operator
    drives from a timer and `execute` from a blocking loop:

      start()   writes both meshes as OBJ into a temporary folder and starts dispex;
      poll()    takes what dispex printed so far (reader threads: never blocks) and returns
                True while it runs;
      finish()  once it ended: the maps moved into the output folder, the modifiers set up
                (ExtractionError with dispex's message when it failed);
      cancel()  ends the process and removes the temporary folder.

    cleanup() (called by finish and cancel) removes the temporary folder (and the output
    folder when the run made it and failed); `warnings` holds
    dispex's warnings, `progress` the last (phase, done, total) it printed."""

    def __init__(self, program, base, sculpt, out_dir, resolution=1024, padding=16,
                 half=False, vector=False, tolerance=0.0):
        self.program = program
        self.base_name = base.name
        self.sculpt_name = sculpt.name
        self.out_dir = out_dir
        self.name = bpy.path.clean_name(base.name)
        self.levels = subdivision_levels(base, sculpt)
        self.options = dict(resolution=resolution, padding=padding, half=half, vector=vector,
                            tolerance=tolerance)
        self.work = None
        self.made_out_dir = False  # the output folder was made for this run
        self.proc = None
        self.lines = queue.Queue()
        self.readers = []
        self.messages = []  # what dispex printed, progress lines left out
        self.progress = None
        self.warnings = []
        self.tiles = []
        self.started = time.monotonic()

    # Paths of the temporary folder, in dispex's messages replaced by what the user knows.
    def _paths(self):
        maps = os.path.join(self.work, "maps")
        return [(os.path.join(maps, ""), os.path.join(self.out_dir, "")),
                (os.path.join(self.work, self.name + "_sculpt.obj"), self.sculpt_name),
                (os.path.join(self.work, self.name + ".obj"), self.base_name),
                (self.work, "(dispex's temporary folder)")]

    def readable(self, text):
        """`text` with the temporary files named as the Blender objects they hold."""
        if self.work:
            for path, name in self._paths():
                text = text.replace(path, name)
        return text

    def start(self):
        base = bpy.data.objects[self.base_name]
        sculpt = bpy.data.objects[self.sculpt_name]
        self.made_out_dir = not os.path.isdir(self.out_dir)
        try:
            os.makedirs(self.out_dir, exist_ok=True)
        except OSError as e:
            raise ExtractionError("dispex: cannot make the output folder %s: %s" % (
                self.out_dir, e.strerror or e))
        if not os.access(self.out_dir, os.W_OK):
            raise ExtractionError("dispex: cannot write in the output folder %s" % self.out_dir)
        self.work = tempfile.mkdtemp(prefix="dispex_")
        maps = os.path.join(self.work, "maps")
        base_path = os.path.join(self.work, self.name + ".obj")
        sculpt_path = os.path.join(self.work, self.name + "_sculpt.obj")
        try:
            write_obj(base_path, base, with_uvs=True)
            write_obj(sculpt_path, sculpt, base.matrix_world.inverted() @ sculpt.matrix_world)
        except OSError as e:
            raise ExtractionError("dispex: cannot write %s and %s for dispex: %s" % (
                self.base_name, self.sculpt_name, e.strerror or e))
        o = self.options
        cmd = [self.program, "extract", base_path, sculpt_path,
               "-o", os.path.join(maps, self.name + ".ptx"), "--uv-maps", maps,
               "--uv-resolution", str(o["resolution"]), "--uv-padding", str(o["padding"]),
               "--data-type", "half" if o["half"] else "float",
               "--report", os.path.join(self.work, "report.json"), "-q", "--progress-lines"]
        if o["vector"]:
            cmd += ["--vector", "object"]
        if o["tolerance"] > 0:
            cmd += ["--tolerance", repr(o["tolerance"])]
        self.started = time.monotonic()
        try:
            self.proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                         stderr=subprocess.PIPE, text=True, errors="replace")
        except OSError as e:
            raise ExtractionError("dispex: cannot run %s: %s (the add-on's preference "
                                  "\"dispex program\")" % (self.program, e.strerror or e))
        for stream, tag in ((self.proc.stdout, "out"), (self.proc.stderr, "err")):
            t = threading.Thread(target=_read_lines, args=(stream, self.lines, tag), daemon=True)
            t.start()
            self.readers.append(t)

    def _drain(self):
        while True:
            try:
                tag, line = self.lines.get_nowait()
            except queue.Empty:
                return
            if line is None:
                continue
            m = PROGRESS_LINE.match(line) if tag == "err" else None
            if m:
                self.progress = (m.group(1), int(m.group(2)), int(m.group(3)))
            elif line.strip():
                self.messages.append(line)

    def running(self):
        return self.proc is not None and self.proc.returncode is None

    def poll(self):
        """Takes what dispex printed; True while it runs."""
        if self.proc is None:
            return False
        self._drain()
        if self.proc.poll() is None:
            return True
        for t in self.readers:
            t.join(timeout=5)
        self._drain()
        return False

    def status_text(self):
        if self.progress is None:
            return "dispex: reading %s and %s" % (self.base_name, self.sculpt_name)
        phase, done, total = self.progress
        if total > 0 and done >= total:  # the UV maps have no count of their own
            return "dispex: %d faces done, writing the UV maps (%.0f s)" % (
                total, time.monotonic() - self.started)
        return "dispex: %d%% of %d faces" % (self.percent(), total)

    def percent(self):
        if self.progress is None or self.progress[2] == 0:
            return 0
        return min(100, 100 * self.progress[1] // self.progress[2])

    def _failure(self):
        rc = self.proc.returncode
        lines = [self.readable(line) for line in self.messages]
        errors = [line for line in lines if not line.startswith("dispex: warning:")]
        if rc == 2 and any("--progress-lines" in line for line in lines):
            return ("dispex: %s does not know --progress-lines: it is older than this add-on "
                    "(the add-on's preference \"dispex program\")" % self.program)
        if errors:
            return errors[-1] if errors[-1].startswith("dispex") else "dispex: " + errors[-1]
        if rc < 0:
            return "dispex: ended by signal %d" % -rc
        return "dispex: failed (exit status %d)" % rc

    def finish(self):
        """After poll() returned False: the maps into the output folder and the modifiers on the
        base. Returns the message of the run; raises ExtractionError on failure. Always removes
        the temporary folder."""
        done = False
        try:
            message = self._finish()
            done = True
            return message
        finally:
            self.cleanup(done)

    def _finish(self):
        self.warnings = [self.readable(line[len("dispex: warning: "):])
                         for line in self.messages if line.startswith("dispex: warning: ")]
        if self.proc.returncode != 0:
            raise ExtractionError(self._failure())
        try:
            with open(os.path.join(self.work, "report.json")) as f:
                report = json.load(f)
        except (OSError, ValueError) as e:
            raise ExtractionError("dispex: no report of the run: %s" % e)
        self.warnings += [self.readable(w) for w in report.get("warnings", [])
                          if self.readable(w) not in self.warnings]
        made = report.get("uv_maps", {}).get("files", [])
        tiles = sorted(n for n in (tile_number(p) for p in made) if n is not None)
        if not tiles:
            raise ExtractionError("dispex: no UV map was written (do the UVs of %s lie in the "
                                  "UDIM tiles?)" % self.base_name)
        base = bpy.data.objects.get(self.base_name)
        if base is None or base.type != "MESH" or not base.data.uv_layers:
            raise ExtractionError("dispex: %s was removed or changed while dispex ran" %
                                  self.base_name)
        try:
            for path in made + [os.path.join(self.work, "maps", self.name + ".ptx")]:
                _move_into(path, self.out_dir)
            for entry in os.listdir(self.out_dir):
                m = TILE_NAME.match(entry)
                if m and m.group(1) == self.name and int(m.group(2)) not in tiles:
                    os.remove(os.path.join(self.out_dir, entry))
                    self.warnings.append("%s: removed, a tile of an earlier run that the UVs "
                                         "of %s no longer touch" % (
                                             os.path.join(self.out_dir, entry), self.base_name))
        except OSError as e:
            raise ExtractionError("dispex: cannot write the maps into %s: %s" % (
                self.out_dir, e.strerror or e))
        self.tiles = tiles
        try:
            apply_modifiers(base, os.path.join(self.out_dir, self.name + ".<UDIM>.exr"), tiles,
                            self.levels, self.options["vector"])
        except RuntimeError as e:  # Blender could not load the tiles
            raise ExtractionError("dispex: the maps are in %s, but Blender could not load "
                                  "them: %s" % (self.out_dir, str(e).strip()))
        return "dispex: %d tiles in %s" % (len(tiles), self.out_dir)

    def cancel(self):
        """Ends dispex (SIGTERM: it stops at once and removes its partial files; killed if it
        has not ended in 5 s) and removes the temporary folder; the output folder is left as
        it was."""
        try:
            if self.running():
                self.proc.terminate()
                try:
                    self.proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait()
            for t in self.readers:
                t.join(timeout=5)
        finally:
            self.cleanup()

    def cleanup(self, done=False):
        """Removes the temporary folder, and unless `done` the output folder if this run made
        it and left it empty."""
        if self.work:
            shutil.rmtree(self.work, ignore_errors=True)
        if not done and self.made_out_dir:
            try:
                os.rmdir(self.out_dir)
            except OSError:
                pass


class DISPEX_OT_extract(bpy.types.Operator):
    """Extract displacement maps of the active object (the base) from the selected sculpt and
    displace the base with them (Esc stops it)"""
    bl_idname = "dispex.extract_displacement"
    bl_label = "Extract Displacement"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        base = context.active_object
        return (running is None and base is not None and base.type == "MESH" and
                any(o is not base and o.type == "MESH" for o in context.selected_objects))

    def _report(self, kind, message):
        last_reports.append((kind, message))
        self.report({kind}, message)

    def _start(self, context):
        """The extraction started, or None once the reason is reported."""
        global running
        last_reports.clear()
        base = context.active_object
        sculpt = next(o for o in context.selected_objects if o is not base and o.type == "MESH")
        s = context.scene.dispex
        job = None
        try:
            if not base.data.uv_layers:
                raise ExtractionError("dispex: %s has no UV map" % base.name)
            program = dispex_program(context)
            job = Extraction(program, base, sculpt, output_folder(s.output_dir), s.resolution,
                             s.padding, s.half, s.vector, s.tolerance)
            job.start()
        except ExtractionError as e:
            if job is not None:
                job.cleanup()
            self._report("ERROR", job.readable(str(e)) if job else str(e))
            return None
        except BaseException:
            if job is not None:
                job.cancel()
            raise
        running = job
        self._job = job
        context.window_manager.progress_begin(0, 100)
        self._show(context)
        return job

    def _show(self, context):
        context.window_manager.progress_update(self._job.percent())
        if context.workspace is not None:
            context.workspace.status_text_set(self._job.status_text())
        for area in context.screen.areas if context.screen is not None else ():
            if area.type == "VIEW_3D":
                area.tag_redraw()  # the panel's line of progress

    def _end(self, context):
        global running
        running = None
        context.window_manager.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        timer = getattr(self, "_timer", None)
        if timer is not None:
            context.window_manager.event_timer_remove(timer)
            self._timer = None

    def _conclude(self, context):
        job = self._job
        self._end(context)
        message = error = None
        try:
            message = job.finish()
        except ExtractionError as e:
            error = str(e)
        for w in job.warnings:
            self._report("WARNING", "dispex: warning: " + w)
        if error is not None:
            self._report("ERROR", error)
            return {"CANCELLED"}
        self._report("INFO", message)
        return {"FINISHED"}

    def execute(self, context):
        """Scripts and background mode: the same steps in a blocking loop."""
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        try:
            while job.poll():
                self._show(context)
                time.sleep(POLL_SECONDS)
        except BaseException:
            job.cancel()
            self._end(context)
            raise
        return self._conclude(context)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        if self._start(context) is None:
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(POLL_SECONDS, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        try:
            if event.type == "ESC":
                self._job.cancel()
                self._end(context)
                self._report("INFO", "dispex: cancelled; the output folder is as it was")
                return {"CANCELLED"}
            if event.type != "TIMER":
                return {"PASS_THROUGH"}
            if self._job.poll():
                self._show(context)
                return {"RUNNING_MODAL"}
            return self._conclude(context)
        except BaseException:
            if running is self._job:  # not ended yet: never leave dispex running
                self._job.cancel()
                self._end(context)
            raise

    def cancel(self, context):
        # Blender ends the operator (a file loaded, the window closed).
        self._job.cancel()
        self._end(context)


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
        if running is not None:
            col.label(text=running.status_text() + " (Esc stops it)")
        else:
            col.label(text="Select the sculpt, then the base (active)")
        col.operator(DISPEX_OT_extract.bl_idname)


classes = (DispexPreferences, DispexSettings, DISPEX_OT_extract, DISPEX_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.dispex = bpy.props.PointerProperty(type=DispexSettings)


def unregister():
    global running
    if running is not None:
        running.cancel()
        running = None
    del bpy.types.Scene.dispex
    for c in reversed(classes):
        bpy.utils.unregister_class(c)


if __name__ == "__main__":
    register()
