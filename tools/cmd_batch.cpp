// dispex batch MANIFEST.json: every asset of a batch manifest on this machine (docs/FARM.md);
// with --asset and --shard, one shard of one asset (what the farm's jobs run).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/cancel.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/view.h"
#include "flag_names.h"
#include "part_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kBatchFlags[] = {
    {"shard_count", "--shard"},
    {"shard_sculpt", "--shard-sculpt"},
    {"threads", "--threads"},
};

struct BatchArgs {
  std::string manifest;
  std::string asset;
  std::string shard;
  std::string parts_dir;
  std::string shard_sculpt = "whole";
  std::string report_path;
  std::string view_dir;
  int threads = 0;
  bool incremental = false;
  bool quiet = false;
};

// The manifest's assets, narrowed to --asset, and for --shard that asset's shard and part.
StatusOr<std::vector<BatchAsset>> SelectAssets(const BatchArgs& args) {
  ExtractOptions defaults;
  defaults.threads = args.threads;
  defaults.incremental = args.incremental;
  DISPEX_ASSIGN_OR_RETURN(std::vector<BatchAsset> assets,
                          ReadBatchManifest(args.manifest, defaults));
  if (!args.asset.empty()) {
    std::erase_if(assets, [&](const BatchAsset& a) { return a.name != args.asset; });
    if (assets.empty()) {
      return Status::Error(
          fmt::format("--asset {}: no such asset in {}", args.asset, args.manifest));
    }
  }
  if (!args.shard.empty()) {
    if (args.asset.empty() || args.parts_dir.empty()) {
      return Status::Error("--shard needs --asset and --parts-dir");
    }
    ExtractOptions& o = assets.front().options;
    Status parsed = ParseShard(args.shard, o.shard_index, o.shard_count);
    if (!parsed.ok()) return parsed.WithPrefix("--shard");
    auto shard_sculpt = ParseShardSculpt(args.shard_sculpt);
    if (!shard_sculpt.ok()) return shard_sculpt.status().WithPrefix("--shard-sculpt");
    o.shard_sculpt = *shard_sculpt;
    o.output_path = PartPath(args.parts_dir, args.asset, o.shard_index, o.shard_count);
  } else if (!args.parts_dir.empty()) {
    return Status::Error("--parts-dir needs --shard");
  }
  if (!args.view_dir.empty() && !args.shard.empty()) {
    return Status::Error("--view shows whole maps: not with --shard");
  }
  DISPEX_RETURN_IF_ERROR(
      CheckOutputs({{"--report", args.report_path}, {"--view", args.view_dir, true}}));
  return assets;
}

// What the batch has done so far: its report, failures and review pages.
struct BatchRun {
  nlohmann::json report;
  int failed = 0;
  std::vector<ViewIndexEntry> pages;
  int pages_failed = 0;
};

// The asset's review page (dispex view), its sculpt and its extraction's report in it.
void WriteAssetPage(const BatchArgs& args, const BatchAsset& asset, const std::string& extract_json,
                    const std::string& progress, nlohmann::json& entry, BatchRun& run) {
  ViewPageOptions view;
  view.base_path = asset.options.base_path;
  view.map_path = asset.options.output_path;
  view.sculpt_path = asset.options.sculpt_path;
  view.extract_report_json = extract_json;
  view.title = asset.name;
  view.threads = args.threads;
  const std::string page = asset.name + ".html";
  const std::string path = (std::filesystem::path(args.view_dir) / page).string();
  StatusOr<ViewPageReport> shown = WriteViewPage(view, path);
  if (shown.ok()) {
    entry["view"] = path;
    run.pages.push_back({asset.name, page, "ok",
                         fmt::format("{} map, {} Ptex faces, {:.1f} MB page", shown->map_kind,
                                     shown->ptex_faces, double(shown->page_bytes) / 1e6)});
    return;
  }
  ++run.pages_failed;
  entry["view_error"] = shown.status().message();
  run.pages.push_back({asset.name, "", "no page", shown.status().message()});
  std::fprintf(stderr, "dispex: %s %s: page FAILED: %s\n", progress.c_str(), asset.name.c_str(),
               shown.status().message().c_str());
}

