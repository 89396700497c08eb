// The mapping kernel alone (TraceMapped, src/extract/mapping/mapping_trace.h) against dispex's ray
// kernel on exactly the samples extract takes from a sculpt that is its base refined: each
// Ptex face's grid of 2^(L+1) samples per side (2^L on sub-faces) is evaluated, then traced
// both ways; only the tracing is timed (each thread's CPU clock, summed), and the answers are
// compared.
//   mapping_bench BASE SCULPT [--threads N] [--no-rays] [--no-far-sheets] [--search-distance D]
//                 [--repeat N]
// --no-far-sheets: without the far-sheet check (no blocks built), to measure what it costs.
// --repeat N: the loop N times, the least CPU time of each kernel kept.
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstring>
#include <optional>

#include "core/system.h"
#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/extract_inputs.h"
#include "extract/mapping/mapping_trace.h"

using namespace dispex;

namespace {

template <class T>
T Must(StatusOr<T> value) {
  if (!value.ok()) {
    fmt::print(stderr, "mapping_bench: {}\n", value.status().message());
    std::exit(1);
  }
  return std::move(value).value();
}

struct Totals {
  double cpu_mapping = 0, cpu_rays = 0;
  std::uint64_t samples = 0, undecided = 0, both = 0, differ = 0, quads = 0, far = 0;
  double max_ulps = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    fmt::print(stderr,
               "usage: mapping_bench BASE SCULPT [--threads N] [--no-rays] [--no-far-sheets] "
               "[--search-distance D] [--repeat N]\n");
    return 2;
  }
  int threads = 0, repeat = 1;
  bool rays = true, far_sheets = true;
  double distance = 0;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = std::atoi(argv[++i]);
    if (a == "--search-distance" && i + 1 < argc) distance = std::atof(argv[++i]);
    if (a == "--no-rays") rays = false;
    if (a == "--no-far-sheets") far_sheets = false;
    if (a == "--repeat" && i + 1 < argc) repeat = std::max(1, std::atoi(argv[++i]));
  }
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);

  Stopwatch clock;
  Mesh base = Must(ReadMesh(argv[1]));
  Mesh sculpt = Must(ReadMesh(argv[2]));
  const double t_read = clock.seconds();
  LimitSurface surface = Must(LimitSurface::Build(base));
  const std::vector<PtexFaceInfo> faces = PtexFaceTable(surface);
  clock.Reset();
  SculptCorrespondence correspondence = Must(MatchRefinedSculpt(surface, sculpt));
  const double t_match = clock.seconds();
  clock.Reset();
  extract::SculptMapping mapping =
      Must(extract::SculptMapping::Build(correspondence, sculpt, faces));
  const double t_table = clock.seconds();
  clock.Reset();
  if (Status s = mapping.MarkFolds(surface, sculpt, faces); !s.ok()) {
    fmt::print(stderr, "mapping_bench: {}\n", s.message());
    return 1;
  }
  const double t_folds = clock.seconds();
  clock.Reset();
  if (far_sheets) mapping.BuildBlocks(sculpt);
  const double t_blocks = clock.seconds();
  const int levels = correspondence.levels;
  correspondence = SculptCorrespondence{};
  std::unique_ptr<Tracer> tracer;
  double t_bvh = 0;
  if (rays) {
    clock.Reset();
    TracerOptions options;
    options.scale = extract::TracerScale(base);
    tracer = Must(MakeEmbreeTracer(sculpt, options));
    t_bvh = clock.seconds();
  }
  if (!(distance > 0)) distance = 0.01 * ComputeBounds(base).diagonal();
  const NormalQuery query{static_cast<float>(distance), HitPolicy::kNearest};
  const double ulp = std::ldexp(double(extract::TracerScale(base)), -23);

  struct Scratch {
    std::optional<LimitEvaluator> evaluator;
    extract::MappingScratch mapping;
    extract::MappingCounters counters;
    TraceCounters trace_counters;
    std::vector<float> positions, normals, t1, t2;
    std::vector<std::uint8_t> f1, f2, undecided;
    Totals totals;
  };
  Totals best;
  double t_loop = 0;
  for (int round = 0; round < repeat; ++round) {
    tbb::enumerable_thread_specific<Scratch> scratches;
    clock.Reset();
    tbb::parallel_for(0, surface.num_ptex_faces(), [&](int f) {
      if (surface.is_hole(PtexFaceId(f))) return;
      Scratch& w = scratches.local();
      if (!w.evaluator) w.evaluator.emplace(surface);
      const int n = 1 << (levels + (surface.sub_face(PtexFaceId(f)) ? 0 : 1));
      const std::size_t count = static_cast<std::size_t>(n) * n;
      w.positions.resize(3 * count);
      w.normals.resize(3 * count);
      w.t1.resize(count);
      w.t2.resize(count);
      w.f1.resize(count);
      w.f2.resize(count);
      w.undecided.resize(count);
      if (!w.evaluator->EvaluateGrid(PtexFaceId(f), n, n, w.positions, w.normals).ok()) return;
      const std::span<const Float3> o(reinterpret_cast<const Float3*>(w.positions.data()), count);
      const std::span<const Float3> d(reinterpret_cast<const Float3*>(w.normals.data()), count);
      ThreadCpuStopwatch step;
      extract::TraceMapped(mapping, sculpt, PtexFaceId(f), n, {}, o, d, query,
                           NormalHits{w.t1, {}, w.f1}, w.undecided, w.mapping, w.counters);
      w.totals.cpu_mapping += step.seconds();
      w.totals.samples += count;
      if (!tracer) return;
      step.Reset();
      tracer->TraceNormals(o, d, query, NormalHits{w.t2, {}, w.f2}, w.trace_counters);
      w.totals.cpu_rays += step.seconds();
      for (std::size_t k = 0; k < count; ++k) {
        if (w.undecided[k]) {
          ++w.totals.undecided;
          continue;
        }
        if (!(w.f1[k] & HitFlags::kHit) || !(w.f2[k] & HitFlags::kHit)) {
          w.totals.differ += w.f1[k] != w.f2[k];
          continue;
        }
        ++w.totals.both;
        w.totals.differ += std::memcmp(&w.t1[k], &w.t2[k], sizeof(float)) != 0;
        w.totals.max_ulps =
            std::max(w.totals.max_ulps, std::fabs(double(w.t1[k]) - double(w.t2[k])) / ulp);
      }
    });
    t_loop = clock.seconds();
    Totals all;
    for (const Scratch& w : scratches) {
      all.cpu_mapping += w.totals.cpu_mapping;
      all.cpu_rays += w.totals.cpu_rays;
      all.samples += w.totals.samples;
      all.undecided += w.counters.queries - w.counters.decided;
      all.quads += w.counters.quads;
      all.far += w.counters.far_sheets;
      all.both += w.totals.both;
      all.differ += w.totals.differ;
      all.max_ulps = std::max(all.max_ulps, w.totals.max_ulps);
    }
    if (round == 0 || all.cpu_mapping < best.cpu_mapping) {
      const double rays_cpu = round == 0 ? all.cpu_rays : std::min(best.cpu_rays, all.cpu_rays);
      best = all;
      best.cpu_rays = rays_cpu;
    } else {
      best.cpu_rays = std::min(best.cpu_rays, all.cpu_rays);
    }
  }
  const Totals& all = best;
  const double s = double(all.samples);
  fmt::print(
      "read {:.2f}s  match {:.2f}s  cell table {:.2f}s ({:.0f} MB)  folds {:.2f}s ({} faces at "
      "risk)  blocks {:.2f}s  bvh {:.2f}s  loop {:.2f}s\n",
      t_read, t_match, t_table, double(mapping.bytes()) / 1e6, t_folds, mapping.fold_risk_faces(),
      t_blocks, t_bvh, t_loop);
  fmt::print("{} samples (level {}), search distance {:.4g}\n", all.samples, levels, distance);
  fmt::print(
      "mapping: {:.2f} CPU s, {:.1f} ns/sample, {:.2f} quads/sample, {} undecided ({} by far "
      "sheets)\n",
      all.cpu_mapping, 1e9 * all.cpu_mapping / s, double(all.quads) / s, all.undecided, all.far);
  if (tracer) {
    fmt::print(
        "rays:    {:.2f} CPU s, {:.1f} ns/sample; {} both hit, {} differ, max {:.3g} ulps "
        "of the scale\n",
        all.cpu_rays, 1e9 * all.cpu_rays / s, all.both, all.differ, all.max_ulps);
  }
  return 0;
}
