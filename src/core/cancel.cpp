#include "dispex/cancel.h"

#include <signal.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>

#include "core/atomic_output.h"

namespace dispex {

namespace {
std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};

// Work polls the flag between faces, but a phase that does not (a read, a BVH build) could
// hold the exit back: a timer ends the process anyway, cleanly, shortly after the signal.
constexpr long kHardStopMicroseconds = 800'000;

extern "C" void HandleHardStop(int) {
  RemoveTemporaryOutputs();
  ::_exit(128 + g_signal.load());
}

extern "C" void HandleCancelSignal(int sig) {
  if (g_cancel.exchange(true)) {
    RemoveTemporaryOutputs();
    ::_exit(128 + sig);
  }
  g_signal.store(sig);
  struct sigaction action {};
  action.sa_handler = HandleHardStop;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGALRM, &action, nullptr);
  struct itimerval timer {};
  timer.it_value.tv_usec = kHardStopMicroseconds;
  ::setitimer(ITIMER_REAL, &timer, nullptr);
}
}  // namespace

void RequestCancel() noexcept {
  g_cancel.store(true);
}
bool CancelRequested() noexcept {
  return g_cancel.load(std::memory_order_relaxed);
}
int CancelSignal() noexcept {
  return g_signal.load();
}

void ResetCancel() noexcept {
  g_cancel.store(false);
  g_signal.store(0);
}

void InstallCancelSignalHandlers() {
  struct sigaction action {};
  action.sa_handler = HandleCancelSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

}  // namespace dispex
