// dispex render BASE [MAP.ptx] -o image.png [--compare [--sculpt SCULPT]] [--per-face] [--view V]
// [--size WxH]
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <optional>

#include "command.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kRenderFlags[] = {
    {"width x height", "--size"},     {"density", "--density"},
    {"min_density", "--min-density"}, {"max_density", "--max-density"},
    {"supersample", "--supersample"}, {"ao_samples", "--ao"},
    {"ao_distance", "--ao-distance"}, {"channel", "--channel"},
    {"threads", "--threads"},         {"azimuth", "--azimuth"},
    {"elevation", "--elevation"},     {"fov_degrees", "--fov"},
};

struct RenderArgs {
  std::vector<std::string> files;
  std::string output_path;
  std::string sculpt_path;
  std::string view = "iso";
  std::string projection = "perspective";
  std::string size = "800x600";
  bool compare = false;
  bool quiet = false;
  SurfaceRenderOptions options;
};

Status Resolve(RenderArgs& a) {
  SurfaceRenderOptions& o = a.options;
  auto view = ParseView(a.view);
  if (!view.ok()) return view.status().WithPrefix("--view");
  o.view.preset = *view;
  auto projection = ParseProjection(a.projection);
  if (!projection.ok()) return projection.status().WithPrefix("--projection");
  o.view.projection = *projection;
  auto size = ParseImageSize(a.size);
  if (!size.ok()) return size.status().WithPrefix("--size");
  o.width = (*size)[0];
  o.height = (*size)[1];
  if (a.compare && a.files.size() < 2) {
    return Status::Error("--compare needs a map: dispex render BASE MAP.ptx --compare");
  }
  if (!a.sculpt_path.empty() && !a.compare) {
    return Status::Error("--sculpt adds a panel to --compare; give both");
  }
  for (const std::string& input : a.files) {
    if (input == a.output_path) {
      return Status::Error(fmt::format("-o {}: the output must differ from the inputs", input));
    }
  }
  return ValidateSurfaceRenderOptions(o);
}

int RunRender(RenderArgs& args) {
  Status resolved = Resolve(args);
  if (!resolved.ok()) return ReportFailure(resolved, kRenderFlags, 2);
  const Status outputs = CheckOutputs({{"-o", args.output_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  const auto start = std::chrono::steady_clock::now();
  ReadOptions read;
  read.threads = args.options.threads;
  auto base = ReadMesh(args.files[0], read);
  if (!base.ok()) return ReportFailure(base.status());
  if (!args.quiet) {
    for (const std::string& w : IgnoredTagWarnings(*base)) {
      fmt::print(stderr, "dispex: warning: {}\n", w);
    }
  }
  std::optional<PtexFile> map;
  if (args.files.size() == 2) {
    auto opened = PtexFile::Open(args.files[1]);
    if (!opened.ok()) return ReportFailure(opened.status());
    map.emplace(std::move(*opened));
  }
  std::optional<Mesh> sculpt;
  if (!args.sculpt_path.empty()) {
    auto read_sculpt = ReadMesh(args.sculpt_path, read);
    if (!read_sculpt.ok()) return ReportFailure(read_sculpt.status());
    sculpt.emplace(std::move(*read_sculpt));
  }
  StatusOr<Image> image =
      args.compare ? RenderComparison(*base, *map, sculpt ? &*sculpt : nullptr, args.options)
                   : RenderSurface(*base, map ? &*map : nullptr, args.options);
  if (!image.ok()) return ReportFailure(image.status(), kRenderFlags);
  Status written = WritePng(args.output_path, *image);
  if (!written.ok()) return ReportFailure(written);
  if (!args.quiet) {
    fmt::print(stderr, "dispex: {} ({}x{}, {} view) in {:.2f}s\n", args.output_path, image->width,
               image->height, args.view,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return 0;
}

void SetupRender(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RenderArgs>();
  SurfaceRenderOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Ray-cast the base mesh's limit surface, displaced by MAP when given (a scalar map along "
      "the normal, a vector map by its vectors), to a PNG; --compare puts base, base + map (and "
      "--sculpt) side by side");
  cmd->add_option("files", args->files, "BASE [MAP.ptx]")->required()->expected(1, 2);
  cmd->add_option("-o,--output", args->output_path, "PNG to write")->required();
  cmd->add_flag("--compare", args->compare, "panels side by side: base, base + map (needs MAP)");
  cmd->add_option("--sculpt", args->sculpt_path,
                  "with --compare: add the sculpt as a third panel (same camera)");
  cmd->add_option("--view", args->view, "front, back, left, right, top or iso (+y is up)")
      ->capture_default_str();
  cmd->add_option("--azimuth", o.view.azimuth,
                  "degrees about +y from the front (+z) towards +x; overrides --view");
  cmd->add_option("--elevation", o.view.elevation,
                  "degrees above the horizon (-90..90); overrides --view");
  cmd->add_option("--projection", args->projection, "perspective or ortho")->capture_default_str();
  cmd->add_option("--fov", o.view.fov_degrees, "vertical field of view, degrees (perspective)")
      ->capture_default_str();
  cmd->add_option("--size", args->size, "image size WxH (all panels together)")
      ->capture_default_str();
  cmd->add_option("--density", o.density, "quads per side of each face without a map")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--min-density", o.min_density,
                  "with a map: fewest quads per face side (faces use their map resolution)")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--max-density", o.max_density, "with a map: most quads per face side")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_option("--supersample", o.supersample, "s x s rays per pixel (1..4)")
      ->check(CLI::Range(1, 4))
      ->capture_default_str();
  cmd->add_option("--ao", o.ao_samples, "ambient occlusion rays per hit (0: off)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--ao-distance", o.ao_distance,
                  "ambient occlusion ray length, fraction of the bounding-box diagonal")
      ->check(Positive())
      ->capture_default_str();
  cmd->add_flag("--per-face", o.per_face_displacement,
                "displace each face by its own map value where faces meet, as a renderer "
                "reading faces on their own does (cracks and steps show), instead of the mean");
  cmd->add_option("--channel", o.channel,
                  "displace along the normal by this map channel (-1: the map says: 1 channel "
                  "is a scalar map, 3 with dispex:vector_space a vector map, P + D)")
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no summary");
  cmd->callback([args, &exit_code] { exit_code = RunRender(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(60, SetupRender);

}  // namespace dispex::cli
