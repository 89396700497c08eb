#include "errors.h"

#include <string>

namespace dispex::python {

namespace {

// The class of dispex._errors that stands for `code`.
const char* ClassName(StatusCode code) {
  switch (code) {
    case StatusCode::kBadInput:
      return "InputError";
    case StatusCode::kMismatch:
      return "MismatchError";
    case StatusCode::kCheckFailed:
      return "VerifyError";
    case StatusCode::kCancelled:
      return "CancelledError";
    case StatusCode::kOverBudget:
      return "MemoryBudgetError";
    case StatusCode::kOutput:
      return "OutputError";
    default:
      return "Error";
  }
}

void Raise(const Status& status) {
  if (status.code() == StatusCode::kInvalidArgument) {
    PyErr_SetString(PyExc_ValueError, status.message().c_str());
    return;
  }
  py::object cls = py::module_::import("dispex._errors").attr(ClassName(status.code()));
  py::object error =
      cls(status.message(), py::arg("code") = StatusCodeName(status.code()),
          py::arg("path") = status.path().empty() ? py::none() : py::object(py::str(status.path())),
          py::arg("face") = status.face() < 0 ? py::none() : py::object(py::int_(status.face())));
  PyErr_SetObject(cls.ptr(), error.ptr());
}

}  // namespace

std::string Shown(const py::handle& value) {
  return py::module_::import("dispex._errors").attr("shown")(value).cast<std::string>();
}

void AddErrors(py::module_&) {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StatusError& e) {
      try {
        Raise(e.status());
      } catch (py::error_already_set& failed) {
        failed.restore();  // dispex._errors could not be imported: that error, as it is
      }
    }
  });
}

void CheckOk(const Status& status) {
  if (!status.ok()) throw StatusError(status);
}

void CheckArgument(const Status& status) {
  if (!status.ok()) throw StatusError(status.WithCode(StatusCode::kInvalidArgument));
}

}  // namespace dispex::python
