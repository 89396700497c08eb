// Library errors in Python terms: a Status about the arguments is a ValueError, any other
// failure a dispex.Error (a RuntimeError); both carry the library's one-line message.
#pragma once

#include <pybind11/pybind11.h>

#include <stdexcept>
#include <utility>

#include "dispex/status.h"

namespace dispex::python {

namespace py = pybind11;

// Raised as dispex.Error.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Defines dispex.Error in `module` and translates Error into it.
void AddErrors(py::module_& module);

// Throws Error (dispex.Error) / py::value_error (ValueError) when `status` failed.
void CheckOk(const Status& status);
void CheckArgument(const Status& status);

template <class T>
T ValueOrRaise(StatusOr<T> result) {
  CheckOk(result.status());
  return std::move(result).value();
}

}  // namespace dispex::python
