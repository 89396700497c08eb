// Library errors in Python terms, chosen by the Status's code (dispex/status.h), never by its
// message: kInvalidArgument is a ValueError, every other failure an instance of a subclass of
// dispex.Error (python/dispex/_errors.py) with the library's one-line message and the fields
// code, path and face.
#pragma once

#include <pybind11/pybind11.h>

#include <exception>
#include <string>
#include <utility>

#include "dispex/status.h"

namespace dispex::python {

namespace py = pybind11;

// A failed Status on its way to Python.
class StatusError : public std::exception {
 public:
  explicit StatusError(Status status) : status_(std::move(status)) {}
  const Status& status() const { return status_; }
  const char* what() const noexcept override { return status_.message().c_str(); }

 private:
  Status status_;
};

// Translates StatusError into its Python exception.
void AddErrors(py::module_& module);

// Throws StatusError when `status` failed; CheckArgument as kInvalidArgument (ValueError)
// unless the status says otherwise.
void CheckOk(const Status& status);
void CheckArgument(const Status& status);

// `value` as a message shows it: its repr, or for a long one (a whole array) its type and,
// for an array, its shape.
std::string Shown(const py::handle& value);

template <class T>
T ValueOrRaise(StatusOr<T> result) {
  CheckOk(result.status());
  return std::move(result).value();
}

}  // namespace dispex::python
