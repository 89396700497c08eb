"""Meshes as NumPy arrays: wrong dtypes, shapes, non-finite points and indices out of range
raise ValueError naming the argument and the array."""
import numpy as np
import pytest

import dispex
from conftest import CUBE

QUAD_POINTS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float32)


def quad(**changes):
    arrays = {"points": QUAD_POINTS, "face_vertex_counts": np.array([4]),
              "face_vertex_indices": np.array([0, 1, 2, 3])}
    arrays.update(changes)
    return arrays


def test_a_good_mesh_keeps_its_arrays():
    mesh = dispex.Mesh(**quad(), name="quad.obj")
    assert (mesh.num_vertices, mesh.num_faces, mesh.name) == (4, 1, "quad.obj")
    assert np.array_equal(mesh.points, QUAD_POINTS)
    assert list(mesh.face_vertex_indices) == [0, 1, 2, 3]


def test_read_mesh_gives_the_files_arrays():
    mesh = dispex.read_mesh(CUBE)
    assert (mesh.num_vertices, mesh.num_faces) == (8, 6)
    assert list(mesh.face_vertex_counts) == [4] * 6
    assert mesh.face_vertex_indices.max() == 7


@pytest.mark.parametrize("changes, message", [
    ({"points": QUAD_POINTS[:, :2]}, r"base\.points: shape \(4, 2\), expected \(N, 3\)"),
    ({"points": np.where(QUAD_POINTS == 1, np.nan, QUAD_POINTS)},
     r"base\.points\[1\]: not finite"),
    ({"points": QUAD_POINTS * 1e39}, r"base\.points\[1\]: not finite \(as float32\)"),
    ({"face_vertex_counts": np.array([2, 2])},
     r"base\.face_vertex_counts\[0\]: 2 vertices, fewer than 3"),
    ({"face_vertex_counts": np.array([5])},
     r"base\.face_vertex_counts: they add up to 5, but face_vertex_indices has 4"),
    ({"face_vertex_indices": np.array([0, 1, 2, 4])},
     r"base\.face_vertex_indices\[3\]: index 4 out of range \(4 vertices\)"),
    ({"face_vertex_indices": np.array([0, 1, 2, -1])},
     r"base\.face_vertex_indices\[3\]: index -1 out of range"),
    ({"face_vertex_indices": np.array([[0, 1, 2, 3]])},
     r"base\.face_vertex_indices: shape \(1, 4\), expected \(N,\)"),
    ({"crease_edges": np.array([[0, 9]])}, r"base\.crease_edges\[1\]: index 9 out of range"),
    ({"holes": np.array([1])}, r"base\.holes\[0\]: index 1 out of range \(1 faces\)"),
    ({"face_groups": np.array([0])}, r"base\.face_groups: needs group_names"),
])
def test_bad_arrays_raise_value_error_naming_them(tmp_path, changes, message):
    with pytest.raises(ValueError, match=message):
        dispex.extract(quad(**changes), CUBE, tmp_path / "m.ptx")
    assert not (tmp_path / "m.ptx").exists()


@pytest.mark.parametrize("changes, message", [
    ({"points": QUAD_POINTS.astype(np.int32)}, r"base\.points: dtype int32 is not a float type"),
    ({"face_vertex_counts": np.array([4.0])},
     r"base\.face_vertex_counts: dtype float64 is not an integer type"),
    ({"uvs": np.array([["a", "b"]])}, r"base\.uvs: dtype <U1 is not a float type"),
])
def test_arrays_of_the_wrong_type_raise_type_error(tmp_path, changes, message):
    arrays = quad(**changes)
    if "uvs" in changes:
        arrays["face_uv_indices"] = np.zeros(4, dtype=np.int32)
    with pytest.raises(TypeError, match=message):
        dispex.extract(arrays, CUBE, tmp_path / "m.ptx")
    assert not (tmp_path / "m.ptx").exists()


def test_a_missing_array_is_named():
    with pytest.raises(ValueError, match="sculpt: no face_vertex_indices array"):
        arrays = quad()
        del arrays["face_vertex_indices"]
        dispex.extract(CUBE, arrays, "m.ptx")


def test_neither_path_nor_mesh():
    with pytest.raises(TypeError, match="base: 3 is neither a path, a dispex.Mesh nor a dict"):
        dispex.extract(3, CUBE, "m.ptx")


def test_subdivision_rules_by_name():
    mesh = dispex.Mesh(**quad(), boundary_interpolation="edge_only", crease_method="chaikin")
    assert mesh.subdivision_rules == {"boundary_interpolation": "edge_only",
                                      "crease_method": "chaikin"}
    with pytest.raises(ValueError, match="boundary_interpolation: 'sharp' is not one of none, "
                                         "edge_only, edge_and_corner"):
        dispex.Mesh(**quad(), boundary_interpolation="sharp")
