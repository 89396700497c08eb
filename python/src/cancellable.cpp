#include "cancellable.h"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "dispex/cancel.h"

namespace dispex::python {

namespace {

constexpr auto kPoll = std::chrono::milliseconds(50);
constexpr auto kCallbackEvery = std::chrono::milliseconds(100);

// Cancellation is one flag for the process: one call at a time, so that a Ctrl-C stops only
// the call it interrupts.
std::mutex g_one_at_a_time;

struct Shown {
  std::uint64_t done = ~std::uint64_t{0}, total = 0;
};

// Calls the callback when the counter moved since it was last shown, once the total is known
// (a callback's done / total never divides by 0).
void Show(const py::object& callback, const ProgressCounter& counter, Shown& shown) {
  const std::uint64_t done = counter.done.load(), total = counter.total.load();
  if (callback.is_none() || total == 0 || (done == shown.done && total == shown.total)) return;
  shown = {done, total};
  callback(done, total);
}

}  // namespace

void RunCancellable(const std::function<void()>& work, const ProgressCounter& counter,
                    const py::object& callback) {
  std::unique_lock one(g_one_at_a_time, std::defer_lock);
  {
    py::gil_scoped_release release;
    one.lock();
  }
  ResetCancel();
  std::mutex mutex;
  std::condition_variable finished_cv;
  bool finished = false;
  std::exception_ptr failure;
  std::optional<py::error_already_set> raised;
  Shown shown;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard lock(mutex);
      finished = true;
      finished_cv.notify_all();
    });
    auto last_shown = std::chrono::steady_clock::now();
    std::unique_lock lock(mutex);
    while (!finished_cv.wait_for(lock, kPoll, [&] { return finished; })) {
      if (raised) continue;  // cancelled: waiting for the work to unwind
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        try {
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (std::chrono::steady_clock::now() - last_shown >= kCallbackEvery) {
            Show(callback, counter, shown);
            last_shown = std::chrono::steady_clock::now();
          }
        } catch (py::error_already_set& e) {
          raised.emplace(std::move(e));
          RequestCancel();
        }
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  ResetCancel();
  if (raised) throw std::move(*raised);
  if (failure) std::rethrow_exception(failure);
  Show(callback, counter, shown);
}

}  // namespace dispex::python
