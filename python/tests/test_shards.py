"""Farm shards from Python (docs/FARM.md): extract(..., shard="I/N") writes a part, merge()
joins the parts of all shards, in any order, into the map one extraction writes, byte for byte."""
import pytest

import dispex
from conftest import CUBE, run_cli


@pytest.mark.parametrize("options", [
    {},
    {"method": "rays", "search_distance": "5%", "shard_sculpt": "part"},
    {"method": "rays", "shard_sculpt": "part"},  # the automatic search distance in parts
])
def test_merged_parts_are_one_extractions_bytes(tmp_path, sculpts, options):
    sculpt = sculpts(CUBE)
    whole = {key: value for key, value in options.items() if key != "shard_sculpt"}
    dispex.extract(CUBE, sculpt, tmp_path / "one.ptx", **whole)
    parts = []
    for i in (1, 2, 3):
        part = tmp_path / f"part{i}.ptx"
        report = dispex.extract(CUBE, sculpt, part, shard=f"{i}/3", **options)
        assert report["shard"]["index"] == i and report["shard"]["count"] == 3
        parts.append(part)
    calls = []
    report = dispex.merge(reversed(parts), tmp_path / "merged.ptx",
                          progress=lambda done, total: calls.append((done, total)))
    assert report["parts_merged"] == 3
    assert (tmp_path / "merged.ptx").read_bytes() == (tmp_path / "one.ptx").read_bytes()
    assert calls and calls[-1][0] == calls[-1][1] > 0
    # The command line merges the same parts to the same bytes.
    run_cli("merge", *parts, "-o", tmp_path / "cli.ptx", "--quiet")
    assert (tmp_path / "cli.ptx").read_bytes() == (tmp_path / "one.ptx").read_bytes()


def test_a_missing_part_names_itself_and_writes_nothing(tmp_path, sculpts):
    sculpt = sculpts(CUBE)
    parts = [tmp_path / f"part{i}.ptx" for i in (1, 2, 3)]
    for i in (1, 3):
        dispex.extract(CUBE, sculpt, parts[i - 1], shard=f"{i}/3")
    with pytest.raises(dispex.Error, match="shard 2/3") as raised:
        dispex.merge([parts[0], parts[2]], tmp_path / "merged.ptx")
    assert "\n" not in str(raised.value)
    assert not (tmp_path / "merged.ptx").exists()


@pytest.mark.parametrize("options, message", [
    ({"shard": "4/3"}, "shard: '4/3': expected I/N"),
    ({"shard": "1/2", "shard_sculpt": "half"}, "shard_sculpt: unknown shard sculpt 'half'"),
])
def test_bad_shard_options_raise_value_error(tmp_path, sculpts, options, message):
    with pytest.raises(ValueError, match=message):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "part.ptx", **options)
    assert not (tmp_path / "part.ptx").exists()


def test_a_shard_of_the_wrong_type_raises_type_error(tmp_path, sculpts):
    with pytest.raises(TypeError, match="shard: 2 is not a string"):
        dispex.extract(CUBE, sculpts(CUBE), tmp_path / "part.ptx", shard=2)


def test_shards_of_meshes_in_memory_are_refused(tmp_path, sculpts):
    with pytest.raises(ValueError, match="base and sculpt must be paths"):
        dispex.extract(dispex.read_mesh(CUBE), sculpts(CUBE), tmp_path / "part.ptx", shard="1/2")


@pytest.mark.parametrize("parts, options, error, message", [
    ("part.ptx", {}, TypeError, "is one path, not a list"),
    ([3], {}, TypeError, r"parts\[0\]: 3 is not a path"),
    (["part.ptx"], {"threads": 1.5}, TypeError, "threads: 1.5 is not an integer"),
    (["part.ptx"], {"max_memory": -1}, ValueError, r"max_memory = -1: must be >= 0"),
])
def test_bad_merge_arguments_raise_value_or_type_error(tmp_path, parts, options, error, message):
    with pytest.raises(error, match=message):
        dispex.merge(parts, tmp_path / "merged.ptx", **options)
