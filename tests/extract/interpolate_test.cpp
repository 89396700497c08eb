// The default method on sculpts that are the base refined (ExtractMethod::kInterpolate): the
// sculpt's vertex displacements interpolated through the correspondence, against exact truth
// (make-sculpt's patterns, evaluated at the limit points here) and against the method that
// follows the sculpt's flat quads, which each check must reject:
//  - a sculpt whose vertices lie on the limit surface (true D = 0) gives maps of |D| within
//    float rounding; the facets' map is off by their sag;
//  - read at the sculpt's vertices, where the sculpt meets the truth, a full-resolution map
//    gives their displacement: the texels are corrected for the blend of the samples around
//    each vertex (vertex_displacements.h), so steep detail, whose flat quads sag by several
//    tolerances, keeps verify's RMS and p99 bounds by a factor of 2; the facets' map, whose
//    blend at a vertex is off by the sag, breaks the RMS bound;
//  - vector maps of a sculpt displaced across the normal come within 1.25x at the 99th
//    percentile of the sculpt's vertices' exact D interpolated bilinearly; the facets' map
//    does not;
//  - on cages with sharp creases every record of the scalar map stays within half its bound
//    (no value from another sheet of the sculpt), and the map passes all of verify's truth
//    bounds, which reject it scaled by 0.8; rays from the limit surface meet the far side of
//    the crease corners (records beyond their bound).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"
#include "e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::MethodOptions;
using testing::TempDir;

std::string Cage(const char* name) {
  return DataPath(std::string("meshes/opensubdiv/") + name);
}

double Diagonal(const std::string& cage) {
  auto mesh = ReadMesh(cage);
  EXPECT_TRUE(mesh.ok());
  return mesh.ok() ? ComputeBounds(*mesh).diagonal() : 0;
}

