"""The module as a pipeline TD uses it: every option of the library's table as a keyword,
exceptions by cause with their fields, NumPy scalars and os.PathLike, assets of several shapes,
maps and UV-space tiles as arrays, meshes with UVs from arrays, and the type stubs."""
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import dispex
from conftest import CUBE, DATA, run_cli

UDIM_BOX = DATA / "uv_maps" / "udim_box.obj"


# ---- Options ----------------------------------------------------------------------------------

def test_every_option_of_the_table_is_a_flag_of_the_command_line():
    help_text = run_cli("extract", "--help").stdout
    names = dispex.option_names()
    assert {"tolerance", "uv_maps_dir", "threads", "incremental", "shard", "shard_sculpt",
            "check_inputs", "max_memory"} <= set(names)
    for name, spec in names.items():
        assert re.search(re.escape(spec["flag"]) + r"\b", help_text), (name, spec["flag"])
        assert spec["kind"] in {"integer", "number", "bool", "text", "path", "choice",
                                "integer_or_auto", "size", "distance"}
    recorded = {name for name, spec in names.items() if spec["in_map"]}
    assert {"tolerance", "oversample", "search_distance", "vector", "method"} <= recorded
    assert not {"threads", "max_memory", "incremental", "uv_maps_dir", "check_inputs"} & recorded


# The command line's flags of `extract` that are not options of the map's extraction: where the
# outputs go and how the run shows itself. Every other flag is made from the library's table
# (tools/cmd_extract.cpp), so a new extraction option is a table entry, never a flag of its own.
CLI_ONLY_FLAGS = {"--output", "--out-dir", "--shapes", "--manifest", "--report", "--preview",
                  "--quiet", "--progress-lines", "--watch", "--watch-settle", "--help",
                  "--search-distance-rel"}  # --search-distance's percentage, spelled apart


def test_every_flag_of_extract_is_in_the_table_or_the_command_lines_own():
    help_text = run_cli("extract", "--help").stdout
    flags = set(re.findall(r"^\s+(?:-\w, )?(--[a-z-]+)", help_text, flags=re.M))
    table = {spec["flag"] for spec in dispex.option_names().values()}
    assert flags - CLI_ONLY_FLAGS == table, (flags - CLI_ONLY_FLAGS) ^ table


# CLI11's names of the value types in --help, by the table's kinds.
HELP_TYPES = {"integer": "INT", "number": "FLOAT"}


def test_each_table_flags_help_is_the_tables():
    """Each option's entry in `extract --help` -- its value's type, default and help line (on the
    flag's line or the next) -- is the table's, so the two cannot drift apart."""
    help_text = run_cli("extract", "--help").stdout
    for name, spec in dispex.option_names().items():
        assert spec["help"] and "\n" not in spec["help"], name
        entry = re.search(r"^ +" + re.escape(spec["flag"]) + r"(?P<head>[^\n]*?) *\n? *"
                          + re.escape(spec["help"]) + "$", help_text, flags=re.M)
        assert entry, (name, spec["help"])
        head = entry["head"]
        if spec["kind"] == "bool":  # a flag: no value; {false} where it turns the option off
            assert head == ("{false}" if spec["default"] == "true" else ""), (name, head)
            continue
        assert head.startswith(" " + HELP_TYPES.get(spec["kind"], "TEXT")), (name, head)
        shown = head.rpartition("=")[2] if "=" in head else ""
        assert shown == spec["default"], (name, head)


def test_the_defaults_help_shows_are_the_librarys(tmp_path, sculpts):
    """Every default the table gives, given on the command line or to the module, makes the map
    that giving none makes."""
    sculpt = sculpts(CUBE)
    specs = dispex.option_names()
    given = [arg for spec in specs.values() if spec["default"] and spec["kind"] != "bool"
             for arg in (spec["flag"], spec["default"])]
    assert "--oversample" in given and "--fixed-resolution" in given
    run_cli("extract", CUBE, sculpt, "-o", tmp_path / "none.ptx", "--quiet")
    run_cli("extract", CUBE, sculpt, "-o", tmp_path / "given.ptx", "--quiet", *given)
    defaults = {name: spec["default"] == "true" if spec["kind"] == "bool" else spec["default"]
                for name, spec in specs.items() if spec["default"]}
    dispex.extract(CUBE, sculpt, tmp_path / "module.ptx", **defaults)
    expected = (tmp_path / "none.ptx").read_bytes()
    assert (tmp_path / "given.ptx").read_bytes() == expected
    assert (tmp_path / "module.ptx").read_bytes() == expected


