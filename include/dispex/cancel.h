// Cooperative cancellation: a signal handler (or any thread) requests it, the library's long
// loops poll it between units of work and stop with a Status. Requesting is async-signal-safe.
// The command line installs the handlers; a program embedding dispex may request it itself.
#pragma once

namespace dispex {

void RequestCancel() noexcept;
bool CancelRequested() noexcept;
// The signal that requested cancellation (0 if none or requested otherwise).
int CancelSignal() noexcept;

// Installs SIGINT/SIGTERM handlers: the first signal requests cancellation (work stops within
// one face and temporary outputs are removed as their writers unwind) and, should a phase not
// poll in time, ends the process 0.8 s later after removing the temporary outputs; a second
// signal does that at once. The exit status is 128 + signal.
void InstallCancelSignalHandlers();

// Clears a previous request (for tests).
void ResetCancel() noexcept;

}  // namespace dispex