double Percentile99(std::vector<double> v) {
  if (v.empty()) return 0;
  const std::size_t k = (v.size() * 99) / 100;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// The largest |value| (scalar) or channel vector length over every texel of `path`.
double LargestTexel(const std::string& path) {
  auto map = PtexFile::Open(path);
  EXPECT_TRUE(map.ok()) << map.status().message();
  if (!map.ok()) return 0;
  const int channels = map->header().num_channels;
  double largest = 0;
  for (int f = 0; f < map->num_faces(); ++f) {
    const PtexFaceInfo& info = map->face_info(PtexFaceId(f));
    const int nu = info.ures(), nv = info.vres();
    for (int j = 0; j < nv; ++j) {
      for (int i = 0; i < nu; ++i) {
        const float u = (i + 0.5f) / nu, v = (j + 0.5f) / nv;
        double length2 = 0;
        for (int c = 0; c < channels; ++c) {
          const double x = map->Sample(PtexFaceId(f), u, v, c);
          length2 += x * x;
        }
        largest = std::max(largest, std::sqrt(length2));
      }
    }
  }
  return largest;
}

TEST(Interpolate, SculptOnTheLimitSurfaceGivesZeroMaps) {
  for (const char* name :
       {"catmark_car.obj", "catmark_nonquads.obj", "catmark_torus_creases0.obj"}) {
    SCOPED_TRACE(name);
    TempDir dir;
    const std::string cage = Cage(name);
    const double diagonal = Diagonal(cage);
    ASSERT_TRUE(
        MakeSculpt(testing::SculptOptions(cage, dir / "zero.obj", 3, Pattern::kNone, 0)).ok());
    auto scalar =
        Extract(MethodOptions(cage, dir / "zero.obj", dir / "h.ptx", ExtractMethod::kAuto));
    ASSERT_TRUE(scalar.ok()) << scalar.status().message();
    EXPECT_EQ(scalar->method.used, ExtractMethod::kInterpolate);
    EXPECT_EQ(scalar->sampling.rays_cast, 0u);
    EXPECT_LE(LargestTexel(dir / "h.ptx"), 1e-5 * diagonal);
    for (VectorSpace space : {VectorSpace::kObject, VectorSpace::kTangent}) {
      ExtractOptions o = MethodOptions(cage, dir / "zero.obj", dir / "d.ptx", ExtractMethod::kAuto);
      o.vector = space;
      auto vector = Extract(o);
      ASSERT_TRUE(vector.ok()) << vector.status().message();
      EXPECT_EQ(vector->method.used, ExtractMethod::kInterpolate);
      EXPECT_LE(LargestTexel(dir / "d.ptx"), 1e-5 * diagonal) << VectorSpaceName(space);
    }
    // The control: the map of the flat quads holds their sag, far above rounding. (On the
    // torus the rays' automatic search distance, estimated from coarse samples nearer the
    // vertices than the texels, is shorter than the sag.)
    if (std::string(name) == "catmark_torus_creases0.obj") continue;
    auto facets =
        Extract(MethodOptions(cage, dir / "zero.obj", dir / "facets.ptx", ExtractMethod::kMapping));
    ASSERT_TRUE(facets.ok()) << facets.status().message();
    EXPECT_GT(LargestTexel(dir / "facets.ptx"), 1e-4 * diagonal);
  }
}

TEST(Interpolate, ReadAtTheVerticesTheMapGivesTheirDisplacement) {
  TempDir dir;
  const std::string cage = Cage("catmark_torus_creases0.obj");
  // Bumps a few sculpt edges wide: the flat quads sag by 0.0165, about 5 tolerances.
  auto made = MakeSculpt(testing::SculptOptions(cage, dir / "s.obj", 3, Pattern::kDetail, 0.04));
  ASSERT_TRUE(made.ok()) << made.status().message();
  ASSERT_EQ(made->folded_faces, 0u);
  double rms[2] = {0, 0}, p99[2] = {0, 0};
  for (ExtractMethod method : {ExtractMethod::kInterpolate, ExtractMethod::kMapping}) {
    ExtractOptions o = MethodOptions(cage, dir / "s.obj", dir / "m.ptx", method);
    o.resolution_rule = ResolutionRule::kFixed;  // two texels a sculpt edge: the samples
    o.fixed_ulog2 = o.fixed_vlog2 = 4;
    o.oversample = 16;
    auto report = Extract(o);
    ASSERT_TRUE(report.ok()) << report.status().message();
    ASSERT_GT(made->linear_error, 4 * report->settings.tolerance);
    const VerifyReport r =
        testing::CheckTruth(cage, dir / "m.ptx", dir / "s.obj.truth", report->settings.tolerance);
    const int k = method == ExtractMethod::kMapping;
    rms[k] = r.truth.rms / report->settings.tolerance;
    p99[k] = r.truth.p99 / report->settings.tolerance;
    if (!k) {
      EXPECT_TRUE(r.passed) << r.failure;
    }
  }
  std::printf(
      "at the vertices, RMS / p99 in tolerances: interpolated %.3f / %.3f, facets %.3f / "
      "%.3f\n",
      rms[0], p99[0], rms[1], p99[1]);
  EXPECT_LE(rms[0], 0.25);
  EXPECT_LE(p99[0], 0.75);
  EXPECT_GT(rms[1], 0.5) << "the facets' map breaks the RMS bound";
}

// |D_map - V| and |floor - V| at every texel centre of a full-resolution object-space map, V the
// pattern's exact D at the limit point, the floor V at the grid's vertices interpolated
// bilinearly over the cell.
struct FloorComparison {
  std::vector<double> map_error, floor_error;
};

FloorComparison CompareWithFloor(const std::string& cage, const std::string& map_path,
                                 const MakeSculptReport& made, Pattern pattern, int levels) {
  FloorComparison out;
  auto base = ReadMesh(cage);
  EXPECT_TRUE(base.ok());
  auto surface = LimitSurface::Build(*base);
  EXPECT_TRUE(surface.ok());
  auto map = PtexFile::Open(map_path);
  EXPECT_TRUE(map.ok());
  if (!base.ok() || !surface.ok() || !map.ok()) return out;
  LimitEvaluator eval(*surface);
  auto exact = [&](int f, float u, float v, double d[3]) {
    const float uv[2] = {u, v};
    float p[3], n[3];
    EXPECT_TRUE(eval.EvaluatePoints(PtexFaceId(f), uv, p, n).ok());
    EvaluatePatternVector(pattern, made.frame, p, n, d);
  };
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    if (surface->is_hole(PtexFaceId(f))) continue;
    const int m = surface->num_ptex_faces(surface->base_face(PtexFaceId(f))) == 1
                      ? 1 << levels
                      : 1 << (levels - 1);
    const int n = map->face_info(PtexFaceId(f)).ures();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float u = (i + 0.5f) / n, v = (j + 0.5f) / n;
        double want[3], corners[4][3];
        exact(f, u, v, want);
        const int ci = std::min(static_cast<int>(u * m), m - 1),
                  cj = std::min(static_cast<int>(v * m), m - 1);
        const double s = u * m - ci, t = v * m - cj;
        const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
        for (int c = 0; c < 4; ++c) {
          exact(f, static_cast<float>(ci + di[c]) / m, static_cast<float>(cj + dj[c]) / m,
                corners[c]);
        }
        const double w[4] = {(1 - s) * (1 - t), s * (1 - t), s * t, (1 - s) * t};
        double map_e2 = 0, floor_e2 = 0;
        for (int a = 0; a < 3; ++a) {
          const double floor = w[0] * corners[0][a] + w[1] * corners[1][a] + w[2] * corners[2][a] +
                               w[3] * corners[3][a];
          const double got = map->Sample(PtexFaceId(f), u, v, a);
          map_e2 += (got - want[a]) * (got - want[a]);
          floor_e2 += (floor - want[a]) * (floor - want[a]);
        }
        out.map_error.push_back(std::sqrt(map_e2));
        out.floor_error.push_back(std::sqrt(floor_e2));
      }
    }
  }
  return out;
}

