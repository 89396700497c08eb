// dispex make-sculpt CAGE --levels L | --layout jittered --density N --pattern P|image:FILE.png
//   [--amplitude A] [--stream] -o SCULPT.obj   (P: smooth, detail, ridges, noise, none, sideways,
//   overhang)
#include <fmt/format.h>

#include "command.h"
#include "dispex/verify.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kMakeSculptFlags[] = {
    {"output_path", "-o"},        {"levels", "--levels"},   {"density", "--density"},
    {"amplitude", "--amplitude"}, {"threads", "--threads"}, {"streamed", "--stream"},
    {"truth_path", "--truth"},
};

struct MakeSculptArgs {
  MakeSculptOptions options;
  std::string pattern = "detail";
  std::string layout = "refined";
  bool quiet = false;
};

int RunMakeSculpt(MakeSculptArgs& args) {
  auto pattern = ParsePatternArgument(args.pattern);
  if (!pattern.ok()) return ReportFailure(pattern.status().WithPrefix("--pattern"), 2);
  args.options.pattern = pattern->pattern;
  args.options.image_path = pattern->image_path;
  auto layout = ParseSculptLayout(args.layout);
  if (!layout.ok()) return ReportFailure(layout.status().WithPrefix("--layout"), 2);
  args.options.layout = *layout;
  if (*layout == SculptLayout::kJittered && args.options.density == 0) {
    return ReportFailure(Status::Error("--layout jittered needs --density N (2..256)"), 2);
  }
  if (*layout == SculptLayout::kRefined && args.options.density != 0) {
    return ReportFailure(Status::Error("--density needs --layout jittered"), 2);
  }
  if (*layout == SculptLayout::kJittered &&
      (args.options.density < 2 || args.options.density > 256)) {
    return ReportFailure(
        Status::Error(fmt::format("--density {}: must be 2..256", args.options.density)), 2);
  }
  if (args.options.streamed && *layout != SculptLayout::kRefined) {
    return ReportFailure(Status::Error("--stream needs --layout refined"), 2);
  }
  if (args.options.streamed && !args.options.truth_path.empty()) {
    return ReportFailure(Status::Error("--stream writes no truth file: leave out --truth"), 2);
  }
  const Status outputs = CheckOutputs({{"-o", args.options.output_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  auto report = MakeSculpt(args.options);
  if (!report.ok()) return ReportFailure(report.status(), kMakeSculptFlags);
  if (!args.quiet) {
    for (const std::string& w : report->warnings) fmt::print(stderr, "dispex: warning: {}\n", w);
    const std::string vector = IsVectorPattern(args.options.pattern)
                                   ? fmt::format(", max |D| {:.4g}, max tangential |D| {:.4g}",
                                                 report->max_displacement, report->max_tangential)
                                   : "";
    if (args.options.streamed) {
      fmt::print(stderr,
                 "dispex: {} ({} vertices, {} quads; pattern {}, amplitude {:.4g}, h in "
                 "[{:.4g}, {:.4g}]{}; streamed, no truth file) in {:.2f}s\n",
                 args.options.output_path, report->vertices, report->faces, args.pattern,
                 report->amplitude, report->h_min, report->h_max, vector, report->seconds);
      return 0;
    }
    std::string truth = args.options.truth_path.empty() ? args.options.output_path + ".truth"
                                                        : args.options.truth_path;
    fmt::print(stderr,
               "dispex: {} ({} vertices, {} {}; pattern {}, amplitude {:.4g}, h in "
               "[{:.4g}, {:.4g}]{}, piecewise-linear error {:.3g}, {} folded faces) and {} in "
               "{:.2f}s\n",
               args.options.output_path, report->vertices, report->faces,
               args.options.layout == SculptLayout::kJittered ? "triangles" : "quads", args.pattern,
               report->amplitude, report->h_min, report->h_max, vector, report->linear_error,
               report->folded_faces, truth, report->seconds);
  }
  return 0;
}

void SetupMakeSculpt(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<MakeSculptArgs>();
  MakeSculptOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "make-sculpt",
      "Make a test sculpt with known displacement: the cage refined L times (or a jittered "
      "grid), displaced along the limit normal by a pattern (or by a vector pattern's D); "
      "writes SCULPT.obj and SCULPT.obj.truth");
  cmd->add_option("cage", o.cage_path, "base cage (.obj, .ply)")->required();
  cmd->add_option("-o,--output", o.output_path,
                  "sculpt to write (.obj, or .ply: binary, faster to read)")
      ->required();
  cmd->add_option("--levels", o.levels, "Catmull-Clark refinement levels (1..8; layout refined)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cmd->add_option("--layout", args->layout,
                  "refined (the cage refined L times, quads) or jittered (--density N: N x N "
                  "cells per Ptex face, jittered vertices, random diagonals, triangles)")
      ->capture_default_str();
  cmd->add_option("--density", o.density, "cells per Ptex face side of --layout jittered (2..256)");
  cmd->add_option("--pattern", args->pattern,
                  "smooth, detail, ridges, noise, none, or image:FILE.png (h = A (2 L - 1), L "
                  "the PNG's luminance at the cage's UVs; v = 0 at the image's bottom row); "
                  "vector patterns: sideways (tangential waves only, D.N = 0) or overhang "
                  "(bumps sheared along the surface until they fold back over themselves: no "
                  "scalar map holds them)")
      ->capture_default_str();
  cmd->add_option("--amplitude", o.amplitude,
                  "pattern amplitude in object units (default: 1% of the bounding-box diagonal)")
      ->check(Positive());
  cmd->add_option("--seed", o.seed, "seed of the noise pattern and the jittered layout")
      ->capture_default_str();
  cmd->add_option("--truth", o.truth_path, "ground-truth file (default: OUTPUT.truth)");
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("--stream", o.streamed,
                "write the refined sculpt as it is evaluated, in memory that grows with the cage "
                "(film-scale benchmark sculpts): a cage of quads only, PLY, no truth file");
  cmd->add_flag("-q,--quiet", args->quiet, "no summary");
  cmd->callback([args, &exit_code] { exit_code = RunMakeSculpt(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(40, SetupMakeSculpt);

}  // namespace dispex::cli
