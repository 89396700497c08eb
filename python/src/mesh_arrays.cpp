#include "mesh_arrays.h"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dispex/mesh_summary.h"
#include "errors.h"

namespace dispex::python {

namespace {

// The array `value` of one of `kinds` ("f": floats; "iu": integers), `ndim` dimensions, the
// last of `columns` (0: any); a ValueError naming `what` otherwise.
py::array Checked(const py::handle& value, const std::string& what, const char* kinds, int ndim,
                  py::ssize_t columns) {
  py::array a = py::array::ensure(value);
  if (!a) throw py::type_error(fmt::format("{}: not an array", what));
  const char kind = a.dtype().kind();
  if (std::string(kinds).find(kind) == std::string::npos) {
    throw py::type_error(
        fmt::format("{}: dtype {} is not {}", what, py::str(a.dtype()).cast<std::string>(),
                    std::string(kinds) == "f" ? "a float type" : "an integer type"));
  }
  if (a.ndim() != ndim || (columns > 0 && a.shape(ndim - 1) != columns)) {
    std::string shape;
    for (py::ssize_t d = 0; d < a.ndim(); ++d)
      shape += fmt::format("{}{}", d ? ", " : "", a.shape(d));
    throw py::value_error(fmt::format("{}: shape ({}), expected {}", what, shape,
                                      ndim == 1 ? "(N,)" : fmt::format("(N, {})", columns)));
  }
  return a;
}

std::vector<std::int64_t> Integers(const py::handle& value, const std::string& what, int ndim = 1,
                                   py::ssize_t columns = 0) {
  py::array a = Checked(value, what, "iu", ndim, columns);
  if (a.dtype().kind() == 'u' && a.dtype().itemsize() == 8) {
    auto u = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    for (py::ssize_t i = 0; i < u.size(); ++i) {
      if (u.data()[i] > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        throw py::value_error(
            fmt::format("{}: value {} at {} is out of range", what, u.data()[i], i));
      }
    }
  }
  auto c = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  return {c.data(), c.data() + c.size()};
}

std::vector<double> Floats(const py::handle& value, const std::string& what, int ndim = 1,
                           py::ssize_t columns = 0) {
  py::array a = Checked(value, what, "f", ndim, columns);
  auto c = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  return {c.data(), c.data() + c.size()};
}

// Index `k` of `values`, named `what`, must lie in [0, limit).
void CheckIndices(const std::vector<std::int64_t>& values, std::int64_t limit,
                  const std::string& what, const char* of) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (values[k] < 0 || values[k] >= limit) {
      throw py::value_error(
          fmt::format("{}[{}]: index {} out of range ({} {})", what, k, values[k], limit, of));
    }
  }
}

std::vector<float> Sharpness(const py::handle& value, const std::string& what, std::size_t n) {
  if (value.is_none()) return std::vector<float>(n, 10.0f);  // infinitely sharp
  std::vector<double> s = Floats(value, what);
  if (s.size() != n) {
    throw py::value_error(fmt::format("{}: {} values for {} elements", what, s.size(), n));
  }
  return {s.begin(), s.end()};
}

// A subdivision rule by its library name (dispex/mesh_summary.h), as OBJ `t` tags set it.
template <class Enum, std::size_t N>
Enum ParseRule(const std::string& name, const std::array<Enum, N>& values,
               std::string_view (*name_of)(Enum), const std::string& what) {
  std::string known;
  for (Enum value : values) {
    if (name == name_of(value)) return value;
    known += fmt::format("{}{}", known.empty() ? "" : ", ", name_of(value));
  }
  throw py::value_error(fmt::format("{}: '{}' is not one of {}", what, name, known));
}

struct Rules {
  std::optional<std::string> boundary, crease_method, triangles;
};

// Rules given by name are set as a file's tags set them (from_file); the others keep the
// defaults a file without the tag has.
void SetRules(Mesh& mesh, const Rules& rules, const std::string& at) {
  SubdivTags& t = mesh.tags;
  if (rules.boundary) {
    t.boundary =
        ParseRule(*rules.boundary,
                  std::array{BoundaryInterpolation::kNone, BoundaryInterpolation::kEdgeOnly,
                             BoundaryInterpolation::kEdgeAndCorner},
                  BoundaryInterpolationName, at + "boundary_interpolation");
    t.boundary_from_file = true;
  }
  if (rules.crease_method) {
    t.crease_method =
        ParseRule(*rules.crease_method, std::array{CreaseMethod::kUniform, CreaseMethod::kChaikin},
                  CreaseMethodName, at + "crease_method");
    t.crease_method_from_file = true;
  }
  if (rules.triangles) {
    t.triangles = ParseRule(*rules.triangles,
                            std::array{TriangleSubdivision::kCatmark, TriangleSubdivision::kSmooth},
                            TriangleSubdivisionName, at + "triangle_subdivision");
    t.triangles_from_file = true;
  }
}

