// dispex merge PART... -o OUT.ptx: the map from the parts of every shard (docs/FARM.md).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/cancel.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kMergeFlags[] = {
    {"output_path", "-o"},
    {"threads", "--threads"},
    {"max_memory", "--max-memory"},
};

struct MergeArgs {
  MergeOptions options;
  std::string report_path;
  std::string max_memory;
  bool quiet = false;
};

int RunMerge(MergeArgs& args) {
  args.options.progress = !args.quiet && StderrIsInteractive();
  if (!args.report_path.empty() && args.report_path == args.options.output_path) {
    return ReportFailure(Status::Error("--report: must differ from the output"), 2);
  }
  const Status outputs = CheckOutputs({{"--report", args.report_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  if (!args.max_memory.empty()) {
    StatusOr<std::uint64_t> limit = ParseByteSize(args.max_memory);
    if (!limit.ok()) return ReportFailure(limit.status().WithPrefix("--max-memory"), 2);
    args.options.max_memory = *limit;
  }
  InstallCancelSignalHandlers();
  StatusOr<ExtractReport> report = MergeShards(args.options);
  if (!report.ok()) {
    const int sig = CancelSignal();
    return ReportFailure(report.status(), kMergeFlags, sig ? 128 + sig : 1);
  }
  if (!args.report_path.empty()) {
    const std::string text = ExtractReportJson(*report);
    Status written = WriteFileAtomically(args.report_path, text.data(), text.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--report"));
  }
  if (!args.quiet) std::fputs(ExtractReportSummary(*report).c_str(), stderr);
  return 0;
}

void SetupMerge(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Merge the parts of every shard (`extract --shard I/N`) into the map a single extraction "
      "writes, byte for byte; reads the base and sculpt the parts name");
  cmd->add_option("parts", args->options.parts, "the parts, one per shard, in any order")
      ->required();
  cmd->add_option("-o,--output", args->options.output_path, "output Ptex file (.ptx)")->required();
  cmd->add_option("--threads", args->options.threads, "worker threads (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--max-memory", args->max_memory,
                  "the memory to keep within, e.g. 8G (default: the memory available; as "
                  "extract's --max-memory)");
  cmd->add_option("--report", args->report_path, "write a JSON report to this file");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress bar and no summary");
  cmd->callback([args, &exit_code] { exit_code = RunMerge(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(25, SetupMerge);

}  // namespace dispex::cli
