#include "dispex/status.h"

namespace dispex {

std::string_view StatusCodeName(StatusCode code) {
  switch (code) {
    case StatusCode::kOk:
      return "ok";
    case StatusCode::kFailed:
      return "failed";
    case StatusCode::kInvalidArgument:
      return "invalid_argument";
    case StatusCode::kBadInput:
      return "bad_input";
    case StatusCode::kMismatch:
      return "mismatch";
    case StatusCode::kCheckFailed:
      return "check_failed";
    case StatusCode::kCancelled:
      return "cancelled";
    case StatusCode::kOverBudget:
      return "over_budget";
    case StatusCode::kOutput:
      return "output";
  }
  return "failed";
}

}  // namespace dispex
