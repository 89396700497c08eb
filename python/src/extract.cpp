// dispex._extract: Extract with meshes given as paths or dispex.Mesh, options by name, the
// report as a dict (the JSON report the command line writes with --report). dispex._extract_asset:
// ExtractAsset (one map per shape, or a manifest's shapes), a dict per shape. dispex._merge:
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
    throw py::type_error(
        fmt::format("{}: {} is neither a path nor a dispex.Mesh", argument, Shown(value)));
  }
}

py::object FromJson(const std::string& json) {
  return py::module_::import("json").attr("loads")(json);
}

// Runs `run` as RunCancellable does (`counter` filled by it); its value, or its error raised.
template <class T>
T Run(const std::function<StatusOr<T>()>& run, const ProgressCounter& counter,
      const py::object& progress) {
  std::optional<StatusOr<T>> result;
  RunCancellable([&] { result.emplace(run()); }, counter, progress);
  return ValueOrRaise(std::move(*result));
}

py::object Extract(const py::handle& base, const py::handle& sculpt, const std::string& output,
                   const py::object& progress, const py::dict& options_json) {
  ExtractOptions options;
  SetInput(base, "base", options.base_path, options.base_mesh);
  SetInput(sculpt, "sculpt", options.sculpt_path, options.sculpt_mesh);
  options.output_path = output;
  SetExtractOptions(options, options_json);
  CheckArgument(ValidateExtractOptions(options));
  ProgressCounter counter;
  options.progress_counter = &counter;
  const ExtractReport report =
      Run<ExtractReport>([&] { return dispex::Extract(options); }, counter, progress);
  return FromJson(ExtractReportJson(report));
}

// One map per shape of an asset: of the files base and sculpt (only `shapes`, when given), or
// of a manifest's shapes. The asset's report as a dict; its "shapes" as {name: report}.
py::object ExtractAssetMaps(const std::optional<std::string>& base,
                            const std::optional<std::string>& sculpt,
                            const std::optional<std::string>& manifest,
                            const std::optional<std::string>& out_dir,
                            const std::vector<std::string>& shapes, const py::object& progress,
                            const py::dict& options_json) {
  ExtractAssetOptions asset;
  SetExtractOptions(asset.options, options_json);
  asset.output_dir = out_dir.value_or("");
  if (manifest) {
    ExtractAssetOptions defaults = asset;
    asset = ValueOrRaise(ReadExtractManifest(*manifest, defaults));
  } else {
    asset.options.base_path = base.value_or("");
    asset.options.sculpt_path = sculpt.value_or("");
  }
  if (asset.output_dir.empty()) {
    throw py::value_error("out_dir: no output folder given (nor one in the manifest)");
  }
  asset.shapes = shapes;
  ProgressCounter counter;
  asset.options.progress_counter = &counter;
  const AssetReport report =
      Run<AssetReport>([&] { return dispex::ExtractAsset(asset); }, counter, progress);
  py::object out = FromJson(AssetReportJson(report));
  py::dict by_name;
  for (py::handle shape : out["shapes"]) by_name[shape["shape"]] = shape;
  out["shapes"] = by_name;
  return out;
}

py::object Merge(const std::vector<std::string>& parts, const std::string& output,
                 const py::object& progress, const py::dict& limits_json) {
  ExtractOptions checked;
  SetExtractOptions(checked, limits_json);
  MergeOptions options;
  options.parts = parts;
  options.output_path = output;
  options.threads = checked.threads;
  options.max_memory = checked.max_memory;
  ProgressCounter counter;
  options.progress_counter = &counter;
  const ExtractReport report =
      Run<ExtractReport>([&] { return dispex::MergeShards(options); }, counter, progress);
  return FromJson(ExtractReportJson(report));
}

}  // namespace

void AddExtract(py::module_& module) {
  module.def("_extract", &Extract, py::arg("base"), py::arg("sculpt"), py::arg("output"),
             py::arg("progress"), py::arg("options"));
  module.def("_extract_asset", &ExtractAssetMaps, py::arg("base"), py::arg("sculpt"),
             py::arg("manifest"), py::arg("out_dir"), py::arg("shapes"), py::arg("progress"),
             py::arg("options"));
  module.def("_merge", &Merge, py::arg("parts"), py::arg("output"), py::arg("progress"),
             py::arg("limits"));
  AddOptionSpecs(module);
}

}  // namespace dispex::python
