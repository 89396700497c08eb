// dispex.Map: a Ptex map read back -- its faces, resolutions, adjacency, meta data, each face's
// texels as a NumPy array -- and sampled at (face, u, v) arrays as renderers read it.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bindings.h"
#include "dispex/ptex.h"
#include "dispex/ptex_sampler.h"
#include "errors.h"

namespace dispex::python {

namespace {

struct PyMap {
  std::shared_ptr<const PtexFile> file;
  // For sampling across faces: the face records and per channel each face's texels, read on
  // first use.
  std::vector<PtexFaceInfo> faces;
  std::vector<std::vector<std::vector<float>>> channels;
  std::vector<std::unique_ptr<PtexMapSampler>> samplers;
  std::mutex mutex;
};

std::shared_ptr<PyMap> Open(const std::string& path) {
  auto map = std::make_shared<PyMap>();
  map->file = std::make_shared<const PtexFile>(ValueOrRaise(PtexFile::Open(path)));
  return map;
}

// The open file; ValueError once the map is closed, as Python's files raise.
const PtexFile& File(const PyMap& map) {
  if (!map.file) throw py::value_error("the dispex.Map is closed");
  return *map.file;
}

void Close(PyMap& map) {
  std::lock_guard lock(map.mutex);
  map.samplers.clear();
  map.channels.clear();
  map.faces.clear();
  map.file.reset();
}

std::string Repr(const PyMap& map) {
  if (!map.file) return "<dispex.Map (closed)>";
  const PtexFile& file = *map.file;
  return fmt::format("<dispex.Map {}: {} faces, {} channel{}, {}>", file.name(), file.num_faces(),
                     file.header().num_channels, file.header().num_channels == 1 ? "" : "s",
                     PtexDataTypeName(file.header().data_type));
}

PtexFaceId Face(const PyMap& map, long long face) {
  File(map);
  if (face < 0 || face >= map.file->num_faces()) {
    throw py::value_error(fmt::format("face {} out of range ({} faces in {})", face,
                                      map.file->num_faces(), map.file->name()));
  }
  return PtexFaceId(static_cast<std::int32_t>(face));
}

py::array_t<float> Texels(const PyMap& map, long long face, int level) {
  const PtexFaceId id = Face(map, face);
  const PtexFile& file = File(map);
  if (level < 0 || level >= file.NumStoredLevels(id)) {
    throw py::value_error(fmt::format("level {}: face {} has {} stored levels", level, face,
                                      file.NumStoredLevels(id)));
  }
  std::vector<float> texels;
  CheckOk(file.ReadFace(id, level, texels));
  const PtexFaceInfo& info = file.face_info(id);
  const int channels = file.header().num_channels;
  const py::ssize_t u = info.ures() >> level, v = info.vres() >> level;
  py::array_t<float> out({v, u, static_cast<py::ssize_t>(channels)});
  std::copy(texels.begin(), texels.end(), out.mutable_data());
  return out;
}

py::object MetaValue(const PtexMetaItem& item) {
  if (item.type == PtexMetaType::kString) return py::str(item.AsString());
  const std::vector<double> values = item.AsNumbers();
  switch (item.type) {
    case PtexMetaType::kInt8:
    case PtexMetaType::kInt16:
    case PtexMetaType::kInt32: {
      py::array_t<std::int64_t> a(static_cast<py::ssize_t>(values.size()));
      for (std::size_t i = 0; i < values.size(); ++i) {
        a.mutable_data()[i] = static_cast<std::int64_t>(values[i]);
      }
      return a;
    }
    default:
      return py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
  }
}

const PtexMapSampler& Sampler(PyMap& map, int channel) {
  std::lock_guard lock(map.mutex);
  const PtexFile& file = *map.file;
  const int channels = file.header().num_channels;
  if (map.samplers.empty()) {
    map.faces.resize(static_cast<std::size_t>(file.num_faces()));
    map.channels.assign(static_cast<std::size_t>(channels),
                        std::vector<std::vector<float>>(map.faces.size()));
    map.samplers.resize(static_cast<std::size_t>(channels));
    std::vector<float> texels;
    for (std::size_t f = 0; f < map.faces.size(); ++f) {
      const PtexFaceId id(static_cast<std::int32_t>(f));
      map.faces[f] = file.face_info(id);
      CheckOk(file.ReadFace(id, 0, texels));
      for (int c = 0; c < channels; ++c) {
        std::vector<float>& out = map.channels[static_cast<std::size_t>(c)][f];
        out.resize(texels.size() / static_cast<std::size_t>(channels));
        for (std::size_t t = 0; t < out.size(); ++t) {
          out[t] = texels[t * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)];
        }
      }
    }
  }
  auto& sampler = map.samplers[static_cast<std::size_t>(channel)];
  if (!sampler) {
    sampler = std::make_unique<PtexMapSampler>(map.faces,
                                               map.channels[static_cast<std::size_t>(channel)]);
  }
  return *sampler;
}

// The map at (faces[i], u[i], v[i]): per face (PtexFile::Sample, bilinear within the face) or
// across faces (the reference Ptex filter, PtexMapSampler::SampleAcrossFaces). One channel:
// (n,); every channel (channel None): (n,) for a scalar map, (n, channels) for a vector map.
py::array_t<double> Sample(PyMap& map, const py::handle& faces_in, const py::handle& u_in,
                           const py::handle& v_in, const std::optional<int>& channel,
                           bool across_faces) {
  auto as_array = [](const py::handle& h, const char* name, char kind) {
    py::array a = py::array::ensure(h);
    if (!a || a.ndim() > 1 ||
        std::string(kind == 'i' ? "iu" : "fiu").find(a.dtype().kind()) == std::string::npos) {
      throw py::type_error(fmt::format("{}: expected a 1-D array of {}", name,
                                       kind == 'i' ? "integers" : "numbers"));
    }
    return a;
  };
  auto faces =
      py::array_t<std::int64_t, py::array::forcecast>::ensure(as_array(faces_in, "faces", 'i'));
  auto u = py::array_t<double, py::array::forcecast>::ensure(as_array(u_in, "u", 'f'));
  auto v = py::array_t<double, py::array::forcecast>::ensure(as_array(v_in, "v", 'f'));
  if (faces.size() != u.size() || faces.size() != v.size()) {
    throw py::value_error(fmt::format("faces, u and v: {}, {} and {} values, not the same number",
                                      faces.size(), u.size(), v.size()));
  }
  const int channels = File(map).header().num_channels;
  if (channel && (*channel < 0 || *channel >= channels)) {
    throw py::value_error(fmt::format("channel {}: the map has {}", *channel, channels));
  }
  for (py::ssize_t i = 0; i < faces.size(); ++i) {
    Face(map, faces.data()[i]);
    for (const auto& [name, a] : {std::pair{"u", &u}, std::pair{"v", &v}}) {
      const double x = a->data()[i];
      if (!(x >= 0 && x <= 1)) {
        throw py::value_error(fmt::format("{}[{}] = {}: not in [0, 1]", name, i, x));
      }
    }
  }
  const int first = channel.value_or(0), count = channel ? 1 : channels;
  py::array_t<double> out = count == 1 ? py::array_t<double>(faces.size())
                                       : py::array_t<double>({faces.size(), py::ssize_t{count}});
  double* values = out.mutable_data();
  for (int c = first; c < first + count; ++c) {
    const PtexMapSampler* sampler = across_faces ? &Sampler(map, c) : nullptr;
    for (py::ssize_t i = 0; i < faces.size(); ++i) {
      const PtexFaceId face(static_cast<std::int32_t>(faces.data()[i]));
      values[i * count + (c - first)] =
          sampler ? sampler->SampleAcrossFaces(face, u.data()[i], v.data()[i])
                  : map.file->Sample(face, static_cast<float>(u.data()[i]),
                                     static_cast<float>(v.data()[i]), c);
    }
  }
  return out;
}

}  // namespace