PyMesh MakeMesh(const py::handle& points, const py::handle& counts, const py::handle& indices,
                const py::handle& crease_edges, const py::handle& crease_sharpness,
                const py::handle& corner_vertices, const py::handle& corner_sharpness,
                const py::handle& holes, const py::handle& face_groups,
                const std::optional<std::vector<std::string>>& group_names, const Rules& rules,
                const py::handle& uvs, const py::handle& face_uv_indices, const std::string& name,
                const std::string& argument) {
  const std::string at = argument.empty() ? "" : argument + ".";
  Mesh mesh;
  mesh.source = argument.empty() ? (name.empty() ? "mesh" : name) : argument;
  const std::vector<double> xyz = Floats(points, at + "points", 2, 3);
  const std::size_t n = xyz.size() / 3;
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw py::value_error(fmt::format("{}points: {} vertices, more than 2^31 - 1", at, n));
  }
  mesh.positions.reserve(n + 1);  // Embree reads 16 bytes at the last vertex
  for (std::size_t v = 0; v < n; ++v) {
    const float p[3] = {static_cast<float>(xyz[3 * v]), static_cast<float>(xyz[3 * v + 1]),
                        static_cast<float>(xyz[3 * v + 2])};
    for (float c : p) {
      if (!std::isfinite(c)) {
        throw py::value_error(fmt::format("{}points[{}]: not finite (as float32)", at, v));
      }
    }
    mesh.positions.push_back({p[0], p[1], p[2]});
  }
  const std::vector<std::int64_t> sizes = Integers(counts, at + "face_vertex_counts");
  const std::vector<std::int64_t> ids = Integers(indices, at + "face_vertex_indices");
  if (sizes.empty()) throw py::value_error(fmt::format("{}face_vertex_counts: no faces", at));
  mesh.face_offsets.reserve(sizes.size() + 1);
  mesh.face_offsets.push_back(0);
  std::uint64_t total = 0;
  for (std::size_t f = 0; f < sizes.size(); ++f) {
    if (sizes[f] < 3) {
      throw py::value_error(
          fmt::format("{}face_vertex_counts[{}]: {} vertices, fewer than 3", at, f, sizes[f]));
    }
    total += static_cast<std::uint64_t>(sizes[f]);
    if (total > ids.size()) break;
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(total));
  }
  if (total != ids.size()) {
    throw py::value_error(
        fmt::format("{}face_vertex_counts: they add up to {}, but "
                    "face_vertex_indices has {} entries",
                    at, total, ids.size()));
  }
  CheckIndices(ids, static_cast<std::int64_t>(n), at + "face_vertex_indices", "vertices");
  mesh.face_indices.assign(ids.begin(), ids.end());

  if (!crease_edges.is_none()) {
    const std::vector<std::int64_t> e = Integers(crease_edges, at + "crease_edges", 2, 2);
    CheckIndices(e, static_cast<std::int64_t>(n), at + "crease_edges", "vertices");
    const std::vector<float> s = Sharpness(crease_sharpness, at + "crease_sharpness", e.size() / 2);
    for (std::size_t k = 0; k < s.size(); ++k) {
      mesh.tags.creases.push_back({VertexId(static_cast<std::int32_t>(e[2 * k])),
                                   VertexId(static_cast<std::int32_t>(e[2 * k + 1])), s[k]});
    }
  } else if (!crease_sharpness.is_none()) {
    throw py::value_error(fmt::format("{}crease_sharpness: given without crease_edges", at));
  }
  if (!corner_vertices.is_none()) {
    const std::vector<std::int64_t> c = Integers(corner_vertices, at + "corner_vertices");
    CheckIndices(c, static_cast<std::int64_t>(n), at + "corner_vertices", "vertices");
    const std::vector<float> s = Sharpness(corner_sharpness, at + "corner_sharpness", c.size());
    for (std::size_t k = 0; k < c.size(); ++k) {
      mesh.tags.corners.push_back({VertexId(static_cast<std::int32_t>(c[k])), s[k]});
    }
  } else if (!corner_sharpness.is_none()) {
    throw py::value_error(fmt::format("{}corner_sharpness: given without corner_vertices", at));
  }
  if (!holes.is_none()) {
    const std::vector<std::int64_t> h = Integers(holes, at + "holes");
    CheckIndices(h, static_cast<std::int64_t>(sizes.size()), at + "holes", "faces");
    for (std::int64_t f : h) mesh.tags.holes.push_back(BaseFaceId(static_cast<std::int32_t>(f)));
  }
  if (!face_groups.is_none()) {
    if (!group_names) throw py::value_error(fmt::format("{}face_groups: needs group_names", at));
    const std::vector<std::int64_t> g = Integers(face_groups, at + "face_groups");
    if (g.size() != sizes.size()) {
      throw py::value_error(
          fmt::format("{}face_groups: {} entries for {} faces", at, g.size(), sizes.size()));
    }
    CheckIndices(g, static_cast<std::int64_t>(group_names->size()), at + "face_groups",
                 "group names");
    mesh.face_groups.assign(g.begin(), g.end());
    mesh.group_names = *group_names;
  } else if (group_names) {
    throw py::value_error(fmt::format("{}group_names: given without face_groups", at));
  }
  if (!uvs.is_none() && !face_uv_indices.is_none()) {
    const std::vector<double> uv = Floats(uvs, at + "uvs", 2, 2);
    for (std::size_t k = 0; k < uv.size(); ++k) {
      if (!std::isfinite(static_cast<float>(uv[k]))) {
        throw py::value_error(fmt::format("{}uvs[{}]: not finite (as float32)", at, k / 2));
      }
    }
    const std::vector<std::int64_t> corners = Integers(face_uv_indices, at + "face_uv_indices");
    if (corners.size() != ids.size()) {
      throw py::value_error(fmt::format(
          "{}face_uv_indices: {} entries, but the faces have {} corners (one UV index each)", at,
          corners.size(), ids.size()));
    }
    CheckIndices(corners, static_cast<std::int64_t>(uv.size() / 2), at + "face_uv_indices", "UVs");
    mesh.uvs.assign(uv.begin(), uv.end());
    mesh.face_uv_indices.assign(corners.begin(), corners.end());
  } else if (!uvs.is_none() || !face_uv_indices.is_none()) {
    throw py::value_error(uvs.is_none() ? fmt::format("{}face_uv_indices: given without uvs", at)
                                        : fmt::format("{}uvs: given without face_uv_indices", at));
  }
  SetRules(mesh, rules, at);
  CheckArgument(CheckMeshArrays(mesh));
  return PyMesh{std::make_shared<const Mesh>(std::move(mesh)), name};
}

