// dispex.verify, dispex.make_sculpt and dispex.info: the commands' library calls, options by name.
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "bindings.h"
#include "cancellable.h"
#include "dispex/files.h"
#include "dispex/mesh_summary.h"
#include "dispex/ptex_describe.h"
#include "dispex/uv_map.h"
#include "dispex/verify.h"
#include "errors.h"

namespace dispex::python {

namespace {

// A real number: a Python int or float or a NumPy scalar (anything with __float__ but a bool or
// a string); TypeError otherwise.
double Number(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || py::isinstance<py::str>(value) ||
      py::isinstance<py::bytes>(value) || !PyNumber_Check(value.ptr()) ||
      py::hasattr(value, "__complex__")) {
    throw py::type_error(fmt::format("{}: {} is not a number", name, Shown(value)));
  }
  return py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
}

// An integer: a Python int or a NumPy integer (anything with __index__ but a bool).
long long Integer(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !PyIndex_Check(value.ptr())) {
    throw py::type_error(fmt::format("{}: {} is not an integer", name, Shown(value)));
  }
  return py::int_(py::reinterpret_borrow<py::object>(value)).cast<long long>();
}

long long NonNegative(const py::handle& value, const std::string& name) {
  const long long n = Integer(value, name);
  if (n < 0) throw py::value_error(fmt::format("{} = {}: must be >= 0", name, n));
  return n;
}

std::string Text(const py::handle& value, const std::string& name) {
  if (!py::isinstance<py::str>(value)) {
    throw py::type_error(fmt::format("{}: {} is not a string", name, Shown(value)));
  }
  return value.cast<std::string>();
}

[[noreturn]] void Unknown(const std::string& name, const char* known) {
  throw py::value_error(fmt::format("{}: unknown option (known: {})", name, known));
}

void SetVerifyOption(VerifyOptions& o, const std::string& name, const py::handle& v) {
  if (name == "truth") {
    o.truth_path = Text(v, name);
  } else if (name == "samples_per_face") {
    o.samples_per_face = static_cast<int>(NonNegative(v, name));
  } else if (name == "max_sculpt_points") {
    o.max_sculpt_points = static_cast<std::size_t>(NonNegative(v, name));
  } else if (name == "max_error") {
    o.max_error = Number(v, name);
  } else if (name == "max_error_rel") {
    o.max_error_rel = Number(v, name);
  } else if (name == "max_rms") {
    o.max_rms = Number(v, name);
  } else if (name == "max_p99") {
    o.max_p99 = Number(v, name);
  } else if (name == "max_mean_tolerances") {
    o.max_mean_tolerances = Number(v, name);
  } else if (name == "tolerance") {
    o.tolerance = Number(v, name);
  } else if (name == "truth_local_bound") {
    if (!py::isinstance<py::bool_>(v)) {
      throw py::type_error(fmt::format("{}: {} is not True or False", name, Shown(v)));
    }
    o.truth_local_bound = v.cast<bool>();
  } else if (name == "truth_local_tolerance_factor") {
    o.truth_local_tolerance_factor = Number(v, name);
  } else if (name == "truth_rms_factor") {
    o.truth_rms_factor = Number(v, name);
  } else if (name == "truth_p99_factor") {
    o.truth_p99_factor = Number(v, name);
  } else if (name == "max_edge_step") {
    o.max_edge_step = Number(v, name);
  } else if (name == "max_edge_step_p99") {
    o.max_edge_step_p99 = Number(v, name);
  } else if (name == "threads") {
    o.threads = static_cast<int>(NonNegative(v, name));
  } else {
    Unknown(name,
            "truth, samples_per_face, max_sculpt_points, max_error, max_error_rel, max_rms, "
            "max_p99, max_mean_tolerances, tolerance, truth_local_bound, "
            "truth_local_tolerance_factor, truth_rms_factor, "
            "truth_p99_factor, max_edge_step, max_edge_step_p99, threads");
  }
}

// Verify's report as a dict; a map that does not pass (the command's exit 3) raises
// dispex.VerifyError "<map>: <why>" carrying the report, unless check=False.
py::object RunVerify(const std::string& base, const std::optional<std::string>& sculpt,
                     const std::string& map, bool check, const py::dict& kwargs) {
  VerifyOptions o;
  o.base_path = base;
  o.sculpt_path = sculpt.value_or("");
  o.map_path = map;
  for (const auto& [key, value] : kwargs) SetVerifyOption(o, py::str(key), value);
  std::optional<StatusOr<VerifyReport>> report;
  RunCancellable([&] { report.emplace(Verify(o)); }, ProgressCounter{}, py::none());
  const VerifyReport done = ValueOrRaise(std::move(*report));
  py::object json = py::module_::import("json").attr("loads")(VerifyReportJson(done));
  if (check && !done.passed) {
    py::object cls = py::module_::import("dispex._errors").attr("VerifyError");
    py::object error =
        cls(map + ": " + done.failure, py::arg("report") = json, py::arg("path") = map);
    PyErr_SetObject(cls.ptr(), error.ptr());
    throw py::error_already_set();
  }
  return json;
}