# A value for each option other than its default, and the command line's arguments for it.
OPTION_VALUES = {
    "oversample": (16, ["--oversample", "16"]),
    "max_oversample": (32, ["--max-oversample", "32"]),
    "min_oversample": (8, ["--min-oversample", "8"]),
    "search_distance": ("30%", ["--search-distance", "30%"]),
    "ray_policy": ("outside-first", ["--ray-policy", "outside-first"]),
    "tolerance": (np.float32(0.002), ["--tolerance", str(float(np.float32(0.002)))]),
    "tolerance_fraction": (0.1, ["--tolerance-fraction", "0.1"]),
    "resolution_rule": ("fixed", ["--resolution-rule", "fixed"]),
    "fixed_resolution": ("8x4", ["--fixed-resolution", "8x4"]),
    "nonzero_threshold": (0.001, ["--nonzero-threshold", "0.001"]),
    "data_type": ("half", ["--data-type", "half"]),
    "compression_level": (np.int64(6), ["--compression-level", "6"]),
    "holes": ("zero", ["--holes", "zero"]),
    "watertight": ("all", ["--watertight", "all"]),
    "max_miss_fraction": (0.5, ["--max-miss-fraction", "0.5"]),
    "bvh_quality": ("high", ["--bvh-quality", "high"]),
    "method": ("rays", ["--method", "rays"]),
    "vector": ("object", ["--vector", "object"]),
    "uv_maps_dir": (None, None),  # below: test_uv_maps_as_the_command_line_writes_them
    "uv_resolution": (None, None),
    "uv_padding": (None, None),
    "max_memory": ("8G", ["--max-memory", "8G"]),
    "embree_isa": ("sse2", ["--embree-isa", "sse2"]),
    "check_inputs": (False, ["--no-input-checks"]),
    "threads": (np.int32(1), ["--threads", "1"]),
    "incremental": (None, None),  # test_extract.py: incremental runs of array meshes
    "cache_dir": ("off", ["--cache-dir", "off"]),
    "shard": (None, None),  # test_shards.py
    "shard_sculpt": (None, None),
    "plan_only": (None, None),  # test_the_plan_says_what_a_run_will_do_and_writes_nothing
}


def test_the_table_of_values_covers_every_option():
    assert set(OPTION_VALUES) == set(dispex.option_names())


@pytest.mark.parametrize("name", [n for n, (v, _) in OPTION_VALUES.items() if v is not None])
def test_each_option_gives_the_command_lines_map(tmp_path, sculpts, name):
    value, flags = OPTION_VALUES[name]
    if name == "vector" or name == "method":
        sculpt = sculpts(CUBE, levels=2, pattern="smooth")
    else:
        sculpt = sculpts(CUBE)
    extra = {"method": "interpolate"} if name == "vector" else {}
    extra_flags = ["--method", "interpolate"] if name == "vector" else []
    if name == "fixed_resolution":
        extra, extra_flags = {"resolution_rule": "fixed"}, ["--resolution-rule", "fixed"]
    py_map, cli_map = tmp_path / "py.ptx", tmp_path / "cli.ptx"
    dispex.extract(CUBE, sculpt, py_map, **{name: value}, **extra)
    run_cli("extract", CUBE, sculpt, "-o", cli_map, "--quiet", *flags, *extra_flags)
    default = tmp_path / "default.ptx"
    dispex.extract(CUBE, sculpt, default, **extra)
    assert py_map.read_bytes() == cli_map.read_bytes()
    if name not in ("threads", "max_memory", "embree_isa", "check_inputs", "bvh_quality",
                    "max_miss_fraction", "holes", "ray_policy", "nonzero_threshold",
                    "max_oversample", "min_oversample", "search_distance", "cache_dir"):
        assert py_map.read_bytes() != default.read_bytes(), f"{name} had no effect"