void AddMaps(py::module_& module) {
  py::class_<PyMap, std::shared_ptr<PyMap>>(
      module, "Map",
      "A Ptex map opened for reading (every section checked; dispex.InputError names what is "
      "wrong). A context manager: `with dispex.Map(path) as m:` closes it at the end.")
      .def(py::init([](const py::object& path) {
             return Open(py::module_::import("os").attr("fsdecode")(path).cast<std::string>());
           }),
           py::arg("path"))
      .def_property_readonly(
          "path", [](const PyMap& m) { return File(m).name(); }, "The file the map was read from")
      .def_property_readonly(
          "num_faces", [](const PyMap& m) { return File(m).num_faces(); },
          "Ptex faces: the base's quads and the quads its n-gons are split into")
      .def_property_readonly(
          "num_channels", [](const PyMap& m) { return File(m).header().num_channels; },
          "1 (a scalar map) or 3 (a vector map)")
      .def_property_readonly(
          "data_type",
          [](const PyMap& m) { return std::string(PtexDataTypeName(File(m).header().data_type)); },
          "The texels' type as stored: \"float32\" or \"float16\"")
      .def_property_readonly(
          "mesh_type",
          [](const PyMap& m) { return std::string(PtexMeshTypeName(File(m).header().mesh_type)); },
          "\"quad\": the Ptex mesh type of every Catmull-Clark map")
      .def_property_readonly(
          "resolutions",
          [](const PyMap& m) {
            py::array_t<std::int32_t> a(
                {static_cast<py::ssize_t>(File(m).num_faces()), py::ssize_t{2}});
            for (int f = 0; f < File(m).num_faces(); ++f) {
              const PtexFaceInfo& info = File(m).face_info(PtexFaceId(f));
              a.mutable_at(f, 0) = info.ures();
              a.mutable_at(f, 1) = info.vres();
            }
            return a;
          },
          "(faces, 2): each face's texels along u and v")
      .def_property_readonly(
          "adjacent_faces",
          [](const PyMap& m) {
            py::array_t<std::int32_t> a(
                {static_cast<py::ssize_t>(File(m).num_faces()), py::ssize_t{4}});
            for (int f = 0; f < File(m).num_faces(); ++f) {
              for (int e = 0; e < 4; ++e) {
                a.mutable_at(f, e) = File(m).face_info(PtexFaceId(f)).adjfaces[e];
              }
            }
            return a;
          },
          "(faces, 4): the neighbour across edges 0 (v=0), 1 (u=1), 2 (v=1), 3 (u=0); -1: none")
      .def_property_readonly(
          "adjacent_edges",
          [](const PyMap& m) {
            py::array_t<std::int32_t> a(
                {static_cast<py::ssize_t>(File(m).num_faces()), py::ssize_t{4}});
            for (int f = 0; f < File(m).num_faces(); ++f) {
              for (int e = 0; e < 4; ++e) {
                a.mutable_at(f, e) = File(m).face_info(PtexFaceId(f)).adjedges[e];
              }
            }
            return a;
          },
          "(faces, 4): the shared edge's index within each neighbour")
      .def_property_readonly(
          "subfaces",
          [](const PyMap& m) {
            py::array_t<bool> a(File(m).num_faces());
            for (int f = 0; f < File(m).num_faces(); ++f) {
              a.mutable_data()[f] = File(m).face_info(PtexFaceId(f)).subface;
            }
            return a;
          },
          "(faces,): the face is one of the quads an n-gon was split into")
      .def_property_readonly(
          "meta",
          [](const PyMap& m) {
            py::dict d;
            for (const PtexMetaItem& item : File(m).meta_data())
              d[item.key.c_str()] = MetaValue(item);
            return d;
          },
          "The meta data: strings as str, numbers as NumPy arrays")
      .def("texels", &Texels, py::arg("face"), py::arg("level") = 0,
           "The face's texels at a stored level, float32 (vres, ures, channels), v-major")
      .def("sample", &Sample, py::arg("faces"), py::arg("u"), py::arg("v"),
           py::arg("channel") = py::none(), py::arg("across_faces") = false,
           "The map at (faces[i], u[i], v[i]): bilinear within each face, or with "
           "across_faces=True the reference Ptex bilinear filter that reads over face edges. "
           "float64 (n,) for a scalar map or one channel, (n, channels) for every channel of "
           "a vector map (channel=None)")
      .def("close", &Close, "Releases the file; the map can no longer be read")
      .def("__enter__", [](const std::shared_ptr<PyMap>& m) { return m; })
      .def("__exit__", [](PyMap& m, const py::args&) { Close(m); })
      .def("__repr__", &Repr);
}

}  // namespace dispex::python