// dispex.Mesh's arguments: the arrays it needs, and the keyword-only ones (dispex.extract checks
// a dict of arrays against them too: dispex._dispex._mesh_keywords).
const std::array<const char*, 3> kPositional = {"points", "face_vertex_counts",
                                                "face_vertex_indices"};
const std::array<const char*, 13> kKeywords = {"crease_edges",
                                               "crease_sharpness",
                                               "corner_vertices",
                                               "corner_sharpness",
                                               "holes",
                                               "face_groups",
                                               "group_names",
                                               "boundary_interpolation",
                                               "crease_method",
                                               "uvs",
                                               "face_uv_indices",
                                               "triangle_subdivision",
                                               "name"};

// The arguments of dispex.Mesh(...), checked as the signature in its docstring says
// (TypeError naming what is wrong), without pybind11's own argument types in the messages.
// `_argument` (the name dispex.extract gives a dict of arrays in errors) is not documented.
PyMesh MeshFromArguments(const py::args& args, const py::kwargs& kwargs) {
  if (args.size() > kPositional.size()) {
    throw py::type_error(fmt::format(
        "Mesh: takes 3 positional arguments (points, face_vertex_counts, face_vertex_indices), "
        "{} given",
        args.size()));
  }
  py::dict given;
  for (std::size_t k = 0; k < args.size(); ++k) given[kPositional[k]] = args[k];
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const bool known = name == "_argument" ||
                       std::find_if(kKeywords.begin(), kKeywords.end(),
                                    [&](const char* k) { return name == k; }) != kKeywords.end() ||
                       std::find_if(kPositional.begin(), kPositional.end(),
                                    [&](const char* k) { return name == k; }) != kPositional.end();
    if (!known) {
      std::string names;
      for (const char* k : kKeywords) names += fmt::format("{}{}", names.empty() ? "" : ", ", k);
      throw py::type_error(fmt::format("Mesh: unknown keyword '{}' (known: {})", name, names));
    }
    if (given.contains(key)) throw py::type_error(fmt::format("Mesh: {} given twice", name));
    given[key] = value;
  }
  for (const char* name : kPositional) {
    if (!given.contains(name)) throw py::type_error(fmt::format("Mesh: no {} given", name));
  }
  auto get = [&](const char* name) -> py::object {
    return given.contains(name) ? py::object(given[name]) : py::object(py::none());
  };
  auto text = [&](const char* name) -> std::optional<std::string> {
    py::object value = get(name);
    if (value.is_none()) return std::nullopt;
    if (!py::isinstance<py::str>(value)) {
      throw py::type_error(fmt::format("{}: {} is not a string", name, Shown(value)));
    }
    return value.cast<std::string>();
  };
  std::optional<std::vector<std::string>> group_names;
  if (py::object names = get("group_names"); !names.is_none()) {
    if (py::isinstance<py::str>(names)) {
      throw py::type_error("group_names: a string, not a list of names");
    }
    group_names.emplace();
    for (py::handle n : names) {
      if (!py::isinstance<py::str>(n)) {
        throw py::type_error(fmt::format("group_names: {} is not a string", Shown(n)));
      }
      group_names->push_back(n.cast<std::string>());
    }
  }
  return MakeMesh(
      get("points"), get("face_vertex_counts"), get("face_vertex_indices"), get("crease_edges"),
      get("crease_sharpness"), get("corner_vertices"), get("corner_sharpness"), get("holes"),
      get("face_groups"), group_names,
      Rules{text("boundary_interpolation"), text("crease_method"), text("triangle_subdivision")},
      get("uvs"), get("face_uv_indices"), text("name").value_or(""),
      text("_argument").value_or(""));
}