def test_numpy_scalars_and_path_like_are_taken(tmp_path, sculpts):
    report = dispex.extract(pathlib.Path(CUBE), sculpts(CUBE), tmp_path / "m.ptx",
                            tolerance=np.float64(0.002), oversample=np.int16(16),
                            check_inputs=np.bool_(True), threads="1")
    assert report["statistics"]["tolerance"] == pytest.approx(0.002)
    assert report["options"]["oversample"] == 16
    verified = dispex.verify(pathlib.Path(CUBE), pathlib.Path(sculpts(CUBE)),
                             tmp_path / "m.ptx", max_rms=np.float32(1e9),
                             samples_per_face=np.int64(4))
    assert verified["passed"] is True


# ---- UV-space maps, assets -------------------------------------------------------------------

def test_uv_maps_as_the_command_line_writes_them(tmp_path, sculpts):
    sculpt = sculpts(UDIM_BOX, levels=2, pattern="smooth")
    report = dispex.extract(UDIM_BOX, sculpt, tmp_path / "py" / "box.ptx", uv_maps=tmp_path / "py",
                            uv_resolution=np.int64(32), uv_padding=2)
    run_cli("extract", UDIM_BOX, sculpt, "-o", tmp_path / "cli" / "box.ptx", "--uv-maps",
            tmp_path / "cli", "--uv-resolution", "32", "--uv-padding", "2", "--quiet")
    tiles = sorted(p.name for p in (tmp_path / "py").glob("*.exr"))
    assert tiles == [f"box.{u}.exr" for u in (1001, 1002, 1003, 1011, 1012, 1013)]
    assert len(report["uv_maps"]["files"]) == 6
    for tile in tiles:
        assert (tmp_path / "py" / tile).read_bytes() == (tmp_path / "cli" / tile).read_bytes()

    uv = dispex.UvMap(tmp_path / "py" / "box.<UDIM>.exr")
    assert uv.udims == [1001, 1002, 1003, 1011, 1012, 1013]
    assert (uv.resolution, uv.num_channels) == (32, 1)
    assert "dispex:version" in uv.attributes or any(k.startswith("dispex:") for k in uv.attributes)
    assert "box" in repr(uv)
    tile = uv.tile(1002)
    assert tile.shape == (32, 32, 1) and tile.dtype == np.float32
    info = dispex.info(tmp_path / "py" / "box.1002.exr")
    tile_info = next(t for t in info["tiles"] if t["udim"] == 1002)
    assert tile.min() == pytest.approx(tile_info["min"]) and tile.max() == pytest.approx(
        tile_info["max"])
    # Texel centres read back their texels: row j at v = (j + 0.5) / N of tile 1002 (u 1..2).
    j, i = 20, 7
    at = uv.sample([1 + (i + 0.5) / 32], [(j + 0.5) / 32])
    assert at[0] == pytest.approx(float(tile[j, i, 0]), abs=1e-6)
    assert np.isnan(uv.sample([5.5], [5.5])[0])
    with pytest.raises(ValueError, match="udim 1004: no such tile"):
        uv.tile(1004)


def test_a_mesh_with_uvs_from_arrays_gives_the_files_tiles(tmp_path, sculpts):
    sculpt = sculpts(UDIM_BOX, levels=2, pattern="smooth")
    box = dispex.read_mesh(UDIM_BOX)
    assert box.uvs.shape[1] == 2 and box.face_uv_indices.size == box.face_vertex_indices.size
    arrays = dispex.Mesh(box.points, box.face_vertex_counts, box.face_vertex_indices,
                         uvs=box.uvs.astype(np.float64), face_uv_indices=box.face_uv_indices,
                         name=str(UDIM_BOX))
    dispex.extract(arrays, sculpt, tmp_path / "a" / "udim_box.ptx", uv_maps_dir=tmp_path / "a",
                   uv_resolution=16)
    dispex.extract(UDIM_BOX, sculpt, tmp_path / "f" / "udim_box.ptx", uv_maps_dir=tmp_path / "f",
                   uv_resolution=16)
    for tile in (tmp_path / "f").glob("*.exr"):
        assert (tmp_path / "a" / tile.name).read_bytes() == tile.read_bytes()
    with pytest.raises(ValueError, match=r"face_uv_indices: 3 entries, but the faces have 96"):
        dispex.Mesh(box.points, box.face_vertex_counts, box.face_vertex_indices, uvs=box.uvs,
                    face_uv_indices=box.face_uv_indices[:3])
    with pytest.raises(ValueError, match="uvs: given without face_uv_indices"):
        dispex.Mesh(box.points, box.face_vertex_counts, box.face_vertex_indices, uvs=box.uvs)