void SetMakeSculptOption(MakeSculptOptions& o, const std::string& name, const py::handle& v) {
  if (name == "levels") {
    o.levels = static_cast<int>(Integer(v, name));
  } else if (name == "layout") {
    auto layout = ParseSculptLayout(Text(v, name));
    CheckArgument(layout.status().WithPrefix(name));
    o.layout = *layout;
  } else if (name == "density") {
    o.density = static_cast<int>(Integer(v, name));
  } else if (name == "pattern") {
    auto pattern = ParsePatternArgument(Text(v, name));
    CheckArgument(pattern.status().WithPrefix(name));
    o.pattern = pattern->pattern;
    o.image_path = pattern->image_path;
  } else if (name == "amplitude") {
    o.amplitude = Number(v, name);
  } else if (name == "seed") {
    const long long seed = NonNegative(v, name);
    if (seed > 0xffffffffLL) throw py::value_error(fmt::format("seed = {}: above 2^32 - 1", seed));
    o.seed = static_cast<std::uint32_t>(seed);
  } else if (name == "truth") {
    o.truth_path = Text(v, name);
  } else if (name == "threads") {
    o.threads = static_cast<int>(NonNegative(v, name));
  } else {
    Unknown(name, "levels, layout, density, pattern, amplitude, seed, truth, threads");
  }
}

py::dict RunMakeSculpt(const std::string& cage, const std::string& output, const py::dict& kwargs) {
  MakeSculptOptions o;
  o.cage_path = cage;
  o.output_path = output;
  for (const auto& [key, value] : kwargs) SetMakeSculptOption(o, py::str(key), value);
  std::optional<StatusOr<MakeSculptReport>> report;
  RunCancellable([&] { report.emplace(MakeSculpt(o)); }, ProgressCounter{}, py::none());
  const MakeSculptReport r = ValueOrRaise(std::move(*report));
  py::dict d;
  d["sculpt"] = output;
  d["truth"] = o.truth_path.empty() ? output + ".truth" : o.truth_path;
  d["vertices"] = r.vertices;
  d["faces"] = r.faces;
  d["amplitude"] = r.amplitude;
  d["diagonal"] = r.diagonal;
  d["edge"] = r.edge;
  d["h_min"] = r.h_min;
  d["h_max"] = r.h_max;
  d["max_displacement"] = r.max_displacement;
  d["max_tangential"] = r.max_tangential;
  d["linear_error"] = r.linear_error;
  d["folded_faces"] = r.folded_faces;
  d["warnings"] = r.warnings;
  d["seconds"] = r.seconds;
  return d;
}

// `dispex info --json [--faces] [--strict]`: the summary of a mesh, a Ptex map or a UV-space map
// (chosen by its first bytes, as the command chooses), as a dict.
py::object Info(const std::string& path, bool faces, bool strict) {
  CheckOk(CheckReadableFile(path));
  std::string json;
  if (IsUvMapPath(path)) {
    json = UvMapSummaryJson(ValueOrRaise(UvMap::Open(path)));
  } else if (HasPtexMagic(path)) {
    const PtexFile file = ValueOrRaise(PtexFile::Open(path));
    CheckOk(file.Validate());  // every block inflated and checked, as the command does
    json = PtexSummaryJson(file, faces);
  } else {
    const Mesh mesh = ValueOrRaise(ReadMesh(path));
    const MeshSummary summary = SummarizeMesh(mesh, DetectMeshFormat(path));
    if (strict)
      CheckOk(
          RequireClean(mesh, summary.validation).WithCode(StatusCode::kBadInput).WithPath(path));
    json = MeshSummaryJson(path, mesh, summary);
  }
  return py::module_::import("json").attr("loads")(json);
}

}  // namespace

void AddTools(py::module_& module) {
  module.def("_verify", &RunVerify, py::arg("base"), py::arg("sculpt"), py::arg("map"),
             py::arg("check"), py::arg("options"));
  module.def("_info", &Info, py::arg("path"), py::arg("faces"), py::arg("strict"));
  module.def("_make_sculpt", &RunMakeSculpt, py::arg("cage"), py::arg("output"),
             py::arg("options"));
}

}  // namespace dispex::python
