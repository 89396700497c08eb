// dispex extract BASE SCULPT -o OUT.ptx | --out-dir DIR [--shapes a,b] | --manifest FILE [options]
#include <fmt/format.h>

#include <cstdio>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/cancel.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/render.h"
#include "flag_names.h"
#include "progress_lines.h"
#include "watch.h"

namespace dispex::cli {
namespace {

// The library's field names in messages, spelled as flags: phrases, fields that are not extract
// options, and the one-word options where messages use them as fields, then the flag of every
// option with a snake_case name (one word such as "vector" or "shard" is also plain English).
const std::vector<FlagName>& ExtractFlagNames() {
  static const std::vector<FlagName> flags = [] {
    std::vector<FlagName> out = {
        {"output_path", "-o"},          {"with check_inputs off", "with --no-input-checks"},
        {"0 (automatic)", "'auto'"},    {"fixed_ulog2 x fixed_vlog2", "--fixed-resolution (log2)"},
        {"output_dir", "--out-dir"},    {"shard_count", "--shard"},
        {"oversample", "--oversample"}, {"tolerance", "--tolerance"},
        {"holes", "--holes"},           {"method", "--method"},
        {"threads", "--threads"},
    };
    for (const ExtractOptionSpec& option : ExtractOptionSpecs()) {
      if (option.name.find('_') != std::string_view::npos) {
        out.push_back({option.name, option.flag});
      }
    }
    return out;
  }();
  return flags;
}

struct ExtractArgs {
  ExtractOptions options;  // the table's options set as their flags are parsed (AddTableFlags)
  double search_distance_rel = 0;
  std::string report_path;
  std::string preview_dir;
  std::string output_dir;
  std::vector<std::string> shapes;
  std::string manifest_path;
  bool quiet = false;
  bool progress_lines = false;
  ProgressLines* lines = nullptr;  // with --progress-lines, while the work runs
  bool watch = false;
  int watch_settle_ms = WatchSettings{}.settle_ms;

