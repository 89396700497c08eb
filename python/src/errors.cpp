#include "errors.h"

namespace dispex::python {

void AddErrors(py::module_& module) {
  static py::exception<Error> error(module, "Error", PyExc_RuntimeError);
  error.attr("__module__") = "dispex";  // raised as dispex.Error, as the package exports it
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });
}

void CheckOk(const Status& status) {
  if (!status.ok()) throw Error(status.message());
}

void CheckArgument(const Status& status) {
  if (!status.ok()) throw py::value_error(status.message());
}

}  // namespace dispex::python