TEST(Interpolate, VectorMapsReachTheVertexInterpolationFloor) {
  constexpr int kLevels = 3;
  // Tangential waves on a curved cage, where the flat quads' sag is of the order of the floor
  // (2.4x at the larger amplitude) or above it (8.8x at the smaller).
  const std::string cage = Cage("catmark_torus_creases0.obj");
  const Pattern pattern = Pattern::kSideways;
  for (const double amplitude : {0.0005, 0.002}) {
    SCOPED_TRACE(amplitude);
    TempDir dir;
    auto made = MakeSculpt(testing::SculptOptions(cage, dir / "sculpt.obj", kLevels, pattern,
                                                  amplitude * Diagonal(cage)));
    ASSERT_TRUE(made.ok()) << made.status().message();
    double ratio[2] = {0, 0};
    for (ExtractMethod method : {ExtractMethod::kAuto, ExtractMethod::kMapping}) {
      ExtractOptions o = MethodOptions(cage, dir / "sculpt.obj", dir / "d.ptx", method);
      o.vector = VectorSpace::kObject;
      o.oversample = 2 << kLevels;  // every sample stored as it is
      o.resolution_rule = ResolutionRule::kFixed;
      o.fixed_ulog2 = o.fixed_vlog2 = kLevels + 1;
      auto report = Extract(o);
      ASSERT_TRUE(report.ok()) << report.status().message();
      const FloorComparison c = CompareWithFloor(cage, dir / "d.ptx", *made, pattern, kLevels);
      const double floor = Percentile99(c.floor_error);
      ASSERT_GT(floor, 0);
      ratio[method == ExtractMethod::kMapping] = Percentile99(c.map_error) / floor;
    }
    EXPECT_LE(ratio[0], 1.25) << "interpolated: p99 over the floor";
    EXPECT_GT(ratio[1], 1.25) << "facets: p99 over the floor";
    std::printf("amplitude %g: p99 |D - V| over the floor: interpolated %.3f, facets %.3f\n",
                amplitude, ratio[0], ratio[1]);
  }
}

TEST(Interpolate, SharpCreaseCornersHoldNoOtherSheet) {
  for (const char* name :
       {"catmark_torus_creases0.obj", "catmark_pawn.obj", "catmark_helmet.obj"}) {
    SCOPED_TRACE(name);
    TempDir dir;
    const std::string cage = Cage(name);
    ASSERT_TRUE(
        MakeSculpt(testing::SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kDetail, 0)).ok());
    const std::string truth = dir / "sculpt.obj.truth";
    double worst[2] = {0, 0};
    for (ExtractMethod method : {ExtractMethod::kAuto, ExtractMethod::kRays}) {
      const std::string map = dir / "map.ptx";
      auto report = Extract(MethodOptions(cage, dir / "sculpt.obj", map, method));
      ASSERT_TRUE(report.ok()) << report.status().message();
      const VerifyReport checked =
          testing::CheckTruth(cage, map, truth, report->settings.tolerance);
      EXPECT_TRUE(checked.truth_local_checked);
      worst[method == ExtractMethod::kRays] = checked.truth_worst_ratio;
      if (method != ExtractMethod::kAuto) continue;
      EXPECT_TRUE(checked.passed) << checked.failure;  // every bound: per record, RMS, p99
      testing::WriteWrongMap(map, dir / "wrong.ptx", testing::WrongMap::kFourFifths);
      EXPECT_FALSE(
          testing::CheckTruth(cage, dir / "wrong.ptx", truth, report->settings.tolerance).passed);
    }
    EXPECT_LE(worst[0], 0.5) << "interpolated: the worst record over its bound";
    EXPECT_GT(worst[1], 1.0) << "rays: the worst record over its bound";
    std::printf("%s: the worst |map - h| over its bound: interpolated %.2f, rays %.2f\n", name,
                worst[0], worst[1]);
  }
}

// The same map at any thread count, scalar and vector.
TEST(Interpolate, MapsAreTheSameAtAnyThreadCount) {
  TempDir dir;
  const std::string cage = Cage("catmark_nonquads.obj");
  ASSERT_TRUE(
      MakeSculpt(testing::SculptOptions(cage, dir / "sculpt.obj", 3, Pattern::kDetail, 0)).ok());
  for (const bool vector : {false, true}) {
    std::string bytes[2];
    for (const int threads : {1, 3}) {
      ExtractOptions o =
          MethodOptions(cage, dir / "sculpt.obj", dir / "map.ptx", ExtractMethod::kAuto);
      if (vector) o.vector = VectorSpace::kTangent;
      o.threads = threads;
      ASSERT_TRUE(Extract(o).ok());
      bytes[threads == 3] = testing::Slurp(dir / "map.ptx");
    }
    EXPECT_EQ(bytes[0], bytes[1]) << (vector ? "vector" : "scalar");
  }
}

}  // namespace
}  // namespace dispex