def concatenated_obj(path, shapes):
    """An OBJ of several shapes (o groups): shapes = [(name, obj path)]."""
    lines, offset = [], 0
    for name, source in shapes:
        mesh = dispex.read_mesh(source)
        lines.append(f"o {name}")
        lines += ["v %.9g %.9g %.9g" % tuple(p) for p in mesh.points]
        start = 0
        for count in mesh.face_vertex_counts:
            ids = mesh.face_vertex_indices[start:start + count] + 1 + offset
            lines.append("f " + " ".join(map(str, ids)))
            start += count
        offset += mesh.num_vertices
    path.write_text("\n".join(lines) + "\n")
    return path


def test_an_asset_of_two_shapes_gives_one_report_per_shape(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    base = concatenated_obj(tmp_path / "asset.obj", [("left", CUBE), ("right", CUBE)])
    sculpted = concatenated_obj(tmp_path / "asset_sculpt.obj", [("left", sculpt), ("right", sculpt)])
    report = dispex.extract(base, sculpted, out_dir=tmp_path / "maps", tolerance=0.002)
    assert list(report["shapes"]) == ["left", "right"]
    assert report["shapes"]["left"]["file"] == str(tmp_path / "maps" / "left.ptx")
    run_cli("extract", base, sculpted, "--out-dir", tmp_path / "cli", "--tolerance", "0.002",
            "--quiet")
    for shape in ("left", "right"):
        assert ((tmp_path / "maps" / f"{shape}.ptx").read_bytes() ==
                (tmp_path / "cli" / f"{shape}.ptx").read_bytes())
    only = dispex.extract(base, sculpted, out_dir=tmp_path / "only", shapes=["right"])
    assert list(only["shapes"]) == ["right"]
    with pytest.raises(ValueError, match="either output"):
        dispex.extract(base, sculpted, tmp_path / "m.ptx", out_dir=tmp_path / "maps")


def test_a_manifests_shapes(tmp_path, sculpts):
    manifest = tmp_path / "asset.json"
    manifest.write_text('{"output_dir": "maps", "options": {"tolerance": 0.002}, "shapes": ['
                        f'{{"name": "cube", "base": "{CUBE.resolve()}", "sculpt": "{sculpts(CUBE).resolve()}"}}]}}')
    report = dispex.extract_manifest(manifest, threads=1)
    assert list(report["shapes"]) == ["cube"]
    assert (tmp_path / "maps" / "cube.ptx").exists()
    with pytest.raises(ValueError, match="threads: set for one run"):
        manifest.write_text('{"options": {"threads": 1}, "shapes": []}')
        dispex.extract_manifest(manifest)


# ---- Exceptions by cause -----------------------------------------------------------------------

def test_a_malformed_file_raises_input_error_naming_it(tmp_path, sculpts):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(dispex.InputError) as raised:
        dispex.extract(bad, sculpts(CUBE), tmp_path / "m.ptx")
    assert raised.value.path == str(bad) and raised.value.code == "bad_input"
    with pytest.raises(dispex.InputError) as raised:
        dispex.Map(bad)
    assert raised.value.path == str(bad)


def test_meshes_that_do_not_belong_together_raise_mismatch_error(tmp_path, sculpts):
    sculpt = dispex.read_mesh(sculpts(CUBE))
    far = dispex.Mesh(sculpt.points + 100.0, sculpt.face_vertex_counts, sculpt.face_vertex_indices,
                      name="far.obj")
    with pytest.raises(dispex.MismatchError) as raised:
        dispex.extract(CUBE, far, tmp_path / "m.ptx", search_distance=0.01)
    assert raised.value.code == "mismatch"
    assert not (tmp_path / "m.ptx").exists()


def test_a_miss_under_holes_fail_names_the_face(tmp_path, sculpts):
    with pytest.raises(dispex.MismatchError, match="holes = fail") as raised:
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", holes="fail",
                       search_distance=1e-6, max_miss_fraction=1, method="rays")
    assert isinstance(raised.value.face, int) and raised.value.face >= 0
    assert f"Ptex face {raised.value.face}:" in str(raised.value)


