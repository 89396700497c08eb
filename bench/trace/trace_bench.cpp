// Throughput of dispex::Tracer on a generated sculpt (a displaced torus, 16.8M quads by
// default) with rays from the undisplaced analytic torus at 64 x 64 samples per base face,
// the way the extraction casts them: TBB parallel over base faces, one batch per face.
// Reports, per build quality and ray mode: BVH build time (the first build in the process
// and later ones), Embree's memory and the process's, and Mrays/s and Mqueries/s, both by
// wall clock and per CPU-second times the thread count (what the threads would do on cores
// of their own: the reference machine is shared, so the wall clock depends on its load).
// Usage: trace_bench [--nu 8192 --nv 2048 --threads 2 --quality low,medium --mode ...]
#include <fmt/format.h>
#include <sys/resource.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "dispex/trace.h"
#include "displaced_torus.h"

namespace dispex::bench {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

double RssMiB() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * 4096.0 / (1 << 20);
}
double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}
// User + system CPU seconds of the whole process so far.
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}
double LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = 0;
  in >> load;
  return load;
}

struct Pass {
  double seconds = 0;      // wall clock
  double cpu_seconds = 0;  // CPU time of the process (all threads) during the pass
  TraceCounters counters;
};

// One extraction-like pass: every base face's samples as one batch.
Pass TraceAll(const Tracer& tracer, const BaseSamples& base, const NormalQuery& query,
              std::vector<float>& t, std::vector<SculptPrimId>& prim,
              std::vector<std::uint8_t>& flags) {
  tbb::enumerable_thread_specific<TraceCounters> counters;
  const double cpu_start = CpuSeconds();
  const auto start = Clock::now();
  tbb::parallel_for(0, base.faces, [&](int face) {
    const std::size_t b = static_cast<std::size_t>(face) * static_cast<std::size_t>(base.per_face);
    const std::size_t n = static_cast<std::size_t>(base.per_face);
    tracer.TraceNormals(std::span(base.points).subspan(b, n), std::span(base.normals).subspan(b, n),
                        query,
                        NormalHits{std::span(t).subspan(b, n), std::span(prim).subspan(b, n),
                                   std::span(flags).subspan(b, n)},
                        counters.local());
  });
  Pass pass;
  pass.seconds = Since(start);
  pass.cpu_seconds = CpuSeconds() - cpu_start;
  for (const TraceCounters& c : counters) pass.counters += c;
  return pass;
}

