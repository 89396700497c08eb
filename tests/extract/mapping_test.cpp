// Scalar extraction through the subdivision correspondence (--method mapping) against the ray
// path: the kernel sample by sample, then whole maps.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/verify.h"
#include "e2e_support.h"
#include "extract/extract_inputs.h"
#include "extract/mapping_trace.h"

namespace dispex::extract {
namespace {

using dispex::testing::DataPath;
using dispex::testing::TempDir;

struct Pair {
  Mesh base, sculpt;
  LimitSurface surface;
  std::vector<PtexFaceInfo> faces;
};

Pair MakePair(const TempDir& dir, const std::string& cage, int levels, Pattern pattern,
              double amplitude = 0) {
  const std::string sculpt_path = dir / "sculpt.obj";
  auto made = MakeSculpt(dispex::testing::SculptOptions(DataPath(cage), sculpt_path, levels,
                                                       pattern, amplitude));
  EXPECT_TRUE(made.ok()) << made.status().message();
  auto base = ReadMesh(DataPath(cage));
  auto sculpt = ReadMesh(sculpt_path);
  EXPECT_TRUE(base.ok() && sculpt.ok());
  auto surface = LimitSurface::Build(*base);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  Pair p{std::move(*base), std::move(*sculpt), std::move(*surface), {}};
  p.faces = PtexFaceTable(p.surface);
  return p;
}

struct KernelComparison {
  std::size_t samples = 0, decided = 0, both_hit = 0, same_t = 0, flag_mismatch = 0;
  std::size_t mapping_only = 0, rays_only = 0;
  double max_ulps = 0;  // |dt| in ulps of the tracer's scale
  double seconds_mapping = 0, seconds_rays = 0;
};

KernelComparison CompareKernel(const Pair& p, HitPolicy policy, float distance, int n) {
  auto correspondence = MatchRefinedSculpt(p.surface, p.sculpt);
  EXPECT_TRUE(correspondence.ok()) << correspondence.status().message();
  auto mapping = SculptMapping::Build(*correspondence, p.sculpt, p.faces);
  EXPECT_TRUE(mapping.ok()) << mapping.status().message();
  TracerOptions options;
  options.scale = TracerScale(p.base);
  auto tracer = MakeEmbreeTracer(p.sculpt, options);
  EXPECT_TRUE(tracer.ok());
  const double ulp = std::ldexp(double(options.scale), -23);
  LimitEvaluator evaluator(p.surface);
  MappingScratch scratch;
  MappingCounters counters;
  TraceCounters trace_counters;
  KernelComparison c;
  const NormalQuery query{distance, policy};
  const std::size_t count = static_cast<std::size_t>(n) * n;
  std::vector<float> pos(3 * count), nrm(3 * count), t1(count), t2(count);
  std::vector<std::uint8_t> f1(count), f2(count), undecided(count);
  std::vector<SculptPrimId> p1(count), p2(count);
  for (int f = 0; f < p.surface.num_ptex_faces(); ++f) {
    if (p.surface.is_hole(PtexFaceId(f))) continue;
    EXPECT_TRUE(evaluator.EvaluateGrid(PtexFaceId(f), n, n, pos, nrm).ok());
    const std::span<const Float3> o(reinterpret_cast<const Float3*>(pos.data()), count);
    const std::span<const Float3> d(reinterpret_cast<const Float3*>(nrm.data()), count);
    auto t0 = std::chrono::steady_clock::now();
    TraceMapped(*mapping, p.sculpt, PtexFaceId(f), n, {}, o, d, query, NormalHits{t1, p1, f1},
                undecided, scratch, counters);
    auto t1c = std::chrono::steady_clock::now();
    (*tracer)->TraceNormals(o, d, query, NormalHits{t2, p2, f2}, trace_counters);
    auto t2c = std::chrono::steady_clock::now();
    c.seconds_mapping += std::chrono::duration<double>(t1c - t0).count();
    c.seconds_rays += std::chrono::duration<double>(t2c - t1c).count();
    for (std::size_t k = 0; k < count; ++k) {
      ++c.samples;
      if (undecided[k]) {
        if (getenv("DEBUG_UNDECIDED")) std::printf("undecided face %d (%zu, %zu) n %d\n", f, k % n, k / n, n);
        continue;
      }
      ++c.decided;
      const bool h1 = f1[k] & HitFlags::kHit, h2 = f2[k] & HitFlags::kHit;
      if (h1 && h2) {
        ++c.both_hit;
        c.same_t += std::memcmp(&t1[k], &t2[k], sizeof(float)) == 0;
        c.max_ulps = std::max(c.max_ulps, std::fabs(double(t1[k]) - double(t2[k])) / ulp);
        c.flag_mismatch += f1[k] != f2[k];
        if (getenv("DEBUG_DIFF") && (f1[k] != f2[k] || t1[k] != t2[k]) && c.flag_mismatch < 20)
          std::printf("face %d k %zu: mapping %.9g %d rays %.9g %d  prims %d (%d:%d) %d (%d:%d)\n", f, k, t1[k], f1[k], t2[k], f2[k],
            p1[k].value, correspondence->face_ptex[p1[k].value].value, correspondence->face_cell[p1[k].value],
            p2[k].value, correspondence->face_ptex[p2[k].value].value, correspondence->face_cell[p2[k].value]);
      } else {
        c.mapping_only += h1;
        c.rays_only += h2;
      }
    }
  }
  return c;
}

TEST(MappingKernel, Explore) {
  struct Case {
    const char* cage;
    int levels;
    Pattern pattern;
  };
  for (const Case& k : {Case{"meshes/opensubdiv/catmark_cube.obj", 3, Pattern::kDetail},
                        Case{"meshes/opensubdiv/catmark_nonquads.obj", 3, Pattern::kDetail},
                        Case{"meshes/opensubdiv/catmark_edgecorner.obj", 3, Pattern::kRidges},
                        Case{"meshes/opensubdiv/catmark_hole_test1.obj", 2, Pattern::kDetail},
                        Case{"meshes/opensubdiv/catmark_pole8.obj", 4, Pattern::kDetail},
                        Case{"meshes/keenan_spot/spot_quadrangulated.obj", 3, Pattern::kDetail}}) {
    TempDir dir;
    const Pair p = MakePair(dir, k.cage, k.levels, k.pattern);
    const KernelComparison c = CompareKernel(p, HitPolicy::kNearest,
                                             0.05f * float(ComputeBounds(p.base).diagonal()),
                                             1 << (k.levels + 1));
    std::printf("%s L%d: samples %zu decided %zu both %zu same %zu flags %zu mapping-only %zu "
                "rays-only %zu max %.3g ulps  mapping %.3f s rays %.3f s\n",
                k.cage, k.levels, c.samples, c.decided, c.both_hit, c.same_t, c.flag_mismatch,
                c.mapping_only, c.rays_only, c.max_ulps, c.seconds_mapping, c.seconds_rays);
  }
}

}  // namespace
}  // namespace dispex::extract