def test_over_the_memory_budget_raises_memory_budget_error(tmp_path, sculpts):
    with pytest.raises(dispex.MemoryBudgetError, match="max_memory"):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", max_memory="1K")


def test_an_output_that_cannot_be_written_raises_output_error(tmp_path, sculpts):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(dispex.OutputError) as raised:
        dispex.extract(CUBE, sculpts(CUBE), blocker / "m.ptx")
    assert raised.value.code == "output"


def test_a_failed_verify_keeps_its_report(tmp_path, sculpts):
    dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx")
    with pytest.raises(dispex.VerifyError) as raised:
        dispex.verify(CUBE, sculpts(CUBE), tmp_path / "m.ptx", max_rms=1e-12)
    assert raised.value.report["passed"] is False
    assert raised.value.report["failure"] in str(raised.value)
    assert raised.value.path == str(tmp_path / "m.ptx")
    assert isinstance(raised.value, dispex.Error)


# ---- Maps ----------------------------------------------------------------------------------------

def test_map_repr_and_context_manager(tmp_path, sculpts):
    dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx")
    with dispex.Map(tmp_path / "m.ptx") as m:
        assert repr(m) == f"<dispex.Map {tmp_path / 'm.ptx'}: 6 faces, 1 channel, float32>"
        assert m.texels(0).ndim == 3
    assert repr(m) == "<dispex.Map (closed)>"
    with pytest.raises(ValueError, match="closed"):
        m.texels(0)
    with pytest.raises(ValueError, match="closed"):
        m.num_faces
    mesh = dispex.read_mesh(CUBE)
    assert repr(mesh) == f"<dispex.Mesh {CUBE}: 8 vertices, 6 faces>"


def test_a_vector_map_is_sampled_three_values_per_point(tmp_path, sculpts):
    dispex.extract(CUBE, sculpts(CUBE, pattern="smooth"), tmp_path / "v.ptx", vector="object")
    m = dispex.Map(tmp_path / "v.ptx")
    faces, u, v = np.array([0, 3, 5]), np.array([0.5, 0.1, 0.9]), np.array([0.5, 0.7, 0.2])
    for across in (False, True):
        values = m.sample(faces, u, v, across_faces=across)
        assert values.shape == (3, 3)
        for c in range(3):
            assert np.array_equal(values[:, c], m.sample(faces, u, v, channel=c,
                                                         across_faces=across))
    assert np.abs(values).max() > 0


# ---- Type stubs and docstrings ----------------------------------------------------------------

def test_every_public_name_has_a_docstring():
    for name in dispex.__all__:
        if name.startswith("__"):
            continue
        value = getattr(dispex, name)
        assert value.__doc__ and len(value.__doc__.strip()) > 20, name
    for cls in (dispex.Map, dispex.UvMap, dispex.Mesh):
        for member, value in vars(cls).items():
            if member.startswith("_"):
                continue
            assert getattr(value, "__doc__", None), f"{cls.__name__}.{member}"


