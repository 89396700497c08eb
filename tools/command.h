// Subcommand registration for the dispex command line.
//
// Each cmd_<name>.cpp defines one subcommand: a function that adds it to the CLI11 app with
// its options and callback, registered with DISPEX_REGISTER_COMMAND. The callback parses
// nothing itself: options land in a struct that is handed to the library.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <initializer_list>
#include <string>

#include "dispex/status.h"

namespace dispex::cli {

// `exit_code` is where the subcommand's callback stores its result.
using CommandSetup = void (*)(CLI::App& app, int& exit_code);

struct CommandRegistration {
  CommandRegistration(int order, CommandSetup setup);
};

// Prints "dispex: <message>" on stderr and returns the exit code for a failed run.
int ReportFailure(const Status& status, int exit_code = 1);

// Checks, before any work, that each output of a command can be written (dispex/files.h:
// CheckOutputFile, CheckOutputFolder; missing folders are made when it is written): the error
// names its option. Empty paths (outputs not asked for) pass.
struct OutputPath {
  const char* flag;
  std::string path;
  bool folder = false;
};
Status CheckOutputs(std::initializer_list<OutputPath> outputs);

// True when stderr is a terminal and CI is not set: only then is progress drawn.
bool StderrIsInteractive();

// Option checks with messages that say what to do: "--tolerance: 0 must be greater than 0
// (leave the option out for the automatic value)".
CLI::Validator Positive();
CLI::Validator NonNegative();

}  // namespace dispex::cli

#define DISPEX_CLI_CONCAT_INNER(a, b) a##b
#define DISPEX_CLI_CONCAT(a, b) DISPEX_CLI_CONCAT_INNER(a, b)
// Registers `setup`; `order` sets the position in `dispex --help`.
#define DISPEX_REGISTER_COMMAND(order, setup)                                                   \
  static const ::dispex::cli::CommandRegistration DISPEX_CLI_CONCAT(dispex_command_, __LINE__)( \
      order, setup)
