// dispex._extract: Extract with meshes given as paths or dispex.Mesh, options by name, the
// report as a dict (the JSON report the command line writes with --report). dispex._merge:
// MergeShards of the parts farm shards wrote, the report likewise.
#include <pybind11/stl.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

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

// Runs `run` (which fills `counter`) as RunCancellable does; its report as a dict.
py::object ReportOf(const std::function<StatusOr<ExtractReport>()>& run,
                    const ProgressCounter& counter, const py::object& progress) {
  std::optional<StatusOr<ExtractReport>> report;
  RunCancellable([&] { report.emplace(run()); }, counter, progress);
  const ExtractReport done = ValueOrRaise(std::move(*report));
  return py::module_::import("json").attr("loads")(ExtractReportJson(done));
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
  return ReportOf([&] { return dispex::Extract(options); }, counter, progress);
}

// `limits`: threads and max_memory, checked as extract's.
py::object Merge(const std::vector<std::string>& parts, const std::string& output,
                 const py::object& progress, const py::dict& limits) {
  ExtractOptions checked;
  SetExtractOptions(checked, limits);
  MergeOptions options;
  options.parts = parts;
  options.output_path = output;
  options.threads = checked.threads;
  options.max_memory = checked.max_memory;
  ProgressCounter counter;
  options.progress_counter = &counter;
  return ReportOf([&] { return dispex::MergeShards(options); }, counter, progress);
}

}  // namespace

void AddExtract(py::module_& module) {
  module.def("_extract", &Extract, py::arg("base"), py::arg("sculpt"), py::arg("output"),
             py::arg("progress"), py::arg("options"));
  module.def("_merge", &Merge, py::arg("parts"), py::arg("output"), py::arg("progress"),
             py::arg("limits"));
}

}  // namespace dispex::python
