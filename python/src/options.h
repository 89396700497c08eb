// Extraction options from Python: the library's option table (ExtractOptionSpecs) handed to the
// package, which turns each keyword argument into the JSON value the library takes
// (python/dispex/_options.py), and those values set on ExtractOptions.
#pragma once

#include <pybind11/pybind11.h>

#include "dispex/extract.h"

namespace dispex::python {

namespace py = pybind11;

// Sets `options` from `values` (option name -> JSON text); ValueError with the library's
// message (naming the option).
void SetExtractOptions(ExtractOptions& options, const py::dict& values);

// dispex._dispex._extract_option_specs(): the table as a list of dicts.
void AddOptionSpecs(py::module_& module);

}  // namespace dispex::python
