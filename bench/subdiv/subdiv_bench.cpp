// Throughput of limit-surface sampling and cost of uniform refinement (docs/bench-notes/
// subdiv.md). Sampling: every Ptex face of a cage at rx x ry texel centres, positions and
// normals, TBB parallel over Ptex faces with one LimitEvaluator per thread, created fresh for
// each pass (so Bfr's per-evaluator caches start cold, as in one extraction), with the regular
// fast path and with Bfr only. Refinement: RefineUniform to a level, wall time and peak RSS.
// Usage: subdiv_bench [--mesh a.obj,b.obj] [--res 64] [--threads 1,2] [--repeat 5] [--modes
// fast,bfr]
//                     [--approx 10] [--refine-mesh m.obj --refine-levels 4,5,6]
#include <fmt/format.h>
#include <sys/resource.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"

namespace dispex::bench {
namespace {

using Clock = std::chrono::steady_clock;

// A closed torus cage of nu x nv quads: every face regular (for the fast path alone).
Mesh MakeTorusCage(int nu, int nv) {
  Mesh mesh;
  mesh.source = fmt::format("torus_{}x{}", nu, nv);
  const double kTwoPi = 6.283185307179586;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const double u = kTwoPi * i / nu, v = kTwoPi * j / nv;
      const double r = 1.0 + 0.35 * std::cos(v);
      mesh.positions.push_back({static_cast<float>(r * std::cos(u)),
                                static_cast<float>(r * std::sin(u)),
                                static_cast<float>(0.35 * std::sin(v))});
    }
  }
  mesh.face_offsets.push_back(0);
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const int i1 = (i + 1) % nu, j1 = (j + 1) % nv;
      for (int v : {j * nu + i, j * nu + i1, j1 * nu + i1, j1 * nu + i}) {
        mesh.face_indices.push_back(v);
      }
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
    }
  }
  return mesh;
}

// CPU seconds used by the whole process so far (all threads).
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: KiB
}

struct Scratch {
  explicit Scratch(const LimitSurface& s, std::size_t n) : eval(s), p(n), nrm(n) {}
  LimitEvaluator eval;
  std::vector<float> p, nrm;
};

// One pass over all Ptex faces; returns wall seconds (and CPU seconds of all threads in
// `cpu`), and the evaluator counters summed.
double SamplePass(const LimitSurface& surface, int res, int threads, LimitEvaluatorStats& sum,
                  double& cpu) {
  const std::size_t n = 3 * static_cast<std::size_t>(res) * res;
  tbb::task_arena arena(threads);
  tbb::enumerable_thread_specific<std::unique_ptr<Scratch>> scratch;
  const auto start = Clock::now();
  const double cpu_start = ProcessCpuSeconds();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, surface.num_ptex_faces()),
                      [&](const tbb::blocked_range<int>& r) {
                        auto& s = scratch.local();
                        if (!s) s = std::make_unique<Scratch>(surface, n);
                        for (int f = r.begin(); f != r.end(); ++f) {
                          if (surface.is_hole(PtexFaceId(f))) continue;
                          Status st = s->eval.EvaluateGrid(PtexFaceId(f), res, res, s->p, s->nrm);
                          if (!st.ok()) std::fprintf(stderr, "%s\n", st.message().c_str());
                        }
                      });
  });
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  cpu = ProcessCpuSeconds() - cpu_start;
  sum = {};
  for (const auto& s : scratch) {
    const LimitEvaluatorStats& st = s->eval.stats();
    sum.faces += st.faces;
    sum.regular_faces += st.regular_faces;
    sum.samples += st.samples;
    sum.fallback_normals += st.fallback_normals;
  }
  return seconds;
}

