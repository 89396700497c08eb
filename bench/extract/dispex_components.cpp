// The machine's limits for one asset, each stage alone: OBJ read, BVH build, limit evaluation
// of every sample extract would take, dispex's tracer kernel over exactly those queries
// (packet8 and single rays: its -n ray cut at the +n hit, the vertex guard, exact t), a bare
// rtcIntersect8 loop over the same two rays per sample with none of that (Embree alone), the
// spectral analysis of the traced samples at the automatic tolerance, and the Ptex write of the
// faces it chose. When the sculpt is the base refined, also the path through the subdivision
// correspondence: the match, the cell table with its fold marks, and the mapping kernel over
// the same samples. bench/run compares the extraction's phases, and its total with the sum of
// the parts of the path it took: read, first BVH, limit evaluation, packet8 rays, spectral,
// write through rays; read, match, cell table, limit evaluation, mapping kernel, spectral,
// write through the correspondence.
//   dispex_components BASE SCULPT [--json FILE] [--threads N] [--repeat N]
// --repeat N (default 3): each ray timing is taken N times and the fastest kept (the shared
// machine's load moves single timings by tens of percent).
#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "core/system.h"
#include "dispex/allocator.h"
#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/spectral.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/mapping/mapping_trace.h"
#include "extract/oversampling.h"
#include "trace/flush_denormals.h"

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

