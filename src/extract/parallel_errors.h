// How a parallel stage of an extraction stops: with the error of the lowest face id (so the
// message does not depend on scheduling), or because cancellation was requested.
#pragma once

#include <fmt/format.h>

#include "core/first_error.h"
#include "dispex/cancel.h"
#include "dispex/status.h"

namespace dispex::extract {

inline Status Cancelled() {
  int sig = CancelSignal();
  return Status::Error(sig ? fmt::format("interrupted by signal {}", sig) : "interrupted");
}

}  // namespace dispex::extract
