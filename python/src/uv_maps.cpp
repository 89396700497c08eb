// dispex.UvMap: a UV-space map (one OpenEXR file per UDIM tile) read back -- each tile as a NumPy
// array, its header's dispex:* attributes -- and sampled at (u, v) arrays as UDIM readers read it.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "dispex/uv_map.h"
#include "errors.h"

namespace dispex::python {

namespace {

const UvMapTile& Tile(const UvMap& map, long long udim) {
  for (const UvMapTile& tile : map.tiles()) {
    if (tile.udim == udim) return tile;
  }
  std::string udims;
  for (const UvMapTile& tile : map.tiles())
    udims += fmt::format("{}{}", udims.empty() ? "" : ", ", tile.udim);
  throw py::value_error(fmt::format("udim {}: no such tile (tiles: {})", udim, udims));
}

// (N, N, channels) float32, row j at v = (j + 0.5) / N of the tile (row 0 at the tile's v = 0,
// the image's bottom row), column i at u = (i + 0.5) / N.
py::array_t<float> TileArray(const UvMap& map, long long udim) {
  const UvMapTile& tile = Tile(map, udim);
  const auto n = static_cast<py::ssize_t>(tile.resolution);
  py::array_t<float> out({n, n, static_cast<py::ssize_t>(tile.channels)});
  std::copy(tile.values.begin(), tile.values.end(), out.mutable_data());
  return out;
}

py::array_t<double> Sample(const UvMap& map, const py::handle& u_in, const py::handle& v_in) {
  auto as_array = [](const py::handle& h, const char* name) {
    py::array a = py::array::ensure(h);
    if (!a || a.ndim() > 1 || std::string("fiu").find(a.dtype().kind()) == std::string::npos) {
      throw py::type_error(fmt::format("{}: expected a 1-D array of numbers", name));
    }
    return py::array_t<double, py::array::forcecast>::ensure(a);
  };
  auto u = as_array(u_in, "u");
  auto v = as_array(v_in, "v");
  if (u.size() != v.size()) {
    throw py::value_error(
        fmt::format("u and v: {} and {} values, not the same number", u.size(), v.size()));
  }
  const int channels = map.channels();
  py::array_t<double> out = channels == 1 ? py::array_t<double>(u.size())
                                          : py::array_t<double>({u.size(), py::ssize_t{channels}});
  std::vector<float> texel(static_cast<std::size_t>(channels));
  for (py::ssize_t i = 0; i < u.size(); ++i) {
    const bool inside = map.Sample(u.data()[i], v.data()[i], texel);
    for (int c = 0; c < channels; ++c) {
      out.mutable_data()[i * channels + c] = inside ? double(texel[static_cast<std::size_t>(c)])
                                                    : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return out;
}

}  // namespace

void AddUvMaps(py::module_& module) {
  py::class_<UvMap, std::shared_ptr<UvMap>>(
      module, "UvMap",
      "A UV-space map read back: `pattern` is DIR/<shape>.<UDIM>.exr with the literal <UDIM>, or "
      "the path of one tile of the set (every tile beside it is read). dispex.InputError names "
      "a tile that cannot be read.")
      .def(py::init([](const py::object& pattern) {
             const std::string path =
                 py::module_::import("os").attr("fsdecode")(pattern).cast<std::string>();
             return std::make_shared<UvMap>(ValueOrRaise(UvMap::Open(path)));
           }),
           py::arg("pattern"))
      .def_property_readonly("paths", &UvMap::paths, "Each tile's file, by UDIM")
      .def_property_readonly(
          "udims",
          [](const UvMap& m) {
            std::vector<int> udims;
            for (const UvMapTile& tile : m.tiles()) udims.push_back(tile.udim);
            return udims;
          },
          "The tiles' UDIM numbers, ascending")
      .def_property_readonly("resolution", &UvMap::resolution, "Texels per tile side")
      .def_property_readonly("num_channels", &UvMap::channels,
                             "1 (a scalar map) or 3 (a vector map's x, y, z)")
      .def_property_readonly(
          "attributes",
          [](const UvMap& m) {
            py::dict d;
            if (!m.tiles().empty()) {
              for (const auto& [name, value] : m.tiles().front().attributes)
                d[name.c_str()] = value;
            }
            return d;
          },
          "The first tile's string attributes (dispex:* conventions, docs/UV_MAPS.md)")
      .def("tile", &TileArray, py::arg("udim"),
           "The tile's texels, float32 (N, N, channels): row j at the tile's v = (j + 0.5) / N "
           "(row 0 at the bottom of the image), column i at u = (i + 0.5) / N")
      .def("sample", &Sample, py::arg("u"), py::arg("v"),
           "The map read bilinearly at (u[i], v[i]) in UDIM space (u 1.5 is tile 1002), each "
           "tile on its own as UDIM readers read it: float64 (n,) or (n, 3); NaN where no tile "
           "holds the point")
      .def("__repr__", [](const UvMap& m) {
        return fmt::format("<dispex.UvMap {}: {} tile{}, {}x{}, {} channel{}>",
                           m.paths().empty() ? "" : m.paths().front(), m.tiles().size(),
                           m.tiles().size() == 1 ? "" : "s", m.resolution(), m.resolution(),
                           m.channels(), m.channels() == 1 ? "" : "s");
      });
}

}  // namespace dispex::python