// One asset extracted (its output folder made when missing, as a farm's merge job makes it),
// its entry in the report, and its page with --view.
void RunAsset(const BatchArgs& args, const BatchAsset& asset, const std::string& progress,
              BatchRun& run) {
  std::error_code ec;
  std::filesystem::create_directories(
      std::filesystem::path(asset.options.output_path).parent_path(), ec);
  StatusOr<ExtractReport> r = Extract(asset.options);
  nlohmann::json entry = {{"name", asset.name}, {"output", asset.options.output_path}};
  if (r.ok()) {
    entry["status"] = "ok";
    const std::string extract_json = ExtractReportJson(*r);
    entry["report"] = nlohmann::json::parse(extract_json);
    if (!args.quiet) {
      std::fprintf(stderr, "dispex: %s %s: %s, %.2fs, peak %.0f MB -> %s\n", progress.c_str(),
                   asset.name.c_str(), r->incremental.unchanged ? "up to date" : "ok",
                   r->times.total, double(r->peak_rss_bytes) / 1e6,
                   asset.options.output_path.c_str());
    }
    if (!args.view_dir.empty()) WriteAssetPage(args, asset, extract_json, progress, entry, run);
  } else {
    ++run.failed;
    const std::string message = WithFlagNames(r.status().message(), kBatchFlags);
    entry["status"] = "failed";
    entry["error"] = message;
    std::fprintf(stderr, "dispex: %s %s: FAILED: %s\n", progress.c_str(), asset.name.c_str(),
                 message.c_str());
    run.pages.push_back({asset.name, "", "failed", message});
  }
  run.report["assets"].push_back(std::move(entry));
}

// The batch's index page, linking each asset's.
Status WriteIndexPage(const BatchArgs& args, BatchRun& run) {
  const std::string index = MakeViewIndex(
      std::filesystem::path(args.manifest).filename().string() + " - dispex batch", run.pages);
  const std::string path = (std::filesystem::path(args.view_dir) / "index.html").string();
  Status written = WriteFileAtomically(path, index.data(), index.size());
  if (!written.ok()) return written.WithPrefix("--view");
  run.report["view_index"] = path;
  if (!args.quiet) std::fprintf(stderr, "dispex: %s: %zu pages\n", path.c_str(), run.pages.size());
  return Status::Ok();
}

int RunBatch(BatchArgs& args) {
  auto assets = SelectAssets(args);
  if (!assets.ok()) return ReportFailure(assets.status(), 2);
  InstallCancelSignalHandlers();
  BatchRun run;
  run.report["manifest"] = args.manifest;
  run.report["assets"] = nlohmann::json::array();
  const std::size_t n = assets->size();
  for (std::size_t k = 0; k < n && !CancelRequested(); ++k) {
    RunAsset(args, (*assets)[k], fmt::format("[{}/{}]", k + 1, n), run);
  }
  run.report["failed"] = run.failed;
  if (!args.view_dir.empty()) {
    run.report["pages_failed"] = run.pages_failed;
    const Status index = WriteIndexPage(args, run);
    if (!index.ok()) return ReportFailure(index);
  }
  if (!args.report_path.empty()) {
    const std::string text = run.report.dump(2) + "\n";
    Status written = WriteFileAtomically(args.report_path, text.data(), text.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--report"));
  }
  if (const int sig = CancelSignal()) return ReportFailure(Status::Error("cancelled"), 128 + sig);
  if (run.failed > 0) std::fprintf(stderr, "dispex: %d of %zu assets failed\n", run.failed, n);
  if (run.pages_failed > 0) {
    std::fprintf(stderr, "dispex: %d review pages failed\n", run.pages_failed);
  }
  if (run.failed > 0 || run.pages_failed > 0) return 1;
  if (!args.quiet && n > 1) std::fprintf(stderr, "dispex: all %zu assets done\n", n);
  return 0;
}

void SetupBatch(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<BatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "batch",
      "Extract every asset of a batch manifest (JSON: base, sculpt, output folder, options per "
      "asset) on this machine; a failing asset does not stop the others");
  cmd->add_option("manifest", args->manifest, "the batch manifest (docs/FARM.md)")->required();
  cmd->add_option("--asset", args->asset, "only this asset");
  cmd->add_option("--shard", args->shard,
                  "I/N: with --asset, only the I-th of N shards, a part in --parts-dir (what "
                  "`dispex farm` jobs run)");
  cmd->add_option("--parts-dir", args->parts_dir,
                  "with --shard: the part is DIR/<asset>.part-I-of-N.ptx");
  cmd->add_option("--shard-sculpt", args->shard_sculpt,
                  "with --shard: what the shard keeps of the sculpt, whole or part (docs/FARM.md)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "worker threads (0: all cores)")
      ->capture_default_str();
  cmd->add_flag("--incremental", args->incremental,
                "re-use each map (or part) already at its output path (docs/INCREMENTAL.md)");
  cmd->add_option("--report", args->report_path,
                  "write one JSON report: every asset's status, error or extraction report");
  cmd->add_option("--view", args->view_dir,
                  "also write a review page per asset (dispex view), DIR/<asset>.html, and "
                  "DIR/index.html linking them");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress lines (failures are still printed)");
  cmd->callback([args, &exit_code] { exit_code = RunBatch(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(35, SetupBatch);

}  // namespace dispex::cli
