// dispex._extract: Extract with meshes given as paths or dispex.Mesh, options by name, the
// report as a dict (the JSON report the command line writes with --report).
#include <pybind11/stl.h>

#include <string>

#include "bindings.h"
#include "cancellable.h"
#include "errors.h"
#include "mesh_arrays.h"
#include "options.h"

namespace dispex::python {

namespace {

// A path (str) or a dispex.Mesh, for the argument `argument` ("base", "sculpt").
void SetInput(const py::handle& value, const char* argument, std::string& path,
              std::shared_ptr<const Mesh>& mesh) {
  if (py::isinstance<PyMesh>(value)) {
    const PyMesh& given = value.cast<const PyMesh&>();
    path = given.name;
    mesh = given.mesh;
  } else if (py::isinstance<py::str>(value)) {
    path = value.cast<std::string>();
  } else {
    throw py::value_error(fmt::format("{}: {} is neither a path nor a dispex.Mesh", argument,
                                      py::repr(value).cast<std::string>()));
  }
}

py::object Extract(const py::handle& base, const py::handle& sculpt, const std::string& output,
                   const py::object& progress, const py::dict& kwargs) {
  ExtractOptions options;
  SetInput(base, "base", options.base_path, options.base_mesh);
  SetInput(sculpt, "sculpt", options.sculpt_path, options.sculpt_mesh);
  options.output_path = output;
  SetExtractOptions(options, kwargs);
  CheckArgument(ValidateExtractOptions(options));
  ProgressCounter counter;
  options.progress_counter = &counter;
  std::optional<StatusOr<ExtractReport>> report;
  RunCancellable([&] { report.emplace(dispex::Extract(options)); }, counter, progress);
  const ExtractReport done = ValueOrRaise(std::move(*report));
  return py::module_::import("json").attr("loads")(ExtractReportJson(done));
}

}  // namespace

void AddExtract(py::module_& module) {
  module.def("_extract", &Extract, py::arg("base"), py::arg("sculpt"), py::arg("output"),
             py::arg("progress"), py::arg("options"));
}

}  // namespace dispex::python
