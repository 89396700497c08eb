#include "flag_names.h"

#include "command.h"

namespace dispex::cli {

namespace {

bool StartsWord(std::string_view text, std::size_t at) {
  return at == 0 || text[at - 1] == ' ' || text[at - 1] == '(';
}

bool EndsWord(std::string_view text, std::size_t at) {
  return at == text.size() || std::string_view(" :),;").find(text[at]) != std::string_view::npos;
}

}  // namespace

std::string WithFlagNames(std::string_view message, std::span<const FlagName> flags) {
  std::string out;
  std::size_t i = 0;
  while (i < message.size()) {
    const FlagName* match = nullptr;
    if (StartsWord(message, i)) {
      for (const FlagName& f : flags) {
        if (message.substr(i, f.field.size()) == f.field && EndsWord(message, i + f.field.size()) &&
            (!match || f.field.size() > match->field.size())) {
          match = &f;
        }
      }
    }
    if (!match) {
      out += message[i++];
      continue;
    }
    out += match->flag;
    i += match->field.size();
    if (message.substr(i, 3) == " = ") i += 2;  // "field = value" -> "flag value"
  }
  return out;
}

int ReportFailure(const Status& status, std::span<const FlagName> flags, int exit_code) {
  return ReportFailure(Status::Error(WithFlagNames(status.message(), flags)), exit_code);
}

}  // namespace dispex::cli
