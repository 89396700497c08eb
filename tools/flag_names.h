// The library's messages name option fields ("max_oversample = 1024: must be ..."); the command
// line speaks of flags. Each command keeps a table from field to flag and prints library errors
// through it, so a user reads "--max-oversample 1024: must be ...".
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "dispex/status.h"

namespace dispex::cli {

struct FlagName {
  std::string_view field;  // as the library writes it: a field name or a short phrase
  std::string_view flag;   // as the command line spells it
};

// `message` with each field of `flags` that stands as a word (after the start, a space or '(';
// before the end, a space or one of ":),;") replaced by its flag; "field = value" becomes
// "flag value".
std::string WithFlagNames(std::string_view message, std::span<const FlagName> flags);

// ReportFailure for a library error, its fields spelled as flags.
int ReportFailure(const Status& status, std::span<const FlagName> flags, int exit_code = 1);

}  // namespace dispex::cli
