// dispex: extract displacement maps from sculpts. This file only dispatches to the
// subcommands (cmd_*.cpp); the work happens in the library.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include "command.h"
#include "dispex/allocator.h"
#include "dispex/files.h"
#include "dispex/version.h"
#include "parse_errors.h"

namespace dispex::cli {
namespace {
std::vector<std::pair<int, CommandSetup>>& Registry() {
  static std::vector<std::pair<int, CommandSetup>> registry;
  return registry;
}
}  // namespace

CommandRegistration::CommandRegistration(int order, CommandSetup setup) {
  Registry().emplace_back(order, setup);
}

int ReportFailure(const Status& status, int exit_code) {
  std::fprintf(stderr, "dispex: %s\n", status.message().c_str());
  return exit_code;
}

Status CheckOutputs(std::initializer_list<OutputPath> outputs) {
  for (const OutputPath& output : outputs) {
    if (output.path.empty()) continue;
    const Status checked =
        output.folder ? CheckOutputFolder(output.path) : CheckOutputFile(output.path);
    if (!checked.ok()) return checked.WithPrefix(output.flag);
  }
  return Status::Ok();
}

bool StderrIsInteractive() {
  const char* ci = std::getenv("CI");
  if (ci && *ci && std::string(ci) != "false" && std::string(ci) != "0") return false;
  return ::isatty(STDERR_FILENO) == 1;
}

namespace {
CLI::Validator NumberCheck(const char* name, bool (*accept)(double), const char* requirement) {
  return CLI::Validator(
      [accept, requirement](std::string& text) -> std::string {
        double value = 0;
        try {
          std::size_t used = 0;
          value = std::stod(text, &used);
          if (used != text.size()) return text + " is not a number";
        } catch (...) {
          return text + " is not a number";
        }
        return accept(value) ? std::string() : text + " " + requirement;
      },
      name);
}
}  // namespace

CLI::Validator Positive() {
  return NumberCheck(
      "> 0", [](double v) { return v > 0; },
      "must be greater than 0 (leave the option out for the automatic value)");
}
CLI::Validator NonNegative() {
  return NumberCheck(
      ">= 0", [](double v) { return v >= 0; }, "must be 0 or more");
}

}  // namespace dispex::cli

int main(int argc, char** argv) {
  using namespace dispex::cli;
  dispex::KeepFreedMemory();  // one run's phases re-use each other's pages
  CLI::App app{"dispex " DISPEX_VERSION_STRING
               ": displacement maps (Ptex) from a Catmull-Clark base mesh and its sculpt"};
  app.set_version_flag("--version", dispex::Version());
  app.require_subcommand(1);
  int exit_code = 0;
  auto registry = Registry();
  std::stable_sort(registry.begin(), registry.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [order, setup] : registry) setup(app, exit_code);
  bool known = false;
  for (const CLI::App* sub : app.get_subcommands({})) {
    known |= argc > 1 && sub->get_name() == argv[1];
  }
  if (argc > 1 && argv[1][0] != '-' && !known) {
    std::fprintf(stderr, "%s\n", UnknownCommandMessage(app, argv[1]).c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s\n", ParseErrorMessage(app, e, argc, argv).c_str());
    return 2;
  }
  return exit_code;
}
