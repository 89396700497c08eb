// Extraction options from Python keyword arguments: ExtractOptions' field names, values as a
// manifest takes them (SetExtractOption), plus threads, max_memory and incremental.
#pragma once

#include <pybind11/pybind11.h>

#include "dispex/extract.h"

namespace dispex::python {

namespace py = pybind11;

// Sets `options` from `kwargs`; ValueError with the library's message (naming the option).
void SetExtractOptions(ExtractOptions& options, const py::dict& kwargs);

}  // namespace dispex::python
