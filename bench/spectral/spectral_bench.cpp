// Benchmarks of the spectral module: the per-face analysis of a production-sized batch (17K
// faces of 64 x 64 samples, smooth displacement plus localized detail, see MakeFace) on 1 and 2 TBB
// threads, and the building blocks (DCT per size, bilinear read-back).
//
//   build-spectral/bench/spectral/spectral_bench --benchmark_min_time=2
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "dispex/spectral.h"
#include "spectral/aligned_buffer.h"
#include "spectral/analyzer_steps.h"
#include "spectral/bilinear_readback.h"
#include "spectral/dct2d.h"

namespace {

constexpr int kFaces = 17000;
constexpr int kN = 64;
constexpr double kTolerance = 1e-4;  // object units

// One face's displacement in object units, for a unit-sized object whose cage faces are ~0.02
// across and whose sculpt edges are ~1e-3 (so the default tolerance, a tenth of a sculpt
// edge, is 1e-4). Every face: a smooth field -- an offset, a gradient and waves of at most
// 0.4 cycles per face (the sculpt's large forms span several cage faces), amplitude ~2e-3.
// About half the faces add localized detail: 1-6 Gaussian bumps of 2e-4..1e-3 with sigma 3-15%
// of the face; a fifth add a crease 5e-4 deep and 3-8% of the face wide.
void MakeFace(int face, float* out) {
  std::mt19937 rng(static_cast<unsigned>(face) * 2654435761u + 12345u);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double wave[3][4];
  for (auto& w : wave) {
    w[0] = 2e-3 * (uni(rng) - 0.5);
    w[1] = 0.8 * (uni(rng) - 0.5);
    w[2] = 0.8 * (uni(rng) - 0.5);
    w[3] = 2 * std::numbers::pi * uni(rng);
  }
  const double offset = 4e-3 * (uni(rng) - 0.5);
  const double gu = 2e-3 * (uni(rng) - 0.5), gv = 2e-3 * (uni(rng) - 0.5);
  struct Bump {
    double s, t, inv2s2, h;
  };
  std::vector<Bump> bumps;
  if (uni(rng) < 0.5) {
    const int count = 1 + static_cast<int>(uni(rng) * 6);
    for (int k = 0; k < count; ++k) {
      const double sigma = 0.03 + 0.12 * uni(rng);
      bumps.push_back({uni(rng), uni(rng), 1.0 / (2 * sigma * sigma),
                       (uni(rng) < 0.5 ? -1 : 1) * (2e-4 + 8e-4 * uni(rng))});
    }
  }
  const bool crease = uni(rng) < 0.2;
  const double angle = 2 * std::numbers::pi * uni(rng);
  const double cx = std::cos(angle), cy = std::sin(angle);
  const double c = 0.3 + 0.4 * uni(rng);
  const double width = 0.03 + 0.05 * uni(rng);
  for (int j = 0; j < kN; ++j) {
    for (int i = 0; i < kN; ++i) {
      const double s = (i + 0.5) / kN, t = (j + 0.5) / kN;
      double d = offset + gu * s + gv * t;
      for (const auto& w : wave) {
        d += w[0] * std::sin(2 * std::numbers::pi * (w[1] * s + w[2] * t) + w[3]);
      }
      for (const Bump& b : bumps) {
        d += b.h * std::exp(-((s - b.s) * (s - b.s) + (t - b.t) * (t - b.t)) * b.inv2s2);
      }
      if (crease) d -= 5e-4 * std::max(0.0, 1.0 - std::fabs(cx * s + cy * t - c) / width);
      out[j * kN + i] = static_cast<float>(d);
    }
  }
}

const std::vector<float>& Faces() {
  static const std::vector<float> faces = [] {
    std::vector<float> f(static_cast<std::size_t>(kFaces) * kN * kN);
    tbb::parallel_for(0, kFaces,
                      [&](int k) { MakeFace(k, f.data() + std::size_t{1} * k * kN * kN); });
    return f;
  }();
  return faces;
}

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// The batch: analysis + resampling of every face, TBB over faces, one analyzer per thread
// (made and warmed before timing, as a pipeline would keep them), texels copied out as the
// Ptex writer would.
void BM_AnalyzeBatch(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const std::vector<float>& faces = Faces();
  tbb::task_arena arena(threads);
  tbb::enumerable_thread_specific<dispex::SpectralAnalyzer> analyzers;
  std::vector<dispex::SpectralFaceStats> stats(kFaces);
  std::vector<int> res(2 * kFaces);
  std::vector<float> out(faces.size());
  dispex::SpectralOptions options;
  options.tolerance = kTolerance;
  auto run = [&] {
    arena.execute([&] {
      tbb::parallel_for(0, kFaces, [&](int k) {
        const std::size_t at = std::size_t{1} * k * kN * kN;
        auto face = analyzers.local().Analyze(std::span<const float>(faces.data() + at, kN * kN),
                                              kN, kN, options);
        if (!face.ok()) std::abort();
        std::copy(face->texels.begin(), face->texels.end(), out.begin() + at);
        stats[k] = face->stats;
        res[2 * k] = face->ulog2;
        res[2 * k + 1] = face->vlog2;
      });
    });
  };
  run();  // warm: plans, buffers, pages
  const double cpu_before = ProcessCpuSeconds();
  for (auto _ : state) {
    run();
    benchmark::ClobberMemory();
  }
  // CPU time of every thread of the process per batch: on a machine shared with other work the
  // wall-clock time overstates the cost, this does not.
  state.counters["cpu_ms_all_threads"] =
      1e3 * (ProcessCpuSeconds() - cpu_before) / static_cast<double>(state.iterations());
  dispex::SpectralTotals totals;
  for (int k = 0; k < kFaces; ++k) totals.Add(stats[k], res[2 * k], res[2 * k + 1]);
  state.counters["faces"] = static_cast<double>(totals.faces);
  state.counters["texel_ratio"] =
      static_cast<double>(totals.texels_after) / static_cast<double>(totals.texels_before);
  state.counters["constant"] = static_cast<double>(totals.constant_faces);
  state.counters["stepped_up"] = static_cast<double>(totals.stepped_up_faces);
  state.counters["step_ups"] = static_cast<double>(totals.step_ups);
  state.counters["max_err"] = totals.max_measured_error;
  state.counters["faces_per_s"] = benchmark::Counter(static_cast<double>(kFaces),
                                                     benchmark::Counter::kIsIterationInvariantRate);
  if (threads == 1) {
    char label[160];
    const auto& h = totals.ulog2_faces;
    std::snprintf(
        label, sizeof label, "faces by final ulog2 0..6: %lld %lld %lld %lld %lld %lld %lld",
        static_cast<long long>(h[0]), static_cast<long long>(h[1]), static_cast<long long>(h[2]),
        static_cast<long long>(h[3]), static_cast<long long>(h[4]), static_cast<long long>(h[5]),
        static_cast<long long>(h[6]));
    state.SetLabel(label);
  }
}
BENCHMARK(BM_AnalyzeBatch)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same batch with the published rule (threshold 1e-4 on |F|) and with verification off,
// for comparison of speed and texel counts.
void BM_AnalyzeBatchRule(benchmark::State& state) {
  const std::vector<float>& faces = Faces();
  tbb::task_arena arena(2);
  tbb::enumerable_thread_specific<dispex::SpectralAnalyzer> analyzers;
  dispex::SpectralOptions options;
  options.tolerance = kTolerance;
  if (state.range(0) == 1) {
    options.rule = dispex::ResolutionRule::kNonzero;
    options.nonzero_threshold = kTolerance;
  }
  if (state.range(0) == 2) options.verify = false;
  std::vector<std::int64_t> texels(kFaces);
  std::vector<double> error(kFaces);
  auto run = [&] {
    arena.execute([&] {
      tbb::parallel_for(0, kFaces, [&](int k) {
        const std::size_t at = std::size_t{1} * k * kN * kN;
        auto face = analyzers.local().Analyze(std::span<const float>(faces.data() + at, kN * kN),
                                              kN, kN, options);
        if (!face.ok()) std::abort();
        texels[k] = face->stats.texels_after;
        error[k] = face->stats.measured_error;
      });
    });
  };
  run();
  for (auto _ : state) run();
  std::int64_t total = 0;
  for (auto t : texels) total += t;
  state.counters["texel_ratio"] = static_cast<double>(total) / (double(kFaces) * kN * kN);
  state.counters["max_err"] = *std::max_element(error.begin(), error.end());
  state.SetLabel(state.range(0) == 1 ? "nonzero rule, |F| > 1e-4"
                                     : "bound rule without read-back verification");
}
BENCHMARK(BM_AnalyzeBatchRule)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ForwardDct(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<float> x(std::size_t{1} * n * n), f(x.size());
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> d(-1, 1);
  for (float& v : x) v = d(rng);
  dispex::SpectralAnalyzer analyzer;
  for (auto _ : state) {
    if (!dispex::spectral::AnalyzerSteps::ForwardDct(analyzer, x, n, n, f).ok()) std::abort();
    benchmark::DoNotOptimize(f.data());
  }
}
BENCHMARK(BM_ForwardDct)->RangeMultiplier(2)->Range(4, 512);

// The raw 2-D transform by each implementation (dct2d.h): FFTW's r2r plan against Makhoul's
// paired complex FFT, which the analyzer uses from 128 samples up.
void BM_Dct2dPath(benchmark::State& state) {
  const int l = static_cast<int>(state.range(0));
  const auto path = state.range(1) == 0 ? dispex::spectral::Dct2d::Path::kR2r
                                        : dispex::spectral::Dct2d::Path::kPairedComplex;
  const std::size_t n = std::size_t{1} << (2 * l);
  dispex::spectral::AlignedFloats in, out;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> d(-1, 1);
  float* x = in.Reserve(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = d(rng);
  dispex::spectral::Dct2d dct;
  for (auto _ : state) {
    dct.Forward(l, l, x, out.Reserve(n), path);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetLabel(state.range(1) == 0 ? "r2r" : "paired complex");
}
BENCHMARK(BM_Dct2dPath)->ArgsProduct({{2, 3, 4, 5, 6, 7, 8, 9}, {0, 1}});

void BM_AnalyzeOneFace(benchmark::State& state) {
  const std::vector<float>& faces = Faces();
  dispex::SpectralAnalyzer analyzer;
  dispex::SpectralOptions options;
  options.tolerance = kTolerance;
  int k = 0;
  for (auto _ : state) {
    auto face = analyzer.Analyze(
        std::span<const float>(faces.data() + std::size_t{1} * k * kN * kN, kN * kN), kN, kN,
        options);
    benchmark::DoNotOptimize(face);
    k = (k + 1) % 1024;
  }
}
BENCHMARK(BM_AnalyzeOneFace);

void BM_MaxBilinearError(benchmark::State& state) {
  const int l = static_cast<int>(state.range(0));
  std::vector<float> samples(kN * kN, 0.5f), texels(std::size_t{1} << (2 * l), 0.25f);
  for (auto _ : state) {
    auto e = dispex::spectral::MaxBilinearError(texels, l, l, samples, kN, kN);
    benchmark::DoNotOptimize(e);
  }
}
BENCHMARK(BM_MaxBilinearError)->DenseRange(2, 6, 2);

}  // namespace

BENCHMARK_MAIN();
