// dispex._dispex, the compiled half of the Python package dispex (python/dispex/__init__.py).
#include "bindings.h"
#include "dispex/version.h"
#include "errors.h"
#include "mesh_arrays.h"

PYBIND11_MODULE(_dispex, module) {
  using namespace dispex::python;
  module.doc() = "dispex: Ptex displacement maps from a Catmull-Clark base cage and its sculpt";
  module.attr("__version__") = dispex::Version();
  AddErrors(module);
  AddMesh(module);
  AddExtract(module);
  AddMaps(module);
  AddUvMaps(module);
  AddTools(module);
}
