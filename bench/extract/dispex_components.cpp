// The machine's limits for one asset, each stage alone: OBJ read, BVH build, limit evaluation
// of every sample extract would take, and raw Embree throughput for exactly those rays (packets
// and single rays). bench/run compares the extraction's phases with these.
//   dispex_components BASE SCULPT [--json FILE] [--threads N]
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <optional>

#include "core/system.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/oversampling.h"

using namespace dispex;

namespace {

template <class T>
T Must(StatusOr<T> value) {
  if (!value.ok()) {
    fmt::print(stderr, "dispex_components: {}\n", value.status().message());
    std::exit(1);
  }
  return std::move(value).value();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr, "usage: dispex_components BASE SCULPT [--json FILE] [--threads N]\n");
    return 2;
  }
  std::string base_path = argv[1], sculpt_path = argv[2], json_path;
  int threads = 0;
  for (int i = 3; i + 1 < argc; i += 2) {
    std::string a = argv[i];
    if (a == "--json") json_path = argv[i + 1];
    if (a == "--threads") threads = std::atoi(argv[i + 1]);
  }
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  nlohmann::ordered_json out;

  Stopwatch clock;
  Mesh sculpt = Must(ReadMesh(sculpt_path));
  double read = clock.seconds();
  double mb = double(std::filesystem::file_size(sculpt_path)) / 1e6;
  out["obj_read"] = {{"what", "OBJ read of the sculpt"}, {"seconds", read}, {"mb_per_s", mb / read}};

  Mesh base = Must(ReadMesh(base_path));
  LimitSurface surface = Must(LimitSurface::Build(base));

  // The first build in a process pays for first touch of its memory (slow on virtual
  // machines); the second low-quality build shows the builder alone.
  const std::pair<BuildQuality, const char*> builds[] = {
      {BuildQuality::kLow, "bvh_low_first"},
      {BuildQuality::kMedium, "bvh_medium"},
      {BuildQuality::kLow, "bvh_low_again"}};
  for (const auto& [q, key] : builds) {
    TracerOptions o;
    o.quality = q;
    auto tracer = Must(MakeEmbreeTracer(sculpt, o));
    out[key] = {{"what", fmt::format("BVH build, {} quality", ToString(q))},
                {"seconds", tracer->stats().build_seconds},
                {"bytes", tracer->stats().backend_bytes}};
  }

  // The samples extract takes: per face the automatic oversampling.
  const int n = surface.num_ptex_faces();
  std::vector<double> areas(static_cast<std::size_t>(n), 1.0);
  OversamplingPlan plan = PlanOversampling(surface, sculpt, areas, 0, 4, 128);
  std::vector<std::size_t> start(static_cast<std::size_t>(n) + 1, 0);
  for (int f = 0; f < n; ++f) start[f + 1] = start[f] + (std::size_t(1) << (2 * plan.log2[f]));
  std::vector<Float3> points(start[n]), normals(start[n]);
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  clock.Reset();
  tbb::parallel_for(0, n, [&](int f) {
    if (surface.is_hole(PtexFaceId(f))) return;
    auto& e = evaluators.local();
    if (!e) e.emplace(surface);
    int r = 1 << plan.log2[f];
    std::span<float> p(&points[start[f]].x, 3 * std::size_t(r) * r);
    std::span<float> q(&normals[start[f]].x, 3 * std::size_t(r) * r);
    (void)e->EvaluateGrid(PtexFaceId(f), r, r, p, q);
  });
  double eval = clock.seconds();
  out["limit_evaluation"] = {{"what", "limit evaluation of the samples"},
                             {"seconds", eval},
                             {"samples", start[n]}};

  auto tracer = Must(MakeEmbreeTracer(sculpt));
  std::vector<Float3> sparse;
  std::vector<Float3> sparse_n;
  for (std::size_t i = 0; i < points.size(); i += 997) {
    sparse.push_back(points[i]);
    sparse_n.push_back(normals[i]);
  }
  auto estimate = Must(EstimateSearchDistance(*tracer, sparse, sparse_n,
                                              ComputeBounds(base).diagonal()));
  for (RayMode mode : {RayMode::kPacket8, RayMode::kSingle}) {
    TracerOptions o;
    o.ray_mode = mode;
    auto t = Must(MakeEmbreeTracer(sculpt, o));
    std::vector<float> dist(points.size());
    std::vector<std::uint8_t> flags(points.size());
    tbb::enumerable_thread_specific<TraceCounters> counters;
    NormalQuery query{static_cast<float>(estimate.distance)};
    clock.Reset();
    tbb::parallel_for(0, n, [&](int f) {
      std::size_t b = start[f], e = start[f + 1];
      if (b == e) return;
      t->TraceNormals({points.data() + b, e - b}, {normals.data() + b, e - b}, query,
                      NormalHits{{dist.data() + b, e - b}, {}, {flags.data() + b, e - b}},
                      counters.local());
    });
    double seconds = clock.seconds();
    std::uint64_t rays = 0;
    for (auto& c : counters) rays += c.rays_cast;
    out[fmt::format("rays_{}", ToString(mode))] = {
        {"what", fmt::format("the same rays alone, {}", ToString(mode))},
        {"seconds", seconds},
        {"rays", rays},
        {"mrays_per_s", double(rays) / 1e6 / seconds}};
  }
  std::string text = out.dump(2);
  fmt::print("{}\n", text);
  if (!json_path.empty()) std::ofstream(json_path) << text << "\n";
  return 0;
}