int Main(int argc, char** argv) {
  CLI::App app{"dispex trace throughput benchmark"};
  int nu = 8192, nv = 2048, base_u = 64, base_v = 16, res = 64, threads = 2, repeat = 3;
  std::vector<std::string> qualities{"low", "medium"};
  std::vector<std::string> modes{"single", "packet4", "packet8", "packet16", "stream"};
  std::string policy_name = "nearest";
  double distance = 0;
  bool no_retry = false, no_robust = false, compact = false, verify = false;
  app.add_option("--nu", nu, "sculpt quads around the ring");
  app.add_option("--nv", nv, "sculpt quads around the tube");
  app.add_option("--base-u", base_u, "base faces around the ring");
  app.add_option("--base-v", base_v, "base faces around the tube");
  app.add_option("--res", res, "samples per base face side");
  app.add_option("--threads", threads, "TBB threads");
  app.add_option("--repeat", repeat, "passes per configuration (median reported)");
  app.add_option("--quality", qualities, "build qualities")->delimiter(',');
  app.add_option("--mode", modes, "ray modes")->delimiter(',');
  app.add_option("--policy", policy_name, "hit policy");
  app.add_option("--distance", distance, "search distance (default: automatic estimate)");
  app.add_flag("--no-retry", no_retry, "do not re-cast missed rays");
  app.add_flag("--no-robust", no_robust, "Embree's fast, non-watertight mode");
  app.add_flag("--verify-hits", verify, "TracerOptions::verify_hits");
  app.add_flag("--compact", compact, "RTC_SCENE_FLAG_COMPACT");
  CLI11_PARSE(app, argc, argv);
  auto policy = ParseHitPolicy(policy_name);
  if (!policy.ok()) {
    std::fprintf(stderr, "trace_bench: %s\n", policy.status().message().c_str());
    return 2;
  }

  tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism,
                                  static_cast<std::size_t>(threads));
  const TorusShape shape;
  auto start = Clock::now();
  const Mesh sculpt = MakeTorusSculpt(shape, nu, nv);
  const double generate_s = Since(start);
  const BaseSamples base = MakeTorusBaseSamples(shape, base_u, base_v, res);
  const BaseSamples sparse = MakeTorusBaseSamples(shape, base_u, base_v, 4);
  fmt::print(
      "sculpt: {} quads, {} vertices (generated in {:.2f} s); base: {} faces x {} samples "
      "= {} queries; threads {}; load average at start {:.2f}\n",
      sculpt.num_faces(), sculpt.num_vertices(), generate_s, base.faces, base.per_face,
      base.points.size(), threads, LoadAverage());
  fmt::print("process RSS after generating: {:.0f} MiB\n", RssMiB());

  std::vector<float> t(base.points.size());
  std::vector<SculptPrimId> prim(base.points.size());
  std::vector<std::uint8_t> flags(base.points.size());
  NormalQuery query{static_cast<float>(distance), *policy};
  bool first_build = true;

  fmt::print("\n{:<7} {:<9} {:>8} {:>7} {:>9} {:>7} {:>8} {:>8} {:>9} {:>9} {:>7} {:>8} {:>7}\n",
             "quality", "mode", "build_s", "cpu_s", "embreeMiB", "rssMiB", "Mrays/s", "Mqry/s",
             "Mrays/cs", "Mqry/cs", "rays/q", "hit%", "repair%");
  for (const std::string& quality_name : qualities) {
    auto quality = ParseBuildQuality(quality_name);
    if (!quality.ok()) {
      std::fprintf(stderr, "trace_bench: %s\n", quality.status().message().c_str());
      return 2;
    }
    for (const std::string& mode_name : modes) {
      auto mode = ParseRayMode(mode_name);
      if (!mode.ok()) {
        std::fprintf(stderr, "trace_bench: %s\n", mode.status().message().c_str());
        return 2;
      }
      TracerOptions options;
      options.quality = *quality;
      options.ray_mode = *mode;
      options.retry_misses = !no_retry;
      options.robust = !no_robust;
      options.compact = compact;
      options.verify_hits = verify;
      const double build_cpu_start = CpuSeconds();
      auto tracer = MakeEmbreeTracer(sculpt, options);
      const double build_cpu = CpuSeconds() - build_cpu_start;
      if (!tracer.ok()) {
        std::fprintf(stderr, "trace_bench: %s\n", tracer.status().message().c_str());
        return 1;
      }
      const TracerStats& stats = (*tracer)->stats();
      if (query.distance <= 0) {
        start = Clock::now();
        auto estimate =
            EstimateSearchDistance(**tracer, sparse.points, sparse.normals, TorusDiagonal(shape));
        if (!estimate.ok()) {
          std::fprintf(stderr, "trace_bench: %s\n", estimate.status().message().c_str());
          return 1;
        }
        query.distance = static_cast<float>(estimate->distance);
        fmt::print(
            "# backend: {}\n# search distance (auto, {:.3f} s): {:.5f} = {} x p{:.1f} "
            "|t| {:.5f} of {} / {} sparse samples (median |t| {:.5f}, max {:.5f}); "
            "the displacement amplitude is {:.5f}\n",
            stats.backend, Since(start), estimate->distance, 1.5, 100 * estimate->percentile,
            estimate->percentile_abs_t, estimate->hits, estimate->samples, estimate->median_abs_t,
            estimate->max_abs_t, shape.amplitude);
      }
      std::vector<Pass> passes;
      for (int r = 0; r < repeat; ++r) {
        passes.push_back(TraceAll(**tracer, base, query, t, prim, flags));
      }
      // Median pass by wall clock, and the median of the CPU-time rates.
      std::vector<double> cpu_rates;
      for (const Pass& p : passes) {
        cpu_rates.push_back(static_cast<double>(p.counters.rays_cast) / p.cpu_seconds * threads);
      }
      std::sort(cpu_rates.begin(), cpu_rates.end());
      std::sort(passes.begin(), passes.end(),
                [](const Pass& a, const Pass& b) { return a.seconds < b.seconds; });
      const Pass& median = passes[passes.size() / 2];
      const TraceCounters& c = median.counters;
      const double rays_per_query =
          static_cast<double>(c.rays_cast) / static_cast<double>(c.queries);
      const double cpu_rate = cpu_rates[cpu_rates.size() / 2];
      fmt::print(
          "{:<7} {:<9} {:>8.2f} {:>7} {:>9.0f} {:>7.0f} {:>8.2f} {:>8.2f} {:>9.2f} {:>9.2f} "
          "{:>7.3f} {:>8.3f} {:>7.3f}\n",
          quality_name, mode_name, stats.build_seconds,
          fmt::format("{:.2f}{}", build_cpu, first_build ? "*" : ""),
          static_cast<double>(stats.backend_bytes) / (1 << 20), RssMiB(),
          static_cast<double>(c.rays_cast) / median.seconds * 1e-6,
          static_cast<double>(c.queries) / median.seconds * 1e-6, cpu_rate * 1e-6,
          cpu_rate / rays_per_query * 1e-6, rays_per_query,
          100.0 * static_cast<double>(c.hits) / static_cast<double>(c.queries),
          100.0 * static_cast<double>(c.repair_rays) / static_cast<double>(c.rays_cast));
      std::fflush(stdout);
      first_build = false;
    }
  }
  fmt::print(
      "\nbuild_s: BVH build wall time; cpu_s: process CPU seconds of MakeEmbreeTracer "
      "(validation + build; * = first build in the process). Mrays/s, Mqry/s: wall "
      "clock; Mrays/cs, Mqry/cs: per CPU-second x threads.\n");
  fmt::print("peak RSS {:.0f} MiB; load average at end {:.2f}\n", PeakRssMiB(), LoadAverage());
  return 0;
}

}  // namespace
}  // namespace dispex::bench

int main(int argc, char** argv) {
  return dispex::bench::Main(argc, argv);
}
