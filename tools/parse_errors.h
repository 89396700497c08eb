// What the command line says when it cannot parse a command: the parser's message, the nearest
// valid name for a misspelled option or command ("did you mean --tolerance?"), and where to
// read on ("see dispex extract --help"), in the one "dispex: ..." format of every error.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace dispex::cli {

// The name in `names` nearest to `word` by edit distance, or "" when none is near enough to be
// a slip of the keyboard (at most 1 edit in 4 letters, at least 1 and at most 3), or a unique
// name that `word` begins (an abbreviation).
std::string NearestName(const std::string& word, const std::vector<std::string>& names);

// The one-line message for `error`, raised parsing argv into `app`.
std::string ParseErrorMessage(const CLI::App& app, const CLI::ParseError& error, int argc,
                              char** argv);

// The one-line message for a first argument that names no command.
std::string UnknownCommandMessage(const CLI::App& app, const std::string& word);

}  // namespace dispex::cli