int Run(int argc, char** argv) {
  CLI::App app{"dispex limit-surface sampling benchmark"};
  std::vector<std::string> meshes;
  std::vector<int> threads_list = {1, 2};
  std::vector<int> refine_levels;
  std::string refine_mesh;
  int res = 64, repeat = 5, approx = 0;
  std::vector<std::string> modes = {"fast", "bfr"};
  app.add_option("--mesh", meshes, "cages to sample (or torus:NUxNV, all regular)")->delimiter(',');
  app.add_option("--res", res, "grid resolution per Ptex face");
  app.add_option("--threads", threads_list, "thread counts")->delimiter(',');
  app.add_option("--repeat", repeat, "passes per configuration (best is reported)");
  app.add_option("--modes", modes, "fast (regular fast path + Bfr), bfr (Bfr only)")
      ->delimiter(',');
  app.add_option("--approx", approx, "Bfr approximation level (0: dispex default)");
  app.add_option("--refine-mesh", refine_mesh, "cage for the RefineUniform measurement");
  app.add_option("--refine-levels", refine_levels, "levels for RefineUniform")->delimiter(',');
  CLI11_PARSE(app, argc, argv);

  for (const std::string& path : meshes) {
    // "torus:NUxNV" makes an all-regular torus cage instead of reading a file.
    int nu = 0, nv = 0;
    StatusOr<Mesh> mesh = (std::sscanf(path.c_str(), "torus:%dx%d", &nu, &nv) == 2)
                              ? StatusOr<Mesh>(MakeTorusCage(nu, nv))
                              : ReadMesh(path);
    if (!mesh.ok()) {
      std::fprintf(stderr, "subdiv_bench: %s\n", mesh.status().message().c_str());
      return 1;
    }
    for (const std::string& mode : modes) {
      const bool fast = mode == "fast";
      SubdivOptions options;
      options.regular_fast_path = fast;
      if (approx > 0) options.approx_level_smooth = approx;
      const auto build_start = Clock::now();
      StatusOr<LimitSurface> surface = LimitSurface::Build(*mesh, options);
      const double build_s = std::chrono::duration<double>(Clock::now() - build_start).count();
      if (!surface.ok()) {
        std::fprintf(stderr, "subdiv_bench: %s\n", surface.status().message().c_str());
        return 1;
      }
      for (int threads : threads_list) {
        double best = 1e30, best_cpu = 1e30;
        LimitEvaluatorStats stats;
        for (int r = 0; r < repeat; ++r) {
          double cpu = 0;
          best = std::min(best, SamplePass(*surface, res, threads, stats, cpu));
          best_cpu = std::min(best_cpu, cpu);
        }
        // Wall-clock rate, and the rate per CPU-second of the threads (which does not depend
        // on other processes competing for the cores).
        const double samples = static_cast<double>(stats.samples);
        std::printf(
            "%-28s %-9s threads %d  %5d Ptex faces (%5lld regular)  %dx%d  build %.3f s  "
            "pass %.4f s  %6.1f M samples/s  (%5.1f M samples per CPU-s)\n",
            mesh->source.substr(mesh->source.find_last_of('/') + 1).c_str(),
            fast ? "fast+bfr" : "bfr-only", threads, surface->num_ptex_faces(),
            static_cast<long long>(stats.regular_faces), res, res, build_s, best,
            samples / best / 1e6, samples / best_cpu / 1e6);
        std::fflush(stdout);
      }
    }
  }

  if (!refine_mesh.empty()) {
    int nu = 0, nv = 0;
    StatusOr<Mesh> mesh = (std::sscanf(refine_mesh.c_str(), "torus:%dx%d", &nu, &nv) == 2)
                              ? StatusOr<Mesh>(MakeTorusCage(nu, nv))
                              : ReadMesh(refine_mesh);
    if (!mesh.ok()) {
      std::fprintf(stderr, "subdiv_bench: %s\n", mesh.status().message().c_str());
      return 1;
    }
    StatusOr<LimitSurface> surface = LimitSurface::Build(*mesh);
    if (!surface.ok()) {
      std::fprintf(stderr, "subdiv_bench: %s\n", surface.status().message().c_str());
      return 1;
    }
    for (int level : refine_levels) {
      const auto start = Clock::now();
      StatusOr<RefinedMesh> refined = RefineUniform(*surface, level);
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      if (!refined.ok()) {
        std::fprintf(stderr, "subdiv_bench: %s\n", refined.status().message().c_str());
        return 1;
      }
      const double out_mib =
          (refined->mesh.positions.size() * sizeof(Float3) + refined->mesh.face_indices.size() * 4 +
           refined->mesh.face_offsets.size() * 4 + refined->normals.size() * 4 +
           refined->ptex_faces.size() * 4 + refined->uvs.size() * 4) /
          1048576.0;
      std::printf(
          "RefineUniform %-20s level %d: %zu vertices, %zu faces, %.2f s, output %.0f MiB, "
          "peak RSS so far %.0f MiB\n",
          refine_mesh.substr(refine_mesh.find_last_of('/') + 1).c_str(), level,
          refined->mesh.num_vertices(), refined->mesh.num_faces(), seconds, out_mib, PeakRssMiB());
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace
}  // namespace dispex::bench

int main(int argc, char** argv) {
  return dispex::bench::Run(argc, argv);
}
