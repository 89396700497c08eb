#include "options.h"

#include <pybind11/stl.h>

#include <string>

#include "errors.h"

namespace dispex::python {

namespace {

std::string_view KindName(OptionKind kind) {
  switch (kind) {
    case OptionKind::kInteger:
      return "integer";
    case OptionKind::kNumber:
      return "number";
    case OptionKind::kBool:
      return "bool";
    case OptionKind::kText:
      return "text";
    case OptionKind::kPath:
      return "path";
    case OptionKind::kChoice:
      return "choice";
    case OptionKind::kIntegerOrAuto:
      return "integer_or_auto";
    case OptionKind::kSize:
      return "size";
    case OptionKind::kDistance:
      return "distance";
  }
  return "text";
}

}  // namespace

void SetExtractOptions(ExtractOptions& options, const py::dict& values) {
  for (const auto& [key, value] : values) {
    CheckArgument(SetExtractOption(options, py::str(key).cast<std::string>(),
                                   py::str(value).cast<std::string>()));
  }
}

void AddOptionSpecs(py::module_& module) {
  module.def("_extract_option_specs", [] {
    py::list specs;
    for (const ExtractOptionSpec& s : ExtractOptionSpecs()) {
      py::dict d;
      d["name"] = std::string(s.name);
      d["flag"] = std::string(s.flag);
      d["kind"] = std::string(KindName(s.kind));
      d["values"] = std::string(s.values);
      d["help"] = std::string(s.help);  // its line in `dispex extract --help`
      d["default"] = std::string(s.default_text);
      d["in_manifest"] = s.in_manifest;
      d["in_map"] = s.in_map;
      specs.append(d);
    }
    return specs;
  });
}

}  // namespace dispex::python
