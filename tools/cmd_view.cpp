// dispex view BASE MAP -o review.html [--sculpt SCULPT] [--verify REPORT.json]
// [--extract-report REPORT.json] [--max-vertices N] [--sculpt-vertices N] [--report R.json]
#include <fmt/format.h>

#include <cstdio>

#include "command.h"
#include "dispex/files.h"
#include "dispex/view.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kViewFlags[] = {
    {"max_vertices", "--max-vertices"},
    {"max_sculpt_vertices", "--sculpt-vertices"},
    {"max_grid", "--max-grid"},
    {"grid", "--grid"},
    {"max_atlas_bytes", "--max-atlas-bytes"},
    {"threads", "--threads"},
};

struct ViewArgs {
  std::string output_path;
  std::string report_path;
  bool no_atlas = false;
  bool quiet = false;
  ViewPageOptions options;
};

int RunView(ViewArgs& args) {
  ViewPageOptions& o = args.options;
  if (args.no_atlas) o.max_atlas_bytes = 0;
  Status valid = ValidateViewPageOptions(o);
  if (!valid.ok()) return ReportFailure(valid, kViewFlags, 2);
  for (const std::string* input :
       {&o.base_path, &o.map_path, &o.sculpt_path, &o.verify_report_path, &o.extract_report_path}) {
    if (!input->empty() && (*input == args.output_path || *input == args.report_path)) {
      return ReportFailure(
          Status::Error(fmt::format("{}: an input cannot be an output of the command", *input)), 2);
    }
  }
  const Status outputs = CheckOutputs({{"-o", args.output_path}, {"--report", args.report_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  auto report = WriteViewPage(o, args.output_path);
  if (!report.ok()) {
    const bool usage = report.status().code() == StatusCode::kInvalidArgument;
    return ReportFailure(report.status(), kViewFlags, usage ? 2 : 1);
  }
  if (!args.report_path.empty()) {
    const std::string json = ViewPageReportJson(*report);
    Status written = WriteFileAtomically(args.report_path, json.data(), json.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--report"));
  }
  if (!args.quiet) {
    for (const std::string& w : report->warnings) fmt::print(stderr, "dispex: warning: {}\n", w);
    for (const std::string& n : report->notes) {
      fmt::print(stderr, "dispex: note: {}\n", WithFlagNames(n, kViewFlags));
    }
    std::string sculpt;
    if (report->sculpt_vertices > 0) {
      sculpt = fmt::format(", sculpt {} of {} vertices", report->sculpt_vertices,
                           report->sculpt_vertices_read);
    }
    fmt::print(stderr,
               "dispex: {} ({:.1f} MB: {} map, {} Ptex faces, grid {}, {} vertices{}{}) in "
               "{:.2f}s\n",
               args.output_path, double(report->page_bytes) / 1e6, report->map_kind,
               report->ptex_faces, report->grid, report->surface_vertices, sculpt,
               report->atlas ? ", atlas" : "", report->seconds);
  }
  return 0;
}

void SetupView(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ViewArgs>();
  ViewPageOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Write one self-contained HTML page (WebGL, three.js inside, nothing fetched) that shows "
      "the base's limit surface displaced by MAP, the limit surface and the sculpt, coloured "
      "by displacement, resolution, verify error or holes, with the map's report and atlas");
  cmd->add_option("base", o.base_path, "base cage (OBJ or PLY)")->required();
  cmd->add_option("map", o.map_path,
                  "the map: a Ptex file, or UV-space tiles 'DIR/<shape>.<UDIM>.exr' (or one tile)")
      ->required();
  cmd->add_option("-o,--output", args->output_path, "HTML page to write")->required();
  cmd->add_option("--sculpt", o.sculpt_path, "the sculpt, shown decimated (--sculpt-vertices)");
  cmd->add_option("--verify", o.verify_report_path,
                  "a report of `dispex verify --report` for the map: per-face errors, summary");
  cmd->add_option("--extract-report", o.extract_report_path,
                  "the map's `dispex extract --report`: the extraction's times");
  cmd->add_option("--title", o.title, "the page's title (default: the map's file name)");
  cmd->add_option("--max-vertices", o.max_vertices,
                  "vertices of the surface on the page: the grid per face is the finest within")
      ->capture_default_str();
  cmd->add_option("--sculpt-vertices", o.max_sculpt_vertices,
                  "vertices of the sculpt on the page (vertex clustering; 0: leave it out)")
      ->capture_default_str();
  cmd->add_option("--grid", o.grid,
                  "quads per side of every quad face, even on a base with n-gons (0: the finest "
                  "within --max-vertices)")
      ->capture_default_str();
  cmd->add_option("--max-grid", o.max_grid, "the finest automatic grid")->capture_default_str();
  cmd->add_option("--max-atlas-bytes", o.max_atlas_bytes,
                  "leave the atlas out when its PNG is larger")
      ->capture_default_str();
  cmd->add_flag("--no-atlas", args->no_atlas, "no atlas on the page");
  cmd->add_option("--report", args->report_path,
                  "write a JSON report: what is on the page, its size by part, notes");
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no summary");
  cmd->callback([args, &exit_code] { exit_code = RunView(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(55, SetupView);

}  // namespace dispex::cli
