"""dispex.extract against `dispex extract`: the same bytes for the same inputs and options,
from paths and from meshes given as arrays; the report as a dict; errors as exceptions."""
import json

import numpy as np
import pytest

import dispex
from conftest import CREASED_CUBE, CUBE, run_cli



def variable(key):
    """Wall times, CPU times and memory (used, and available: the plan's limit) differ from run
    to run; the rest is the map's."""
    return ("seconds" in key or key.startswith(("peak_rss", "cpu")) or
            key in ("threads", "limit_bytes"))


def stable(report):
    if isinstance(report, dict):
        return {k: stable(v) for k, v in report.items() if not variable(k)}
    if isinstance(report, list):
        return [stable(v) for v in report]
    return report


def cli_extract(base, sculpt, output, *flags):
    report = output.with_suffix(".json")
    run_cli("extract", base, sculpt, "-o", output, "--report", report, "--quiet", *flags)
    return json.loads(report.read_text())


def arrays(mesh, name):
    """The mesh's arrays handed back as new arrays, as a DCC script would pass its own."""
    tags = {}
    for array in ("crease_edges", "crease_sharpness", "corner_vertices", "corner_sharpness",
                  "holes"):
        if len(getattr(mesh, array)):
            tags[array] = np.array(getattr(mesh, array))
    return dispex.Mesh(np.array(mesh.points, dtype=np.float64),
                       np.array(mesh.face_vertex_counts, dtype=np.int64),
                       np.array(mesh.face_vertex_indices, dtype=np.int64),
                       name=name, **tags, **mesh.subdivision_rules)


@pytest.mark.parametrize("cage", [CUBE, CREASED_CUBE])
def test_paths_and_arrays_give_the_command_lines_bytes(tmp_path, sculpts, cage):
    sculpt = sculpts(cage)
    options = {"tolerance": 0.002, "data_type": "half"}
    expected = cli_extract(cage, sculpt, tmp_path / "cli.ptx", "--tolerance", "0.002",
                           "--data-type", "half")
    cli_bytes = (tmp_path / "cli.ptx").read_bytes()

    report = dispex.extract(cage, sculpt, tmp_path / "py.ptx", **options)
    assert (tmp_path / "py.ptx").read_bytes() == cli_bytes
    assert report["output"]["path"] == str(tmp_path / "py.ptx")
    expected["output"]["path"] = report["output"]["path"]
    assert stable(report) == stable(expected)

    base = arrays(dispex.read_mesh(cage), cage.name)
    sculpt_mesh = arrays(dispex.read_mesh(sculpt), sculpt.name)
    report = dispex.extract(base, sculpt_mesh, tmp_path / "arrays.ptx", **options)
    assert (tmp_path / "arrays.ptx").read_bytes() == cli_bytes
    assert report["inputs"]["base_fingerprint"] == expected["inputs"]["base_fingerprint"]


def test_options_change_the_map(tmp_path, sculpts):
    """The options reach the library: another tolerance, another map."""
    sculpt = sculpts(CUBE)
    a = dispex.extract(CUBE, sculpt, tmp_path / "a.ptx", tolerance=0.002)
    b = dispex.extract(CUBE, sculpt, tmp_path / "b.ptx", tolerance=0.02)
    assert a["statistics"]["tolerance"] == 0.002 and b["statistics"]["tolerance"] == 0.02
    assert (tmp_path / "a.ptx").read_bytes() != (tmp_path / "b.ptx").read_bytes()


def test_creases_given_as_arrays_are_used(tmp_path, sculpts):
    """Dropping the creases of a creased cage changes the map: the tags are not ignored."""
    sculpt = sculpts(CREASED_CUBE)
    cage = dispex.read_mesh(CREASED_CUBE)
    assert len(cage.crease_edges) > 0
    smooth = dispex.Mesh(cage.points, cage.face_vertex_counts, cage.face_vertex_indices,
                         name=CREASED_CUBE.name, **cage.subdivision_rules)
    dispex.extract(cage, sculpt, tmp_path / "creased.ptx")
    dispex.extract(smooth, sculpt, tmp_path / "smooth.ptx")
    assert (tmp_path / "creased.ptx").read_bytes() != (tmp_path / "smooth.ptx").read_bytes()


def test_incremental_run_of_an_unchanged_array_mesh_leaves_the_map(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    base = arrays(dispex.read_mesh(CUBE), CUBE.name)
    dispex.extract(base, sculpt, tmp_path / "m.ptx", incremental=True)
    again = dispex.extract(base, sculpt, tmp_path / "m.ptx", incremental=True)
    assert again["incremental"]["unchanged"] is True
    moved = dispex.Mesh(base.points * 1.01, base.face_vertex_counts, base.face_vertex_indices,
                        name=CUBE.name)
    changed = dispex.extract(moved, sculpt, tmp_path / "m.ptx", incremental=True)
    assert changed["incremental"]["unchanged"] is False


@pytest.mark.parametrize("options, message", [
    ({"tolerance": "x"}, "tolerance: 'x' is not a number"),
    ({"tolerance": float("nan")}, "tolerance: nan is not a finite number"),
    ({"oversample": 3}, "oversample = 3"),
    ({"holes": "maybe"}, "holes"),
    ({"compression_level": 99}, "compression_level = 99"),
    ({"colour": 1}, "colour: unknown option"),
    ({"colour": 1}, "uv_maps_dir, .*threads, incremental, cache_dir, shard, .*shard_sculpt"),
    ({"uv_maps": "uv", "uv_maps_dir": "uv"}, "given twice"),
])
def test_bad_values_raise_value_error_naming_them(tmp_path, sculpts, options, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", **options)
    assert not (tmp_path / "m.ptx").exists()


@pytest.mark.parametrize("options, message", [
    ({"threads": 1.5}, "threads: 1.5 is not an integer"),
    ({"threads": True}, "threads: True is not an integer"),
    ({"check_inputs": None}, "check_inputs: None is not True or False"),
    ({"holes": 1}, "holes: 1 is not a string \\(fill, fail or zero\\)"),
    ({"uv_maps": 3}, "uv_maps: 3 is not a path"),
    ({"progress": 3}, "progress: 3 is not callable"),
])
def test_values_of_the_wrong_type_raise_type_error(tmp_path, sculpts, options, message):
    with pytest.raises(TypeError, match=message):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", **options)
    assert not (tmp_path / "m.ptx").exists()


def test_failures_raise_dispex_error_with_the_librarys_message(tmp_path, sculpts):
    missing = tmp_path / "missing.obj"
    with pytest.raises(dispex.InputError, match=str(missing)) as raised:
        dispex.extract(missing, sculpts(CUBE), tmp_path / "m.ptx")
    assert isinstance(raised.value, dispex.Error) and isinstance(raised.value, RuntimeError)
    assert raised.value.path == str(missing) and raised.value.code == "bad_input"
    assert "\n" not in str(raised.value)
    assert not (tmp_path / "m.ptx").exists()


def test_version_is_the_librarys(tmp_path, sculpts):
    report = dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx")
    assert report["version"] == dispex.__version__
    assert run_cli("--version").stdout.strip().endswith(dispex.__version__)
    assert dispex.Map(tmp_path / "m.ptx").meta["dispex:version"] == dispex.__version__
