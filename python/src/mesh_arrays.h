// dispex.Mesh: a polygon mesh from NumPy arrays (what a DCC script holds in memory), checked as
// the readers check a file's, for extract(base=..., sculpt=...).
#pragma once

#include <pybind11/pybind11.h>

#include <memory>

#include "dispex/mesh.h"

namespace dispex::python {

namespace py = pybind11;

// The Python object: the mesh, shared with the extractions it is given to.
struct PyMesh {
  std::shared_ptr<const Mesh> mesh;
  std::string name;  // the file name it stands for in reports and maps ("" : the argument's)
};

// Defines dispex.Mesh (its constructor from arrays, the arrays back, dispex.read_mesh).
void AddMesh(py::module_& module);

}  // namespace dispex::python
