// dispex preview MAP.ptx -o map.png [--mode auto|grey|signed|vector] [--range auto|A] [--labels]
#include <fmt/format.h>

#include <charconv>
#include <cmath>

#include "command.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kPreviewFlags[] = {
    {"range", "--range"},       {"channel", "--channel"}, {"min_tile", "--tile"},
    {"max_tile", "--max-tile"}, {"width", "--width"},     {"threads", "--threads"},
};

struct PreviewArgs {
  std::string map_path;
  std::string output_path;
  std::string mode = "auto";  // vector for vector maps, else signed (DefaultAtlasMode)
  std::string range = "auto";
  AtlasOptions options;
  bool quiet = false;
};

Status Resolve(PreviewArgs& a) {
  if (a.mode != "auto") {
    auto mode = ParseAtlasMode(a.mode);
    if (!mode.ok()) {
      return Status::Error(fmt::format("--mode {}: expected auto, grey, signed or vector", a.mode));
    }
    a.options.mode = *mode;
  }
  if (a.range != "auto") {
    double value = 0;
    auto [end, ec] = std::from_chars(a.range.data(), a.range.data() + a.range.size(), value);
    if (ec != std::errc() || end != a.range.data() + a.range.size() || !(value > 0) ||
        !std::isfinite(value)) {
      return Status::Error(fmt::format(
          "--range {}: expected 'auto' or a number A > 0 (the range [-A, A])", a.range));
    }
    a.options.range = value;
  }
  if (a.output_path == a.map_path) {
    return Status::Error(fmt::format("-o {}: the output must differ from the map", a.output_path));
  }
  return ValidateAtlasOptions(a.options);
}

int RunPreview(PreviewArgs& args) {
  Status resolved = Resolve(args);
  if (!resolved.ok()) return ReportFailure(resolved, kPreviewFlags, 2);
  const Status outputs = CheckOutputs({{"-o", args.output_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  auto map = PtexFile::Open(args.map_path);
  if (!map.ok()) return ReportFailure(map.status());
  if (args.mode == "auto") args.options.mode = DefaultAtlasMode(*map);
  AtlasLayout layout;
  auto image = RenderAtlas(*map, args.options, &layout);
  if (!image.ok()) return ReportFailure(image.status(), kPreviewFlags);
  Status written = WritePng(args.output_path, *image);
  if (!written.ok()) return ReportFailure(written);
  if (!args.quiet) {
    fmt::print(stderr, "dispex: {} ({}x{}; {} faces; {} colours span [{:.4g}, {:.4g}])\n",
               args.output_path, image->width, image->height, map->num_faces(),
               AtlasModeName(args.options.mode), layout.range_min, layout.range_max);
  }
  return 0;
}

void SetupPreview(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<PreviewArgs>();
  AtlasOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "preview",
      "Draw a Ptex map as a PNG atlas: one tile per face in face-id order, values in grey, "
      "signed green/red, or a vector map's three channels as red, green, blue, with a legend of "
      "the value range");
  cmd->add_option("map", args->map_path, "Ptex map (.ptx)")->required();
  cmd->add_option("-o,--output", args->output_path, "PNG to write")->required();
  cmd->add_option("--mode", args->mode,
                  "auto (vector for vector maps, else signed), grey (black = low, white = high), "
                  "signed (green +, red -, black 0) or vector (channels --channel.. +2 as red, "
                  "green, blue; 128 grey = 0)")
      ->capture_default_str();
  cmd->add_option("--range", args->range,
                  "'auto' (signed, vector: +-max|value|, grey: [min, max]) or A for [-A, A]")
      ->capture_default_str();
  cmd->add_flag("--labels", o.labels, "write each face id on its tile");
  cmd->add_option("--tile", o.min_tile,
                  "smallest tile side in pixels (faces scaled up by an "
                  "integer factor)")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--max-tile", o.max_tile,
                  "largest tile side in pixels (bigger faces are shown reduced)")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--width", o.width, "atlas width in pixels (0: about square)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--channel", o.channel, "channel to draw (vector: the first of three)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no summary");
  cmd->callback([args, &exit_code] { exit_code = RunPreview(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(50, SetupPreview);

}  // namespace dispex::cli