  bool asset() const { return !output_dir.empty() || !manifest_path.empty(); }
};

// --search-distance-rel: the search distance as a fraction, spelled apart (0: not given).
Status ApplySearchDistanceRel(ExtractArgs& a) {
  if (a.search_distance_rel == 0) return Status::Ok();
  if (a.options.search_distance.kind != SearchDistanceSpec::Kind::kAuto) {
    return Status::Error("give --search-distance or --search-distance-rel, not both");
  }
  a.options.search_distance = {SearchDistanceSpec::Kind::kRelative, a.search_distance_rel};
  return Status::Ok();
}

// The files beside the map (--report, --preview, --out-dir): writable, the report none of the
// inputs and outputs.
Status CheckOtherOutputs(const ExtractArgs& a) {
  const ExtractOptions& o = a.options;
  if (!a.report_path.empty() && (a.report_path == o.base_path || a.report_path == o.sculpt_path ||
                                 a.report_path == o.output_path)) {
    return Status::Error(
        fmt::format("--report {}: must differ from the inputs and the output", a.report_path));
  }
  return CheckOutputs({{"--report", a.report_path},
                       {"--preview", a.preview_dir, /*folder=*/true},
                       {"--out-dir", a.output_dir, /*folder=*/true}});
}

// --watch: one map re-extracted each round, re-using it and its UV-space tiles.
Status ResolveWatch(ExtractArgs& a) {
  if (!a.watch) return Status::Ok();
  if (a.asset()) return Status::Error("--watch re-extracts one map (-o), not --out-dir/--manifest");
  if (a.options.shard_count > 0) {
    return Status::Error("--watch re-extracts a whole map, not a --shard");
  }
  a.options.incremental = true;
  return Status::Ok();
}

// What is written -- one map per shape (--out-dir, --manifest) or one map (-o) -- and the flags
// that go with it; one map's options are checked here, an asset's shapes' by ExtractAsset.
Status CheckTargets(const ExtractArgs& a) {
  const ExtractOptions& o = a.options;
  if (a.asset()) {
    if (!o.output_path.empty()) return Status::Error("give -o or --out-dir/--manifest, not both");
    if (!a.manifest_path.empty() && !a.shapes.empty()) {
      return Status::Error("--shapes selects shapes of BASE; a --manifest names its own");
    }
    if (!a.preview_dir.empty()) return Status::Error("--preview needs -o (one map)");
    return Status::Ok();
  }
  if (!a.shapes.empty()) return Status::Error("--shapes needs --out-dir (one map per shape)");
  if (o.shard_count > 0 && !a.preview_dir.empty()) {
    return Status::Error("--preview needs a whole map, not a shard's part: preview the merged map");
  }
  if (o.plan_only && (!a.preview_dir.empty() || a.watch)) {
    return Status::Error("--plan writes nothing: not with --preview or --watch");
  }
  if (o.base_path.empty() || o.sculpt_path.empty()) {
    return Status::Error("give BASE and SCULPT (or --manifest)");
  }
  if (o.output_path.empty()) return Status::Error("give -o OUT.ptx, or --out-dir DIR");
  return ValidateExtractOptions(o);
}

// The parsed command line made whole and checked, before any work. The table's options are set
// and their values checked as they are parsed (AddTableFlags).
Status Resolve(ExtractArgs& a) {
  DISPEX_RETURN_IF_ERROR(ApplySearchDistanceRel(a));
  a.options.progress = !a.quiet && !a.progress_lines && StderrIsInteractive();
  DISPEX_RETURN_IF_ERROR(CheckOtherOutputs(a));
  DISPEX_RETURN_IF_ERROR(ResolveWatch(a));
  return CheckTargets(a);
}

// The exit status of a run: its error, or 0 once its JSON report is written and its summary
// printed.
template <class Report>
int Conclude(const ExtractArgs& args, const StatusOr<Report>& report,
             std::string (*json)(const Report&), std::string (*summary)(const Report&)) {
  if (args.lines != nullptr) args.lines->Finish();  // the last progress line before the rest
  if (!report.ok()) {
    int sig = CancelSignal();
    return ReportFailure(report.status(), ExtractFlagNames(), sig ? 128 + sig : 1);
  }
  if (!args.report_path.empty()) {
    const std::string text = json(*report);
    Status written = WriteFileAtomically(args.report_path, text.data(), text.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--report"));
  }
  if (!args.quiet) std::fputs(summary(*report).c_str(), stderr);
  return 0;
}

// --out-dir or --manifest: one map per shape.
int RunAsset(ExtractArgs& args) {
  ExtractAssetOptions asset;
  asset.options = args.options;
  asset.output_dir = args.output_dir;
  asset.shapes = args.shapes;
  if (!args.manifest_path.empty()) {
    if (!args.options.base_path.empty() || !args.options.sculpt_path.empty()) {
      return ReportFailure(Status::Error("--manifest names the files: give no BASE or SCULPT"),
                           ExtractFlagNames(), 2);
    }
    auto read = ReadExtractManifest(args.manifest_path, asset);
    if (!read.ok()) return ReportFailure(read.status(), ExtractFlagNames(), 2);
    asset = std::move(*read);
  } else if (args.options.base_path.empty() || args.options.sculpt_path.empty()) {
    return ReportFailure(Status::Error("give BASE and SCULPT (or --manifest)"), ExtractFlagNames(),
                         2);
  }
  return Conclude(args, ExtractAsset(asset), AssetReportJson, AssetReportSummary);
}

// --watch (tools/watch.h): a round at start and one per save of BASE or SCULPT, each printing a
// line; one that fails leaves the map as it was. Ends on Ctrl-C: 128 + the signal.
int RunWatchRounds(const ExtractArgs& args) {
  WatchSettings settings;
  settings.settle_ms = args.watch_settle_ms;
  std::vector<std::string> warned;
  const ExtractOptions& o = args.options;
  return RunWatch(
      {o.base_path, o.sculpt_path}, settings, args.quiet,
      [&](const std::vector<std::string>& changed) {
        ProgressLines lines("extract", args.progress_lines);
        ExtractOptions options = o;
        options.progress_counter = lines.counter();
        const StatusOr<ExtractReport> report = Extract(options);
        lines.Finish();
        if (CancelRequested()) return;
        if (!report.ok()) {
          const std::string why = WithFlagNames(report.status().message(), ExtractFlagNames());
          std::fputs(WatchFailureLine(changed, o.output_path, why).c_str(), stderr);
          return;
        }
        if (!args.report_path.empty()) {
          const std::string text = ExtractReportJson(*report);
          Status written = WriteFileAtomically(args.report_path, text.data(), text.size());
          if (!written.ok()) ReportFailure(written.WithPrefix("--report"));
        }
        if (!args.preview_dir.empty() && (!report->incremental.unchanged || changed.empty())) {
          Status previews = WritePreviews(o.base_path, o.output_path, args.preview_dir);
          if (!previews.ok()) ReportFailure(previews.WithPrefix("--preview"));
        }
        if (!args.quiet) {
          std::fputs(WatchRoundLines(changed, *report, warned).c_str(), stderr);
        }
      });
}

int RunExtract(ExtractArgs& args) {
  Status resolved = Resolve(args);
  if (!resolved.ok()) return ReportFailure(resolved, ExtractFlagNames(), 2);
  InstallCancelSignalHandlers();
  if (args.watch) return RunWatchRounds(args);
  ProgressLines lines(args.asset() ? "shapes" : "extract", args.progress_lines);
  args.options.progress_counter = lines.counter();
  args.lines = &lines;
  if (args.asset()) return RunAsset(args);
  const int status = Conclude(args, Extract(args.options), ExtractReportJson, ExtractReportSummary);
  if (status != 0) return status;
  if (!args.preview_dir.empty()) {
    Status previews =
        WritePreviews(args.options.base_path, args.options.output_path, args.preview_dir);
    if (!previews.ok()) return ReportFailure(previews.WithPrefix("--preview"));
  }
  return 0;
}

// BASE, SCULPT and where the maps go.
void AddInputsAndOutputs(CLI::App* cmd, ExtractArgs& a) {
  ExtractOptions& o = a.options;
  cmd->add_option("base", o.base_path, "base mesh: the Catmull-Clark cage (.obj, .ply)");
  cmd->add_option("sculpt", o.sculpt_path, "sculpted high-resolution mesh (.obj, .ply)");
  cmd->add_option("-o,--output", o.output_path, "output Ptex file (.ptx) of a single-shape base");
  cmd->add_option("--out-dir", a.output_dir,
                  "one map per shape (OBJ o/g group) of the base: DIR/<shape>.ptx, each shape's "
                  "rays hitting only the sculpt's shape of the same name");
  cmd->add_option("--shapes", a.shapes, "with --out-dir: only these shapes (a,b,c)")
      ->delimiter(',');
  cmd->add_option("--manifest", a.manifest_path,
                  "JSON naming shapes spread over several files, with options per shape "
                  "(docs/SHAPES.md); the command line's options are its defaults");
}

// CLI11's name in --help of the type of an option's value.
std::string TypeName(OptionKind kind) {
  switch (kind) {
    case OptionKind::kInteger:
      return "INT";
    case OptionKind::kNumber:
      return "FLOAT";
    default:
      return "TEXT";
  }
}

// A flag for every option of the library's table (ExtractOptionSpecs), with its help line and
// default from there; each value is set through the table's setter as it is parsed, so a bad
// value is a parse error naming the flag: "--tolerance: x is not a number".
void AddTableFlags(CLI::App* cmd, ExtractOptions& o) {
  for (const ExtractOptionSpec& spec : ExtractOptionSpecs()) {
    auto set = [&o, name = spec.name](const std::string& text) {
      const Status status = SetExtractOptionText(o, name, text);
      if (!status.ok()) {
        throw CLI::ValidationError(WithFlagNames(status.message(), ExtractFlagNames()));
      }
    };
    if (spec.kind == OptionKind::kBool) {
      // The flag gives the opposite of the default: "!" has CLI11 give "false".
      const std::string flag = (spec.default_text == "true" ? "!" : "") + std::string(spec.flag);
      cmd->add_flag(flag)->description(std::string(spec.help))->each(set);
      continue;
    }
    CLI::Option* option = cmd->add_option(std::string(spec.flag))
                              ->description(std::string(spec.help))
                              ->type_name(TypeName(spec.kind));
    if (!spec.default_text.empty()) option->default_str(std::string(spec.default_text));
    // 0 is automatic, which here is the flag left out: said in --help (":> 0") and refused.
    if (spec.zero_is_auto && spec.kind != OptionKind::kIntegerOrAuto) option->check(Positive());
    option->each(set);
  }
}

// The command line's own flags: how the run shows itself, and what else it writes.
void AddRunFlags(CLI::App* cmd, ExtractArgs& a) {
  // 0 stands for "not given" here, so 0 itself is refused as a value.
  cmd->add_option("--search-distance-rel", a.search_distance_rel,
                  "search distance as a fraction of the base bounding-box diagonal")
      ->check(Positive());
  CLI::Option* watch =
      cmd->add_flag("--watch", a.watch,
                    "keep running: extract again each time BASE or SCULPT is saved, re-using the "
                    "map (--incremental; UV-space maps: a full extraction), one line per round; "
                    "a broken save leaves the map as it was; Ctrl-C ends it (exit 130)");
  cmd->add_option("--watch-settle", a.watch_settle_ms,
                  "with --watch: milliseconds a file written in place must stay unchanged (size, "
                  "time) before it is read")
      ->check(NonNegative())
      ->needs(watch)
      ->capture_default_str();
  cmd->add_option("--report", a.report_path, "write a JSON report to this file");
  cmd->add_option("--preview", a.preview_dir,
                  "also write DIR/<map>_atlas.png and DIR/<map>_compare.png (base and base + "
                  "map side by side)");
  cmd->add_flag("-q,--quiet", a.quiet, "no progress bar and no summary");
  cmd->add_flag("--progress-lines", a.progress_lines,
                "progress for a program that drives the command: a line 'progress extract "
                "DONE/TOTAL' (Ptex faces; 'progress shapes' with --out-dir) on stderr up to 10 "
                "times a second and once at the end, also when stderr is not a terminal (instead "
                "of the bar; -q leaves them on)");
}

void SetupExtract(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ExtractArgs>();
  CLI::App* cmd = app.add_subcommand(
      "extract",
      "Extract a Ptex displacement map: BASE cage + SCULPT -> OUT.ptx, or one map per shape");
  AddInputsAndOutputs(cmd, *args);
  AddTableFlags(cmd, args->options);
  AddRunFlags(cmd, *args);
  cmd->callback([args, &exit_code] { exit_code = RunExtract(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(20, SetupExtract);

}  // namespace dispex::cli
