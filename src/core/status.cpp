#include "dispex/status.h"

#include "core/enum_names.h"

namespace dispex {

namespace {

constexpr auto kStatusCodeNames = EnumTable<StatusCode>({
    {StatusCode::kOk, "ok"},
    {StatusCode::kFailed, "failed"},
    {StatusCode::kInvalidArgument, "invalid_argument"},
    {StatusCode::kBadInput, "bad_input"},
    {StatusCode::kMismatch, "mismatch"},
    {StatusCode::kCheckFailed, "check_failed"},
    {StatusCode::kCancelled, "cancelled"},
    {StatusCode::kOverBudget, "over_budget"},
    {StatusCode::kOutput, "output"},
});

}  // namespace

std::string_view StatusCodeName(StatusCode code) {
  return EnumName(kStatusCodeNames, code);
}

}  // namespace dispex
