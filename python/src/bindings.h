// The parts of the module dispex._dispex, each defined in its own file.
#pragma once

#include <fmt/format.h>
#include <pybind11/pybind11.h>

namespace dispex::python {

namespace py = pybind11;

void AddExtract(py::module_& module);  // extract.cpp
void AddMaps(py::module_& module);     // maps.cpp: dispex.Map, reading and sampling
void AddTools(py::module_& module);    // tools.cpp: verify, make_sculpt, info
void AddUvMaps(py::module_& module);   // uv_maps.cpp: dispex.UvMap

}  // namespace dispex::python
