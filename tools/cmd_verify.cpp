// dispex verify BASE [SCULPT] MAP.ptx [--truth FILE] [--tolerance T] [--max-error E]
//               or --displaced MESH SCULPT [--max-p99 E]
//               [--max-edge-step K] [--max-edge-step-p99 K]
#include <fmt/format.h>

#include <cstdio>

#include "command.h"
#include "dispex/files.h"
#include "dispex/verify.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kVerifyFlags[] = {
    {"sculpt_path", "a SCULPT"},
    {"truth_path", "--truth"},
    {"samples_per_face", "--samples"},
    {"max_error", "--max-error"},
    {"max_error_rel", "--max-error-rel"},
    {"max_rms", "--max-rms"},
    {"max_p99", "--max-p99"},
    {"max_mean_tolerances", "--max-mean-tolerances"},
};

struct VerifyArgs {
  std::vector<std::string> files;
  VerifyOptions options;
  std::string report_path;
  bool quiet = false;
};

int RunVerify(VerifyArgs& args) {
  VerifyOptions& o = args.options;
  if (!o.displaced_path.empty()) {
    if (args.files.size() != 1) {
      return ReportFailure(
          Status::Error("--displaced MESH takes one file, the SCULPT it is measured against"), 2);
    }
    o.sculpt_path = args.files[0];
  } else if (args.files.size() == 1) {
    return ReportFailure(Status::Error("BASE SCULPT MAP or BASE MAP expected"), 2);
  } else if (args.files.size() == 3) {
    o.base_path = args.files[0];
    o.sculpt_path = args.files[1];
    o.map_path = args.files[2];
  } else {
    o.base_path = args.files[0];
    o.map_path = args.files[1];
  }
  const Status outputs = CheckOutputs({{"--report", args.report_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  auto report = Verify(o);
  if (!report.ok()) return ReportFailure(report.status(), kVerifyFlags);
  if (!args.report_path.empty()) {
    std::string json = VerifyReportJson(*report);
    Status written = WriteFileAtomically(args.report_path, json.data(), json.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--report"));
  }
  if (!args.quiet) {
    for (const std::string& w : report->warnings) fmt::print(stderr, "dispex: warning: {}\n", w);
    std::fputs(VerifyReportSummary(*report).c_str(), stdout);
  }
  if (!report->passed) {
    const std::string& measured = o.displaced_path.empty() ? o.map_path : o.displaced_path;
    return ReportFailure(Status::Error(measured + ": " + report->failure), kVerifyFlags, 3);
  }
  return 0;
}

void SetupVerify(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<VerifyArgs>();
  VerifyOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "verify",
      "Measure a displacement map: the base limit surface displaced by MAP against the "
      "sculpt, both ways (and/or against a make-sculpt truth file), and the steps at shared "
      "face edges");
  cmd->add_option("files", args->files,
                  "BASE SCULPT MAP.ptx, or BASE MAP.ptx (edge steps, and --truth if given), or "
                  "SCULPT with --displaced")
      ->required()
      ->expected(1, 3);
  cmd->add_option("--displaced", o.displaced_path,
                  "measure this already displaced mesh (e.g. a renderer's) against SCULPT, both "
                  "ways, instead of a map");
  cmd->add_option("--max-p99", o.max_p99,
                  "fail (exit 3) when a 99th-percentile error exceeds this, object units")
      ->check(Positive());
  cmd->add_option("--truth", o.truth_path, "make-sculpt truth file: compare with the exact h");
  cmd->add_option("--samples", o.samples_per_face,
                  "samples per side of each face (0: twice the map resolution, 8..64)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--max-sculpt-points", o.max_sculpt_points,
                  "sculpt vertices measured (evenly strided; 0: all)")
      ->capture_default_str();
  cmd->add_option("--max-error", o.max_error,
                  "fail (exit 3) when a max error exceeds this, object units")
      ->check(Positive());
  cmd->add_option("--max-error-rel", o.max_error_rel,
                  "fail when a max error exceeds this fraction of the bounding-box diagonal")
      ->check(Positive());
  cmd->add_option("--max-mean-tolerances", o.max_mean_tolerances,
                  "fail (exit 3) when the mean distance from the sculpt's points to the displaced "
                  "surface exceeds this many of the map's tolerances (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--max-rms", o.max_rms,
                  "fail (exit 3) when an RMS error exceeds this, object units")
      ->check(Positive());
  cmd->add_option("--tolerance", o.tolerance,
                  "tau of the truth and edge bounds (default: the map's own, from its meta data)")
      ->check(Positive());
  cmd->add_option("--truth-rms-factor", o.truth_rms_factor,
                  "fail when the truth RMS exceeds this x tau (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--truth-p99-factor", o.truth_p99_factor,
                  "fail when the truth 99th percentile exceeds this x tau (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--truth-local-factor", o.truth_local_tolerance_factor,
                  "k of the per-record bound k tau + 2 x the sculpt's local linear error")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_flag("!--no-local-bound", o.truth_local_bound, "no per-record bound");
  cmd->add_option("--max-edge-step", o.max_edge_step,
                  "fail when a step at a shared face edge (either reader) exceeds this x tau")
      ->check(Positive());
  cmd->add_option("--max-edge-step-p99", o.max_edge_step_p99,
                  "fail when the 99th percentile of the edge steps exceeds this x tau")
      ->check(Positive());
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--report", args->report_path, "write a JSON report to this file");
  cmd->add_flag("-q,--quiet", args->quiet, "no summary on stdout");
  cmd->callback([args, &exit_code] { exit_code = RunVerify(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(30, SetupVerify);

}  // namespace dispex::cli
