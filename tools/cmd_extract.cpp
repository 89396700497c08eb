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
  ExtractOptions options;
  std::string oversample = "auto";
  std::string search_distance = "auto";
  double search_distance_rel = 0;
  std::string ray_policy = "nearest";
  std::string resolution_rule = "bound";
  std::string fixed_resolution = "64x64";
  std::string data_type = "float";
  std::string holes = "fill";
  std::string watertight = "filter";
  std::string bvh_quality = "low";
  std::string method = "auto";
  std::string vector;
  std::string report_path;
  std::string preview_dir;
  std::string max_memory;
  std::string output_dir;
  std::vector<std::string> shapes;
  std::string manifest_path;
  std::string shard;
  std::string shard_sculpt = "whole";
  bool quiet = false;
  bool progress_lines = false;
  ProgressLines* lines = nullptr;  // with --progress-lines, while the work runs
  bool watch = false;
  int watch_settle_ms = WatchSettings{}.settle_ms;

  bool asset() const { return !output_dir.empty() || !manifest_path.empty(); }
};

Status Resolve(ExtractArgs& a) {
  ExtractOptions& o = a.options;
  if (a.oversample != "auto") {
    try {
      std::size_t used = 0;
      o.oversample = std::stoi(a.oversample, &used);
      if (used != a.oversample.size() || o.oversample <= 0) throw std::invalid_argument("");
    } catch (...) {
      return Status::Error(
          fmt::format("--oversample {}: expected 'auto' or a power of two", a.oversample));
    }
  }
  if (a.search_distance_rel != 0) {
    if (a.search_distance != "auto") {
      return Status::Error("give --search-distance or --search-distance-rel, not both");
    }
    o.search_distance = {SearchDistanceSpec::Kind::kRelative, a.search_distance_rel};
  } else {
    auto spec = ParseSearchDistance(a.search_distance);
    if (!spec.ok()) return spec.status().WithPrefix("--search-distance");
    o.search_distance = *spec;
  }
  auto policy = ParseHitPolicy(a.ray_policy);
  if (!policy.ok()) return policy.status().WithPrefix("--ray-policy");
  o.ray_policy = *policy;
  auto rule = ParseResolutionRule(a.resolution_rule);
  if (!rule.ok()) return rule.status().WithPrefix("--resolution-rule");
  o.resolution_rule = *rule;
  int rx = 0, ry = 0;
  char x = 0, extra = 0;
  if (std::sscanf(a.fixed_resolution.c_str(), "%d%c%d%c", &rx, &x, &ry, &extra) != 3 || x != 'x' ||
      rx < 1 || ry < 1 || (rx & (rx - 1)) || (ry & (ry - 1))) {
    return Status::Error(fmt::format(
        "--fixed-resolution {}: expected WxH with powers of two, e.g. 64x64", a.fixed_resolution));
  }
  o.fixed_ulog2 = __builtin_ctz(static_cast<unsigned>(rx));
  o.fixed_vlog2 = __builtin_ctz(static_cast<unsigned>(ry));
  if (a.data_type == "float") {
    o.data_type = PtexDataType::kFloat;
  } else if (a.data_type == "half") {
    o.data_type = PtexDataType::kHalf;
  } else {
    return Status::Error(fmt::format("--data-type {}: expected float or half", a.data_type));
  }
  auto holes = ParseHolePolicy(a.holes);
  if (!holes.ok()) return holes.status().WithPrefix("--holes");
  o.holes = *holes;
  auto watertight = ParseWatertightEdges(a.watertight);
  if (!watertight.ok()) return watertight.status().WithPrefix("--watertight");
  o.watertight = *watertight;
  if (!a.vector.empty()) {
    auto space = ParseVectorSpace(a.vector);
    if (!space.ok()) return space.status().WithPrefix("--vector");
    o.vector = *space;
  }
  auto quality = ParseBuildQuality(a.bvh_quality);
  if (!quality.ok()) return quality.status().WithPrefix("--bvh-quality");
  o.bvh_quality = *quality;
  auto method = ParseExtractMethod(a.method);
  if (!method.ok()) return method.status().WithPrefix("--method");
  o.method = *method;
  o.progress = !a.quiet && !a.progress_lines && StderrIsInteractive();
  if (!a.shard.empty()) {
    Status shard = ParseShard(a.shard, o.shard_index, o.shard_count);
    if (!shard.ok()) return shard.WithPrefix("--shard");
  }
  auto shard_sculpt = ParseShardSculpt(a.shard_sculpt);
  if (!shard_sculpt.ok()) return shard_sculpt.status().WithPrefix("--shard-sculpt");
  o.shard_sculpt = *shard_sculpt;
  if (!a.max_memory.empty()) {
    auto bytes = ParseByteSize(a.max_memory);
    if (!bytes.ok()) return bytes.status().WithPrefix("--max-memory");
    o.max_memory = *bytes;
  }
  if (!a.report_path.empty() && (a.report_path == o.base_path || a.report_path == o.sculpt_path ||
                                 a.report_path == o.output_path)) {
    return Status::Error(
        fmt::format("--report {}: must differ from the inputs and the output", a.report_path));
  }
  DISPEX_RETURN_IF_ERROR(CheckOutputs({{"--report", a.report_path},
                                       {"--preview", a.preview_dir, /*folder=*/true},
                                       {"--out-dir", a.output_dir, /*folder=*/true}}));
  if (a.watch) {
    if (a.asset()) {
      return Status::Error("--watch re-extracts one map (-o), not --out-dir/--manifest");
    }
    if (o.shard_count > 0) return Status::Error("--watch re-extracts a whole map, not a --shard");
    // Each round re-uses the map; UV-space maps are not re-used: a full extraction each round.
    if (o.uv_maps_dir.empty()) o.incremental = true;
  }
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
        if (!args.preview_dir.empty() && (!report->unchanged || changed.empty())) {
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

void SetupExtract(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ExtractArgs>();
  ExtractOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "extract",
      "Extract a Ptex displacement map: BASE cage + SCULPT -> OUT.ptx, or one map per shape");
  cmd->add_option("base", o.base_path, "base mesh: the Catmull-Clark cage (.obj, .ply)");
  cmd->add_option("sculpt", o.sculpt_path, "sculpted high-resolution mesh (.obj, .ply)");
  cmd->add_option("-o,--output", o.output_path, "output Ptex file (.ptx) of a single-shape base");
  cmd->add_option("--out-dir", args->output_dir,
                  "one map per shape (OBJ o/g group) of the base: DIR/<shape>.ptx, each shape's "
                  "rays hitting only the sculpt's shape of the same name");
  cmd->add_option("--shapes", args->shapes, "with --out-dir: only these shapes (a,b,c)")
      ->delimiter(',');
  cmd->add_option("--manifest", args->manifest_path,
                  "JSON naming shapes spread over several files, with options per shape "
                  "(docs/SHAPES.md); the command line's options are its defaults");
  cmd->add_option("--oversample", args->oversample,
                  "samples per side of each face: 'auto' (from the sculpt's density) or a "
                  "power of two 1..512")
      ->capture_default_str();
  cmd->add_option("--max-oversample", o.max_oversample, "cap for automatic oversampling")
      ->capture_default_str();
  cmd->add_option("--min-oversample", o.min_oversample, "floor for automatic oversampling")
      ->capture_default_str();
  cmd->add_option("--search-distance", args->search_distance,
                  "how far along ±normal to look: 'auto', a length, or N% of the base "
                  "bounding-box diagonal")
      ->capture_default_str();
  // 0 stands for "not given" here, so 0 itself is refused as a value.
  cmd->add_option("--search-distance-rel", args->search_distance_rel,
                  "search distance as a fraction of the base bounding-box diagonal")
      ->check(Positive());
  cmd->add_option("--ray-policy", args->ray_policy,
                  "hit kept when both directions hit: nearest, outside-first, inside-first")
      ->capture_default_str();
  // The library reads tolerance 0 as automatic; here automatic is the option left out, so 0 is
  // refused rather than taken silently.
  cmd->add_option("--tolerance", o.tolerance,
                  "largest allowed error per face, object units (default: "
                  "--tolerance-fraction x the sculpt's median edge length)")
      ->check(Positive());
  cmd->add_option("--tolerance-fraction", o.tolerance_fraction,
                  "automatic tolerance as a fraction of the sculpt's median edge length")
      ->capture_default_str();
  cmd->add_option("--resolution-rule", args->resolution_rule,
                  "per-face resolution: bound (error bound), nonzero (published rule), fixed")
      ->capture_default_str();
  cmd->add_option("--nonzero-threshold", o.nonzero_threshold,
                  "|DCT coefficient| counted as non-zero by --resolution-rule nonzero")
      ->capture_default_str();
  cmd->add_option("--fixed-resolution", args->fixed_resolution, "WxH for --resolution-rule fixed")
      ->capture_default_str();
  cmd->add_option("--data-type", args->data_type, "texel type: float or half")
      ->capture_default_str();
  cmd->add_option("--compression-level", o.compression_level,
                  "deflate level 0..12 (-1: default, 1)")
      ->capture_default_str();
  cmd->add_option("--holes", args->holes,
                  "samples whose rays miss: fill (interpolate), fail (error), zero")
      ->capture_default_str();
  cmd->add_option("--watertight", args->watertight,
                  "shared face edges meet within the tolerance for: filter (the Ptex library's "
                  "filters), all (also readers that read each face on its own), off")
      ->capture_default_str();
  cmd->add_option("--max-miss-fraction", o.max_miss_fraction,
                  "fail when more than this fraction of the samples miss the sculpt after the "
                  "second search (0..1; 1: never)")
      ->capture_default_str();
  cmd->add_option("--method", args->method,
                  "where values come from: auto (interpolate when the sculpt is the base "
                  "refined, else rays), interpolate (the sculpt's vertex displacements "
                  "interpolated through the subdivision correspondence, no rays), mapping "
                  "(rays through the correspondence: the map follows the sculpt's flat quads), "
                  "rays (a BVH of the sculpt); interpolate and mapping fail when the sculpt is "
                  "not the base refined")
      ->capture_default_str();
  cmd->add_option("--bvh-quality", args->bvh_quality, "BVH build quality: low, medium, high")
      ->capture_default_str();
  cmd->add_option("--embree-isa", o.embree_isa,
                  "Embree kernels: sse2, sse4.2, avx, avx2, avx512 (default: $DISPEX_EMBREE_ISA, "
                  "else the widest this CPU runs)");
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")->capture_default_str();
  cmd->add_option("--max-memory", args->max_memory,
                  "refuse work estimated to need more memory than this (e.g. 8G; default: the "
                  "memory available)");
  cmd->add_option("--vector", args->vector,
                  "write a vector displacement map (3 channels: sculpt - limit surface) in this "
                  "space: tangent (T, B, N), parametric (dP/du, dP/dv, N) or object (x, y, z); "
                  "the sculpt must be the base refined (see `dispex match`)");
  cmd->add_option("--uv-maps", o.uv_maps_dir,
                  "also write UV-space maps: DIR/<map>.<UDIM>.exr (OpenEXR, one float channel, or "
                  "R, G, B = x, y, z with --vector object) for every UDIM tile the base's UVs "
                  "touch, extracted at each texel (UVs interpolated face-varying linearly; "
                  "docs/UV_MAPS.md)");
  cmd->add_option("--uv-resolution", o.uv_resolution, "texels per side of each UDIM tile")
      ->capture_default_str();
  cmd->add_option("--uv-padding", o.uv_padding,
                  "texels of dilation outside the UV faces, so that filtering at seams never "
                  "reads empty texels")
      ->capture_default_str();
  cmd->add_flag("!--no-input-checks", o.check_inputs,
                "extract inputs that look like a mistake: a sculpt with fewer faces than its "
                "base, or one moved, scaled or turned against it as a whole");
  cmd->add_flag("--plan", o.plan_only,
                "print the plan -- which faces would be traced and which copied, the method and "
                "what the BVH holds -- and stop: the inputs are read and matched, nothing is "
                "written (with --report, the report's \"plan\")");
  cmd->add_flag("--incremental", o.incremental,
                "re-use the map at the output path: left as it is when made from the same "
                "inputs and options, else only the faces whose inputs changed are extracted "
                "(the result is the file a full extraction writes)");
  cmd->add_option("--shard", args->shard,
                  "I/N: extract only the I-th of N shards of the faces (balanced by estimated "
                  "cost) into a part for `dispex merge` (docs/FARM.md)");
  cmd->add_option("--shard-sculpt", args->shard_sculpt,
                  "what a shard keeps of the sculpt: whole, or part (only what its faces' rays "
                  "reach: memory falls with N; needs --method rays and --search-distance)")
      ->capture_default_str();
  CLI::Option* watch =
      cmd->add_flag("--watch", args->watch,
                    "keep running: extract again each time BASE or SCULPT is saved, re-using the "
                    "map (--incremental; UV-space maps: a full extraction), one line per round; "
                    "a broken save leaves the map as it was; Ctrl-C ends it (exit 130)");
  cmd->add_option("--watch-settle", args->watch_settle_ms,
                  "with --watch: milliseconds a file written in place must stay unchanged (size, "
                  "time) before it is read")
      ->check(NonNegative())
      ->needs(watch)
      ->capture_default_str();
  cmd->add_option("--report", args->report_path, "write a JSON report to this file");
  cmd->add_option("--preview", args->preview_dir,
                  "also write DIR/<map>_atlas.png and DIR/<map>_compare.png (base and base + "
                  "map side by side)");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress bar and no summary");
  cmd->add_flag("--progress-lines", args->progress_lines,
                "progress for a program that drives the command: a line 'progress extract "
                "DONE/TOTAL' (Ptex faces; 'progress shapes' with --out-dir) on stderr up to 10 "
                "times a second and once at the end, also when stderr is not a terminal (instead "
                "of the bar; -q leaves them on)");
  cmd->callback([args, &exit_code] { exit_code = RunExtract(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(20, SetupExtract);

}  // namespace dispex::cli