def test_the_stubs_match_the_module():
    """mypy's stubtest compares python/dispex/__init__.pyi with the module as imported."""
    result = subprocess.run([sys.executable, "-m", "mypy.stubtest", "dispex",
                             "--ignore-missing-stub", "--allowlist",
                             str(pathlib.Path(__file__).parent / "stubtest-allowlist.txt")],
                            capture_output=True, text=True,
                            env=dict(os.environ, MYPYPATH=os.environ.get("PYTHONPATH", "")))
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_script_using_the_module_type_checks(tmp_path):
    script = tmp_path / "tool.py"
    script.write_text(
        "import dispex\n"
        "report = dispex.extract('base.obj', 'sculpt.obj', 'out.ptx', tolerance=0.001)\n"
        "print(report['statistics'])\n"
        "with dispex.Map('out.ptx') as m:\n"
        "    n: int = m.num_faces\n"
        "    m.sample([0], [0.5], [0.5])\n"
        "try:\n"
        "    dispex.verify('base.obj', None, 'out.ptx')\n"
        "except dispex.VerifyError as e:\n"
        "    print(e.report['failure'], e.path)\n")
    bad = tmp_path / "bad.py"
    bad.write_text("import dispex\nm = dispex.Map('out.ptx')\nn: str = m.num_faces\n")
    env = dict(os.environ, MYPYPATH=os.environ.get("PYTHONPATH", ""))
    good = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--no-incremental",
                           "--cache-dir", str(tmp_path / "cache"), str(script)],
                          capture_output=True, text=True, env=env)
    assert good.returncode == 0, good.stdout
    wrong = subprocess.run([sys.executable, "-m", "mypy", "--no-incremental", "--cache-dir",
                            str(tmp_path / "cache"), str(bad)], capture_output=True, text=True,
                           env=env)
    assert wrong.returncode == 1 and "Incompatible types in assignment" in wrong.stdout


def test_messages_show_no_whole_arrays_and_no_binding_internals(tmp_path, sculpts):
    big = np.zeros(1000)
    with pytest.raises(TypeError, match=r"tolerance: <numpy.ndarray of shape \(1000,\)> is not"):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", tolerance=big)
    mesh = dispex.read_mesh(CUBE)
    with pytest.raises(TypeError) as raised:
        dispex.Mesh(mesh.points, mesh.face_vertex_counts, mesh.face_vertex_indices, creases=big)
    message = str(raised.value)
    assert message.startswith("Mesh: unknown keyword 'creases' (known: crease_edges, ")
    assert "handle" not in message and "_argument" not in message and "0., 0." not in message
    with pytest.raises(TypeError, match="Mesh: no face_vertex_indices given"):
        dispex.Mesh(mesh.points, mesh.face_vertex_counts)
    with pytest.raises(TypeError, match="Mesh: takes 3 positional arguments"):
        dispex.Mesh(mesh.points, mesh.face_vertex_counts, mesh.face_vertex_indices, None)
    assert "handle" not in dispex.Mesh.__init__.__doc__


def test_the_plan_says_what_a_run_will_do_and_writes_nothing(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    out = tmp_path / "m.ptx"
    plan = dispex.extract(CUBE, sculpt, out, plan_only=True)["plan"]
    assert not out.exists()
    assert plan["output"] == "map" and plan["faces"]["all"] == 6
    assert plan["faces"]["extracted"] == 6 and plan["faces"]["copied"] == 0
    dispex.extract(CUBE, sculpt, out)
    assert dispex.extract(CUBE, sculpt, out, plan_only=True, incremental=True)["plan"][
        "output"] == "up to date"
    # A changed option: the plan's counts are those the run then has.
    planned = dispex.extract(CUBE, sculpt, out, plan_only=True, incremental=True,
                             tolerance=0.0005)["plan"]
    done = dispex.extract(CUBE, sculpt, out, incremental=True, tolerance=0.0005)
    assert planned["redo_reason"] == "options: tolerance"
    assert planned["faces"]["extracted"] == done["incremental"]["faces_extracted"]
    assert planned["faces"]["copied"] == done["incremental"]["faces_copied"]
    # The automatic memory limit follows the machine's available memory, which moves between
    # the two calls; the rest of the plan must not.
    for p in (planned, done["plan"]):
        assert p["memory"].pop("limit_bytes") > 0
    assert done["plan"] == planned
    part = dispex.extract(CUBE, sculpt, tmp_path / "p.ptx", plan_only=True, shard="1/2")["plan"]
    assert part["output"] == "shard part"
    assert part["faces"]["extracted"] + part["faces"]["another_shards"] == 6
