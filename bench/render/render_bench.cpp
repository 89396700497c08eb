// Cost of the pictures (docs/bench-notes/render.md): the atlas of a map, and the stages of a
// surface render — limit-surface tessellation at the map's densities, Embree BVH build, camera
// rays with shading — plus the whole `render --compare --sculpt` image. The map comes from a
// sculpt generated on the spot (MakeSculpt + Extract, as `dispex make-sculpt` and `dispex
// extract` do). Wall time and CPU time of the whole process (all threads), best of --repeat.
// Usage: render_bench [--cage c.obj] [--levels 4] [--pattern detail] [--amplitude 0.005]
//                     [--size 960x360] [--threads 1,2] [--repeat 3] [--ao 0]
#include <fmt/format.h>
#include <tbb/task_arena.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/verify.h"
#include "render/ray_caster.h"
#include "render/tessellation.h"

namespace dispex::bench {
namespace {

namespace fs = std::filesystem;

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Timing {
  double wall = 1e300, cpu = 1e300;
};

// Best wall and CPU time of `repeat` runs of `work`.
Timing Measure(int repeat, const std::function<void()>& work) {
  Timing best;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = CpuSeconds();
    work();
    best.cpu = std::min(best.cpu, CpuSeconds() - c0);
    best.wall = std::min(
        best.wall, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

template <class T>
T Check(StatusOr<T> value) {
  if (!value.ok()) {
    fmt::print(stderr, "render_bench: {}\n", value.status().message());
    std::exit(1);
  }
  return std::move(value).value();
}

void Row(const std::string& what, int threads, const Timing& t, const std::string& extra) {
  fmt::print("| {} | {} | {:.3f} | {:.3f} | {} |\n", what, threads, t.wall, t.cpu, extra);
}

}  // namespace
}  // namespace dispex::bench

int main(int argc, char** argv) {
  using namespace dispex;
  using namespace dispex::bench;
  std::string cage =
      std::string(DISPEX_SOURCE_DIR) + "/tests/data/meshes/keenan_spot/spot_control_mesh.obj";
  int levels = 4, repeat = 3, ao = 0;
  std::string pattern = "detail", size = "960x360";
  double amplitude = 0.005;
  std::vector<int> thread_counts = {1, 2};
  CLI::App app{"dispex render benchmark"};
  app.add_option("--cage", cage, "base cage");
  app.add_option("--levels", levels, "make-sculpt levels");
  app.add_option("--pattern", pattern, "make-sculpt pattern");
  app.add_option("--amplitude", amplitude, "make-sculpt amplitude");
  app.add_option("--size", size, "image size of the comparison (WxH)");
  app.add_option("--threads", thread_counts, "thread counts")->delimiter(',');
  app.add_option("--repeat", repeat, "runs per measurement (best kept)");
  app.add_option("--ao", ao, "ambient occlusion rays");
  CLI11_PARSE(app, argc, argv);

  const fs::path dir =
      fs::temp_directory_path() / fmt::format("dispex_render_bench_{}", ::getpid());
  fs::create_directories(dir);
  MakeSculptOptions make;
  make.cage_path = cage;
  make.output_path = (dir / "sculpt.obj").string();
  make.levels = levels;
  make.pattern = Check(ParsePattern(pattern));
  make.amplitude = amplitude;
  Check(MakeSculpt(make));
  ExtractOptions extract;
  extract.base_path = cage;
  extract.sculpt_path = make.output_path;
  extract.output_path = (dir / "map.ptx").string();
  Check(Extract(extract));

  const Mesh base = Check(ReadMesh(cage));
  const Mesh sculpt = Check(ReadMesh(make.output_path));
  const PtexFile map = Check(PtexFile::Open(extract.output_path));
  const auto dims = Check(ParseImageSize(size));
  const LimitSurface surface = Check(LimitSurface::Build(base));
  std::vector<std::array<int, 2>> density(static_cast<std::size_t>(surface.num_ptex_faces()));
  SurfaceRenderOptions options;
  options.width = dims[0];
  options.height = dims[1];
  options.ao_samples = ao;
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const PtexFaceInfo& info = map.face_info(PtexFaceId(f));
    density[static_cast<std::size_t>(f)] = {
        std::clamp(info.ures(), options.min_density, options.max_density),
        std::clamp(info.vres(), options.min_density, options.max_density)};
  }

  fmt::print(
      "cage {} ({} faces, {} Ptex faces); sculpt {} quads; map {} faces; image {}; "
      "ao {}\n\n",
      fs::path(cage).filename().string(), base.num_faces(), surface.num_ptex_faces(),
      sculpt.num_faces(), map.num_faces(), size, ao);
  fmt::print("| stage | threads | wall s | CPU s | size |\n|---|---:|---:|---:|---|\n");
  for (int threads : thread_counts) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      AtlasOptions atlas_options;
      Image atlas;
      Timing t = Measure(repeat, [&] {
        map.ReleaseSampleCache();
        atlas = Check(RenderAtlas(map, atlas_options));
      });
      Row("atlas (RenderAtlas)", threads, t, fmt::format("{}x{}", atlas.width, atlas.height));
      std::vector<std::uint8_t> png;
      t = Measure(repeat, [&] { png = Check(EncodePng(atlas)); });
      Row("atlas PNG encoding", threads, t, fmt::format("{} KB", png.size() / 1024));

      render::ShadedMesh mesh;
      t = Measure(repeat, [&] {
        map.ReleaseSampleCache();
        mesh = Check(render::TessellateLimitSurface(base, surface, density, &map, 0));
      });
      Row("tessellate + displace + normals", threads, t,
          fmt::format("{} triangles, {} vertices", mesh.mesh.num_faces(),
                      mesh.mesh.num_vertices()));
      std::unique_ptr<Tracer> tracer;
      t = Measure(repeat, [&] { tracer = Check(MakeEmbreeTracer(mesh.mesh)); });
      Row("Embree BVH build", threads, t, "");
      const Camera camera =
          Check(FrameCamera(base.positions, options.view, options.width / 3, options.height));
      render::ShadingOptions shading;
      shading.supersample = options.supersample;
      shading.ao_samples = ao;
      shading.ao_distance = 0.05f * ComputeBounds(base).diagonal();
      Image panel;
      t = Measure(repeat,
                  [&] { panel = Check(render::CastPanel(mesh, *tracer, camera, shading)); });
      const double rays =
          double(panel.width) * panel.height * shading.supersample * shading.supersample;
      Row("camera rays + shading (one panel)", threads, t,
          fmt::format("{}x{}, {:.2f} M rays/s wall, {:.2f} M rays per CPU-s", panel.width,
                      panel.height, rays / t.wall * 1e-6, rays / t.cpu * 1e-6));
      SurfaceRenderOptions whole = options;
      whole.threads = threads;
      Image image;
      t = Measure(repeat, [&] {
        map.ReleaseSampleCache();
        image = Check(RenderComparison(base, map, &sculpt, whole));
      });
      Row("whole comparison (base, base + map, sculpt)", threads, t,
          fmt::format("{}x{}", image.width, image.height));
    });
  }
  fs::remove_all(dir);
  return 0;
}
