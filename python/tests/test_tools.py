"""dispex.make_sculpt and dispex.verify against the command line's."""
import json

import pytest

import dispex
from conftest import CUBE, run_cli


def test_make_sculpt_writes_the_command_lines_files(tmp_path):
    summary = dispex.make_sculpt(CUBE, tmp_path / "py.obj", levels=2, pattern="ridges")
    run_cli("make-sculpt", CUBE, "-o", tmp_path / "cli.obj", "--levels", 2, "--pattern",
            "ridges", "--quiet")
    assert (tmp_path / "py.obj").read_bytes() == (tmp_path / "cli.obj").read_bytes()
    assert (tmp_path / "py.obj.truth").read_bytes() == (tmp_path / "cli.obj.truth").read_bytes()
    assert summary["vertices"] == 6 * 16 + 2 and summary["faces"] == 6 * 16
    assert summary["truth"] == str(tmp_path / "py.obj.truth")


@pytest.mark.parametrize("options, error, message", [
    ({"levels": 9}, ValueError, "levels = 9: must be 1..8"),
    ({"amplitude": -1}, ValueError, "amplitude = -1: must be >= 0"),
    ({"pattern": "stripes"}, ValueError, "pattern: unknown pattern"),
    ({"levels": "2"}, TypeError, "levels: '2' is not an integer"),
    ({"amplitude": None}, TypeError, "amplitude: None is not a number"),
    ({"colour": 1}, ValueError, "colour: unknown option"),
])
def test_make_sculpt_errors(tmp_path, options, error, message):
    with pytest.raises(error, match=message):
        dispex.make_sculpt(CUBE, tmp_path / "s.obj", **options)
    assert not (tmp_path / "s.obj").exists()


def test_verify_report_is_the_command_lines(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    dispex.extract(CUBE, sculpt, tmp_path / "m.ptx", tolerance=0.002)
    report = dispex.verify(CUBE, sculpt, tmp_path / "m.ptx", truth=f"{sculpt}.truth",
                           truth_rms_factor=0, truth_p99_factor=0, truth_local_bound=False,
                           threads=1)
    run_cli("verify", CUBE, sculpt, tmp_path / "m.ptx", "--truth", f"{sculpt}.truth",
            "--truth-rms-factor", 0, "--truth-p99-factor", 0, "--no-local-bound",
            "--threads", 1, "--report", tmp_path / "cli.json", "--quiet")
    expected = json.loads((tmp_path / "cli.json").read_text())
    report.pop("seconds", None)
    expected.pop("seconds", None)
    assert report == expected and report["passed"] is True


def test_verify_failing_a_bound(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    dispex.extract(CUBE, sculpt, tmp_path / "m.ptx", resolution_rule="fixed",
                   fixed_resolution="1x1")
    with pytest.raises(dispex.Error, match="m.ptx: "):
        dispex.verify(CUBE, sculpt, tmp_path / "m.ptx", max_error=1e-6)
    report = dispex.verify(CUBE, sculpt, tmp_path / "m.ptx", max_error=1e-6, check=False)
    assert report["passed"] is False


@pytest.mark.parametrize("faces", [False, True])
def test_info_is_the_command_lines_json(tmp_path, sculpts, faces):
    dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx")
    for path in (CUBE, tmp_path / "m.ptx"):
        flags = ["--faces"] if faces and path != CUBE else []
        expected = json.loads(run_cli("info", path, "--json", *flags).stdout)
        assert dispex.info(path, faces=faces) == expected
    assert "face_list" in dispex.info(tmp_path / "m.ptx", faces=True)


def test_info_of_a_uv_map_is_the_command_lines_json(tmp_path, sculpts):
    dispex.extract(CUBE, sculpts(CUBE), tmp_path / "m.ptx", uv_maps_dir=str(tmp_path / "uv"),
                   uv_resolution=32)
    tiles = sorted((tmp_path / "uv").iterdir())
    assert tiles
    expected = json.loads(run_cli("info", tiles[0], "--json").stdout)
    summary = dispex.info(tiles[0])
    assert summary == expected and summary["kind"] == "scalar" and summary["resolution"] == 32


def test_info_errors(tmp_path):
    with pytest.raises(dispex.Error, match="missing.obj"):
        dispex.info(tmp_path / "missing.obj")
    open_mesh = tmp_path / "dangling.obj"
    open_mesh.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\n")
    assert dispex.info(open_mesh)["validation"]["unreferenced_vertices"] == 1
    with pytest.raises(dispex.Error, match="dangling.obj: mesh is not clean: 1 unreferenced"):
        dispex.info(open_mesh, strict=True)