template <class T>
py::array_t<T> ToArray(const std::vector<T>& values) {
  return py::array_t<T>(static_cast<py::ssize_t>(values.size()), values.data());
}

}  // namespace

void AddMesh(py::module_& module) {
  py::class_<PyMesh>(
      module, "Mesh",
      "A polygon mesh (a base cage or a sculpt) from NumPy arrays: points (N, 3) "
      "floats, face_vertex_counts (F,) and face_vertex_indices (sum of counts,) "
      "integers; optional subdivision tags (crease_edges (K, 2) with "
      "crease_sharpness (K,), corner_vertices with corner_sharpness, holes: face "
      "ids; sharpness defaults to 10, infinitely sharp) and groups (face_groups "
      "(F,) indices into group_names); texture coordinates (uvs (M, 2) floats with "
      "face_uv_indices, one index into uvs per face corner, laid out as "
      "face_vertex_indices: what UV-space maps need); the subdivision rules OBJ `t` tags set "
      "(boundary_interpolation: none, edge_only, edge_and_corner; "
      "crease_method: uniform, chaikin; triangle_subdivision: catmark, smooth; "
      "None: a file's default). `name`: the file name the mesh stands for "
      "in reports and maps. Wrong dtypes, shapes, non-finite points and indices "
      "out of range raise ValueError naming the array, a value that is not an array "
      "TypeError.")
      .def(py::init([](const py::args& args, const py::kwargs& kwargs) {
             return MeshFromArguments(args, kwargs);
           }),
           "Mesh(points, face_vertex_counts, face_vertex_indices, *, crease_edges=None, "
           "crease_sharpness=None, corner_vertices=None, corner_sharpness=None, holes=None, "
           "face_groups=None, group_names=None, boundary_interpolation=None, crease_method=None, "
           "triangle_subdivision=None, uvs=None, face_uv_indices=None, name='')")
      .def_readonly("name", &PyMesh::name, "The file name the mesh stands for in reports and maps")
      .def_property_readonly(
          "num_vertices", [](const PyMesh& m) { return m.mesh->num_vertices(); }, "Vertices")
      .def_property_readonly(
          "num_faces", [](const PyMesh& m) { return m.mesh->num_faces(); }, "Faces")
      .def_property_readonly(
          "points",
          [](const PyMesh& m) {
            py::array_t<float> a(
                {static_cast<py::ssize_t>(m.mesh->num_vertices()), py::ssize_t{3}});
            std::memcpy(a.mutable_data(), m.mesh->positions.data(),
                        m.mesh->num_vertices() * sizeof(Float3));
            return a;
          },
          "(N, 3) float32: the vertex positions")
      .def_property_readonly(
          "face_vertex_counts",
          [](const PyMesh& m) {
            std::vector<std::int32_t> counts(m.mesh->num_faces());
            for (std::size_t f = 0; f < counts.size(); ++f) {
              counts[f] = m.mesh->face_size(f);
            }
            return ToArray(counts);
          },
          "(F,) int32: each face's number of vertices")
      .def_property_readonly(
          "face_vertex_indices", [](const PyMesh& m) { return ToArray(m.mesh->face_indices); },
          "The faces' vertex indices, face after face")
      .def_property_readonly(
          "crease_edges",
          [](const PyMesh& m) {
            const auto& c = m.mesh->tags.creases;
            py::array_t<std::int32_t> a({static_cast<py::ssize_t>(c.size()), py::ssize_t{2}});
            for (std::size_t k = 0; k < c.size(); ++k) {
              a.mutable_at(k, 0) = c[k].v0.value;
              a.mutable_at(k, 1) = c[k].v1.value;
            }
            return a;
          },
          "(K, 2) int32: the vertex pairs of creased edges")
      .def_property_readonly(
          "crease_sharpness",
          [](const PyMesh& m) {
            std::vector<float> s;
            for (const auto& c : m.mesh->tags.creases) s.push_back(c.sharpness);
            return ToArray(s);
          },
          "(K,) float32: each creased edge's sharpness (10: infinitely sharp)")
      .def_property_readonly(
          "holes",
          [](const PyMesh& m) {
            std::vector<std::int32_t> h;
            for (BaseFaceId f : m.mesh->tags.holes) h.push_back(f.value);
            return ToArray(h);
          },
          "The face ids tagged as holes")
      .def_property_readonly(
          "face_groups", [](const PyMesh& m) { return ToArray(m.mesh->face_groups); },
          "(F,) int32: each face's index into group_names (empty: no groups)")
      .def_property_readonly(
          "group_names", [](const PyMesh& m) { return m.mesh->group_names; },
          "The o/g group names face_groups indexes")
      .def_property_readonly(
          "uvs",
          [](const PyMesh& m) {
            py::array_t<float> a({static_cast<py::ssize_t>(m.mesh->num_uvs()), py::ssize_t{2}});
            std::copy(m.mesh->uvs.begin(), m.mesh->uvs.end(), a.mutable_data());
            return a;
          },
          "(M, 2) float32: the texture coordinates (u, v); empty when the mesh has none")
      .def_property_readonly(
          "face_uv_indices", [](const PyMesh& m) { return ToArray(m.mesh->face_uv_indices); },
          "One index into uvs per face corner, laid out as face_vertex_indices")
      .def_property_readonly(
          "corner_vertices",
          [](const PyMesh& m) {
            std::vector<std::int32_t> v;
            for (const auto& c : m.mesh->tags.corners) v.push_back(c.vertex.value);
            return ToArray(v);
          },
          "The vertex ids tagged as corners")
      .def_property_readonly(
          "corner_sharpness",
          [](const PyMesh& m) {
            std::vector<float> s;
            for (const auto& c : m.mesh->tags.corners) s.push_back(c.sharpness);
            return ToArray(s);
          },
          "Each corner's sharpness")
      .def_property_readonly(
          "subdivision_rules",
          [](const PyMesh& m) {
            // The rules tags set, by name, as the constructor takes them.
            const SubdivTags& t = m.mesh->tags;
            py::dict d;
            if (t.boundary_from_file)
              d["boundary_interpolation"] = std::string(BoundaryInterpolationName(t.boundary));
            if (t.crease_method_from_file)
              d["crease_method"] = std::string(CreaseMethodName(t.crease_method));
            if (t.triangles_from_file)
              d["triangle_subdivision"] = std::string(TriangleSubdivisionName(t.triangles));
            return d;
          },
          "The subdivision rules tags set, by name, as the constructor takes them")
      .def("__repr__", [](const PyMesh& m) {
        return fmt::format("<dispex.Mesh {}: {} vertices, {} faces>",
                           m.name.empty() ? "(unnamed)" : m.name, m.mesh->num_vertices(),
                           m.mesh->num_faces());
      });

  module.def("_mesh_keywords",
             [] { return std::vector<std::string>(kKeywords.begin(), kKeywords.end()); });
  module.def(
      "read_mesh",
      [](const std::string& path) {
        Mesh mesh = ValueOrRaise(ReadMesh(path));
        const std::string name = mesh.source;
        return PyMesh{std::make_shared<const Mesh>(std::move(mesh)), name};
      },
      py::arg("path"), "Reads an OBJ or PLY file into a dispex.Mesh (its name: the path).");
}

}  // namespace dispex::python