void MustOk(const Status& status) {
  if (!status.ok()) {
    fmt::print(stderr, "dispex_components: {}\n", status.message());
    std::exit(1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  KeepFreedMemory();  // as the command-line tool does, so that the parts compare with its runs
  if (argc < 3) {
    fmt::print(stderr,
               "usage: dispex_components BASE SCULPT [--json FILE] [--threads N] [--repeat N]\n");
    return 2;
  }
  std::string base_path = argv[1], sculpt_path = argv[2], json_path;
  int threads = 0, repeat = 3;
  for (int i = 3; i + 1 < argc; i += 2) {
    std::string a = argv[i];
    if (a == "--json") json_path = argv[i + 1];
    if (a == "--threads") threads = std::atoi(argv[i + 1]);
    if (a == "--repeat") repeat = std::max(1, std::atoi(argv[i + 1]));
  }
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  nlohmann::ordered_json out;

  Stopwatch clock;
  Mesh sculpt = Must(ReadMesh(sculpt_path));
  double read = clock.seconds();
  double mb = double(std::filesystem::file_size(sculpt_path)) / 1e6;
  out["obj_read"] = {
      {"what", "OBJ read of the sculpt"}, {"seconds", read}, {"mb_per_s", mb / read}};

  Mesh base = Must(ReadMesh(base_path));
  LimitSurface surface = Must(LimitSurface::Build(base));

  // The first build in a process pays for first touch of its memory (slow on virtual
  // machines); the second low-quality build shows the builder alone.
  const std::pair<BuildQuality, const char*> builds[] = {{BuildQuality::kLow, "bvh_low_first"},
                                                         {BuildQuality::kMedium, "bvh_medium"},
                                                         {BuildQuality::kLow, "bvh_low_again"}};
  for (const auto& [q, key] : builds) {
    TracerOptions o;
    o.quality = q;
    auto tracer = Must(MakeEmbreeTracer(sculpt, o));
    out[key] = {{"what", fmt::format("BVH build, {} quality", BuildQualityName(q))},
                {"seconds", tracer->stats().build_seconds},
                {"bytes", tracer->stats().backend_bytes}};
  }

  // The samples extract takes: per face the automatic oversampling.
  const int n = surface.num_ptex_faces();
  std::vector<double> areas(static_cast<std::size_t>(n), 1.0);
  extract::OversamplingPlan plan = extract::PlanOversampling(surface, sculpt, areas, 0, 4, 128);
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
  out["limit_evaluation"] = {
      {"what", "limit evaluation of the samples"}, {"seconds", eval}, {"samples", start[n]}};

  auto tracer = Must(MakeEmbreeTracer(sculpt));
  std::vector<Float3> sparse;
  std::vector<Float3> sparse_n;
  for (std::size_t i = 0; i < points.size(); i += 997) {
    sparse.push_back(points[i]);
    sparse_n.push_back(normals[i]);
  }
  auto estimate =
      Must(EstimateSearchDistance(*tracer, sparse, sparse_n, ComputeBounds(base).diagonal()));
  // Through the correspondence (extract --method mapping), on the same samples and distance.
  MatchOptions match_options;
  match_options.face_tables = false;  // as extract asks for it
  if (auto correspondence = MatchRefinedSculpt(surface, sculpt, match_options);
      correspondence.ok()) {
    clock.Reset();
    // Timed the second time, on warm memory, as in a run.
    correspondence = MatchRefinedSculpt(surface, sculpt, match_options);
    const double match = clock.seconds();
    const std::vector<PtexFaceInfo> table = PtexFaceTable(surface);
    clock.Reset();
    extract::SculptMapping mapping =
        Must(extract::SculptMapping::Build(std::move(*correspondence), sculpt, table));
    MustOk(mapping.MarkFolds(surface, sculpt, table));
    mapping.BuildBlocks(sculpt);
    const double cells = clock.seconds();
    out["mapping_match"] = {{"what", "the correspondence (MatchRefinedSculpt)"},
                            {"seconds", match}};
    out["mapping_table"] = {{"what", "its cell table, fold marks and blocks"}, {"seconds", cells}};
    struct Scratch {
      extract::MappingScratch mapping;
      extract::MappingCounters counters;
      std::vector<float> t;
      std::vector<std::uint8_t> flags, undecided;
    };
    const NormalQuery query{static_cast<float>(estimate.distance)};
    double seconds = 1e30;
    for (int r = 0; r < repeat; ++r) {
      tbb::enumerable_thread_specific<Scratch> scratches;
      clock.Reset();
      tbb::parallel_for(0, n, [&](int f) {
        const std::size_t b = start[f], e = start[f + 1];
        if (b == e || surface.is_hole(PtexFaceId(f))) return;
        Scratch& w = scratches.local();
        w.t.resize(e - b);
        w.flags.resize(e - b);
        w.undecided.resize(e - b);
        extract::TraceMapped(mapping, sculpt, PtexFaceId(f), 1 << plan.log2[f], {},
                             {points.data() + b, e - b}, {normals.data() + b, e - b}, query,
                             NormalHits{w.t, {}, w.flags}, w.undecided, w.mapping, w.counters);
      });
      seconds = std::min(seconds, clock.seconds());
    }
    out["mapping_kernel"] = {
        {"what",
         "the mapping kernel alone on the samples (rings and far-sheet check, no fallback BVH)"},
        {"seconds", seconds},
        {"samples", start[n]}};
  }
  std::vector<float> distances;  // packet8's, for the spectral stage
  for (RayMode mode : {RayMode::kPacket8, RayMode::kSingle}) {
    TracerOptions o;
    o.ray_mode = mode;
    auto t = Must(MakeEmbreeTracer(sculpt, o));
    std::vector<float> dist(points.size());
    std::vector<std::uint8_t> flags(points.size());
    tbb::enumerable_thread_specific<TraceCounters> counters;
    NormalQuery query{static_cast<float>(estimate.distance)};
    double seconds = 1e30;
    for (int r = 0; r < repeat; ++r) {
      counters.clear();
      clock.Reset();
      tbb::parallel_for(0, n, [&](int f) {
        std::size_t b = start[f], e = start[f + 1];
        if (b == e) return;
        t->TraceNormals({points.data() + b, e - b}, {normals.data() + b, e - b}, query,
                        NormalHits{{dist.data() + b, e - b}, {}, {flags.data() + b, e - b}},
                        counters.local());
      });
      seconds = std::min(seconds, clock.seconds());
    }
    std::uint64_t rays = 0;
    for (auto& c : counters) rays += c.rays_cast;
    out[fmt::format("rays_{}", RayModeName(mode))] = {
        {"what", fmt::format("dispex's {} kernel alone on the samples (cuts, guard, exact t)",
                             RayModeName(mode))},
        {"seconds", seconds},
        {"rays", rays},
        {"mrays_per_s", double(rays) / 1e6 / seconds}};
    if (mode == RayMode::kPacket8) distances = std::move(dist);
  }
  // Embree alone: a bare rtcIntersect8 loop over the same rays, +n over [0, d] then -n over
  // [0, the +n hit's t] (d on a miss), in 8-wide strips of each face, coherent context, the
  // same low-quality robust BVH, no guard, no exact t, no re-casts.
  {
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
    std::vector<Float3> vertices(sculpt.positions);
    vertices.reserve(vertices.size() + 1);
    std::vector<std::int32_t> quads;
    for (std::size_t f = 0; f < sculpt.num_faces(); ++f) {
      const auto face = sculpt.face(f);
      if (face.size() == 4) quads.insert(quads.end(), face.begin(), face.end());
    }
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               vertices.data(), 0, sizeof(Float3), sculpt.num_vertices());
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, quads.data(),
                               0, 4 * sizeof(std::int32_t), quads.size() / 4);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_LOW);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    const float d = static_cast<float>(estimate.distance);
    tbb::enumerable_thread_specific<std::uint64_t> cast(0);
    double seconds = 1e30;
    for (int r = 0; r < repeat; ++r) {
      cast.clear();
      clock.Reset();
      tbb::parallel_for(0, n, [&](int f) {
        trace::ScopedFlushDenormals flush;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        std::uint64_t& rays = cast.local();
        for (std::size_t b = start[f]; b < start[f + 1]; b += 8) {
          const int width = static_cast<int>(std::min<std::size_t>(8, start[f + 1] - b));
          alignas(32) int valid[8];
          RTCRayHit8 rh;
          float first[8];
          for (const float sign : {1.0f, -1.0f}) {
            for (int i = 0; i < 8; ++i) {
              const Float3& o = points[b + std::min(i, width - 1)];
              const Float3& q = normals[b + std::min(i, width - 1)];
              valid[i] = i < width ? -1 : 0;
              rh.ray.org_x[i] = o.x, rh.ray.org_y[i] = o.y, rh.ray.org_z[i] = o.z;
              rh.ray.dir_x[i] = sign * q.x, rh.ray.dir_y[i] = sign * q.y;
              rh.ray.dir_z[i] = sign * q.z;
              rh.ray.tnear[i] = 0;
              rh.ray.tfar[i] = sign > 0 ? d : first[i];
              rh.ray.time[i] = 0;
              rh.ray.mask[i] = ~0u;
              rh.ray.id[i] = 0;
              rh.ray.flags[i] = 0;
              rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
              rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, scene, &context, &rh);
            for (int i = 0; i < 8; ++i) first[i] = rh.ray.tfar[i];
            rays += static_cast<std::uint64_t>(width);
          }
        }
      });
      seconds = std::min(seconds, clock.seconds());
    }
    std::uint64_t rays = 0;
    for (const std::uint64_t c : cast) rays += c;
    out["rays_bare_rtcintersect8"] = {
        {"what", "bare rtcIntersect8 loop over the same rays (Embree alone)"},
        {"seconds", seconds},
        {"rays", rays},
        {"mrays_per_s", double(rays) / 1e6 / seconds}};
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }

  // Spectral analysis of every face's samples (misses as 0: extract fills them from their
  // neighbours first) at the automatic tolerance, 5% of the sculpt's median edge; then the
  // faces it chose written as a Ptex file with the default options, and removed.
  for (float& d : distances) {
    if (!std::isfinite(d)) d = 0;
  }
  SpectralOptions spectral;
  spectral.tolerance = 0.05 * MedianEdgeLength(sculpt);
  std::vector<std::vector<float>> texels(static_cast<std::size_t>(n));
  std::vector<PtexFaceInfo> faces = PtexFaceTable(surface);
  tbb::enumerable_thread_specific<SpectralAnalyzer> analyzers;
  clock.Reset();
  tbb::parallel_for(0, n, [&](int f) {
    const int r = 1 << plan.log2[f];
    if (start[f] == start[f + 1]) return;
    SpectralFace face = Must(analyzers.local().Analyze(
        {distances.data() + start[f], start[f + 1] - start[f]}, r, r, spectral));
    faces[f].ulog2 = static_cast<std::int8_t>(face.ulog2);
    faces[f].vlog2 = static_cast<std::int8_t>(face.vlog2);
    texels[f].assign(face.texels.begin(), face.texels.end());
  });
  const double spectral_seconds = clock.seconds();
  std::size_t written = 0;
  for (const auto& t : texels) written += t.size();
  out["spectral"] = {{"what", "spectral analysis of the traced samples, automatic tolerance"},
                     {"seconds", spectral_seconds},
                     {"samples", start[n]},
                     {"texels", written}};
  const std::string map_path =
      std::filesystem::temp_directory_path() / fmt::format("dispex_components_{}.ptx", ::getpid());
  clock.Reset();
  {
    PtexWriter writer = Must(PtexWriter::Create(map_path, PtexWriterOptions{}, n));
    tbb::parallel_for(0, n, [&](int f) {
      if (texels[f].empty()) return;
      MustOk(writer.SetFace(PtexFaceId(f), faces[f], texels[f]));
    });
    MustOk(writer.Finish());
  }
  const double write_seconds = clock.seconds();
  out["ptex_write"] = {{"what", "Ptex write of the faces the analysis chose (default options)"},
                       {"seconds", write_seconds},
                       {"bytes", std::filesystem::file_size(map_path)}};
  std::filesystem::remove(map_path);

  std::string text = out.dump(2);
  fmt::print("{}\n", text);
  if (!json_path.empty()) std::ofstream(json_path) << text << "\n";
  return 0;
}
