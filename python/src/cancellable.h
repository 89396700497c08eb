// Long library calls from Python: run on a worker thread with the GIL released, so other
// Python threads run meanwhile; the calling thread wakes every 50 ms to run Python's signal
// handlers (Ctrl-C raises KeyboardInterrupt there) and the progress callback. A Python
// exception from either requests the library's cooperative cancellation (dispex/cancel.h):
// the work stops at the next face (or at the end of a phase that does not poll, such as a
// read), its outputs unwound (no file, no temporary left), and the exception propagates once
// the worker has returned. One call runs at a time; others wait.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>

#include "dispex/progress.h"

namespace dispex::python {

namespace py = pybind11;

// Runs `work` as above. `callback` (None, or called as callback(done, total) at most ten times
// a second while `counter` moves, and once at the end) reads `counter`, which `work` fills.
void RunCancellable(const std::function<void()>& work, const ProgressCounter& counter,
                    const py::object& callback);

}  // namespace dispex::python
