#include "parse_errors.h"

#include <algorithm>
#include <cctype>

namespace dispex::cli {

namespace {

// Edits (insert, delete, replace, swap two neighbours) that turn `a` into `b`.
std::size_t EditDistance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::size_t> d((n + 1) * (m + 1));
  auto at = [&](std::size_t i, std::size_t j) -> std::size_t& { return d[i * (m + 1) + j]; };
  for (std::size_t i = 0; i <= n; ++i) at(i, 0) = i;
  for (std::size_t j = 0; j <= m; ++j) at(0, j) = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      at(i, j) = std::min(
          {at(i - 1, j) + 1, at(i, j - 1) + 1, at(i - 1, j - 1) + (a[i - 1] != b[j - 1] ? 1 : 0)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        at(i, j) = std::min(at(i, j), at(i - 2, j - 2) + 1);
      }
    }
  }
  return at(n, m);
}

// The long option names of `app` ("--tolerance") and its short ones ("-o").
std::vector<std::string> OptionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
    for (const std::string& name : option->get_snames()) names.push_back("-" + name);
  }
  return names;
}

// The subcommand argv names, if any.
const CLI::App* Command(const CLI::App& app, int argc, char** argv) {
  if (argc < 2) return nullptr;
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub->get_name() == argv[1]) return sub;
  }
  return nullptr;
}

}  // namespace

std::string NearestName(const std::string& word, const std::vector<std::string>& names) {
  std::string best, prefixed;
  std::size_t best_distance = std::string::npos, prefixes = 0;
  const std::size_t limit = std::clamp<std::size_t>(word.size() / 4, 1, 3);
  for (const std::string& name : names) {
    const std::size_t d = EditDistance(word, name);
    if (d < best_distance) best_distance = d, best = name;
    if (word.size() > 3 && name.size() > word.size() && name.compare(0, word.size(), word) == 0) {
      ++prefixes;
      prefixed = name;
    }
  }
  if (best_distance > 0 && best_distance <= limit) return best;
  return prefixes == 1 ? prefixed : "";
}

std::string ParseErrorMessage(const CLI::App& app, const CLI::ParseError& error, int argc,
                              char** argv) {
  std::string what = error.what();
  std::replace(what.begin(), what.end(), '\n', ' ');
  const CLI::App* command = Command(app, argc, argv);
  if (command != nullptr) {
    // Each word of the command line that looks like an option and is none of the command's.
    std::vector<std::string> names = OptionNames(*command);
    const std::vector<std::string> global = OptionNames(app);
    names.insert(names.end(), global.begin(), global.end());
    std::string hints;
    for (int i = 2; i < argc; ++i) {
      std::string word = argv[i];
      if (word == "--") break;
      if (word.size() < 2 || word[0] != '-' || std::isdigit(static_cast<unsigned char>(word[1])) ||
          word[1] == '.') {
        continue;  // a value, a negative number
      }
      word = word.substr(0, word.find('='));
      if (std::find(names.begin(), names.end(), word) != names.end()) continue;
      const std::string nearest = NearestName(word, names);
      hints += nearest.empty() ? "" : "; " + word + ": did you mean " + nearest + "?";
    }
    what += hints;
  }
  const std::string help =
      command != nullptr ? "dispex " + command->get_name() + " --help" : "dispex --help";
  return "dispex: " + what + " (see " + help + ")";
}

std::string UnknownCommandMessage(const CLI::App& app, const std::string& word) {
  std::vector<std::string> names;
  std::string list;
  for (const CLI::App* sub : app.get_subcommands({})) {
    names.push_back(sub->get_name());
    list += (list.empty() ? "" : ", ") + sub->get_name();
  }
  const std::string nearest = NearestName(word, names);
  return "dispex: unknown command '" + word + "'" +
         (nearest.empty() ? "" : " (did you mean " + nearest + "?)") + "; commands: " + list +
         " (see dispex --help)";
}

}  // namespace dispex::cli
