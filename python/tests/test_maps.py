"""Reading a map back: faces, resolutions, adjacency, meta data, texels, and sampling."""
import numpy as np
import pytest

import dispex
from conftest import CUBE, run_cli


@pytest.fixture(scope="module")
def fixed_map(tmp_path_factory, sculpts):
    """A map whose faces are 8 x 4 texels: u and v are told apart."""
    path = tmp_path_factory.mktemp("maps") / "fixed.ptx"
    dispex.extract(CUBE, sculpts(CUBE), path, resolution_rule="fixed", fixed_resolution="8x4")
    return dispex.Map(path)


def test_faces_resolutions_and_adjacency(fixed_map):
    assert fixed_map.num_faces == 6 and fixed_map.num_channels == 1
    assert fixed_map.data_type == "float32" and fixed_map.mesh_type == "quad"
    assert fixed_map.resolutions.tolist() == [[8, 4]] * 6
    adjacent = fixed_map.adjacent_faces
    edges = fixed_map.adjacent_edges
    assert adjacent.shape == (6, 4) and (adjacent >= 0).all()  # a closed cube
    for f in range(6):
        for e in range(4):  # every neighbour names this face back across the shared edge
            g, back = adjacent[f, e], edges[f, e]
            assert adjacent[g, back] == f and edges[g, back] == e
    assert not fixed_map.subfaces.any()


def test_meta_data(fixed_map):
    meta = fixed_map.meta
    assert meta["dispex:version"] == dispex.__version__
    assert meta["dispex:base"] == CUBE.name
    assert list(meta["PtexFaceVertCounts"]) == [4] * 6
    assert meta["PtexVertPositions"].shape == (24,)


def test_texels_are_the_command_lines_dump(fixed_map):
    texels = fixed_map.texels(2)
    assert texels.shape == (4, 8, 1) and texels.dtype == np.float32
    dump = run_cli("info", fixed_map.path, "--dump", "2").stdout
    numbers = [float(x) for line in dump.splitlines() for x in line.split()
               if x.lstrip("-").replace(".", "", 1).replace("e-", "", 1).isdigit()]
    assert np.allclose(sorted(numbers)[-32:], sorted(texels.ravel()), rtol=1e-5) or \
        np.allclose(numbers[-32:], texels.ravel(), rtol=1e-5)


def test_sampling_at_texel_centres_gives_the_texels(fixed_map):
    """Per face, bilinear reading at a texel's centre is that texel: row j is v, column i u."""
    face = 3
    texels = fixed_map.texels(face)[:, :, 0]
    j, i = np.meshgrid(np.arange(4), np.arange(8), indexing="ij")
    u = (i.ravel() + 0.5) / 8
    v = (j.ravel() + 0.5) / 4
    values = fixed_map.sample(np.full(u.size, face), u, v)
    assert np.allclose(values, texels.ravel(), rtol=0, atol=1e-6)
    across = fixed_map.sample(np.full(u.size, face), u, v, across_faces=True)
    inner = (i.ravel() > 0) & (i.ravel() < 7) & (j.ravel() > 0) & (j.ravel() < 3)
    assert np.allclose(across[inner], texels.ravel()[inner], rtol=0, atol=1e-6)


@pytest.mark.parametrize("faces, u, v, message", [
    ([6], [0.5], [0.5], "face 6 out of range"),
    ([0], [1.5], [0.5], r"u\[0\] = 1.5: not in \[0, 1\]"),
    ([0], [0.5], [np.nan], r"v\[0\] = nan: not in \[0, 1\]"),
    ([0, 1], [0.5], [0.5], "faces, u and v: 2, 1 and 1 values"),
])
def test_bad_sample_arguments(fixed_map, faces, u, v, message):
    with pytest.raises(ValueError, match=message):
        fixed_map.sample(np.array(faces), np.array(u), np.array(v))


def test_sample_arguments_of_the_wrong_type(fixed_map):
    with pytest.raises(TypeError, match="faces: expected a 1-D array of integers"):
        fixed_map.sample(np.array([0.5]), np.array([0.5]), np.array([0.5]))


def test_a_file_that_is_not_a_map_raises_dispex_error(tmp_path):
    bad = tmp_path / "bad.ptx"
    bad.write_bytes(b"not a ptex file at all")
    with pytest.raises(dispex.Error, match="bad.ptx"):
        dispex.Map(bad)
