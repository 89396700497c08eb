// PtexMapSampler: the per-face reader and the reference bilinear filter across faces, on maps
// whose readings are known in closed form (linear functions on a grid of faces, turned and
// of mixed resolution; a worked two-face example) and on real cages with n-gons and
// extraordinary vertices (constants stay constant, equal resolutions meet without a step).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex_sampler.h"
#include "dispex/subdiv.h"

namespace dispex {
namespace {

// An n x n grid of unit quads; face (x, y) covers [x, x+1] x [y, y+1] of the plane, turned by
// `turn[f]` quarter turns (its local (u, v) frame starts at another corner).
struct Grid {
  int n = 0;
  std::vector<int> turn;
  std::vector<PtexFaceInfo> faces;
  std::vector<std::vector<float>> texels;

  int Id(int x, int y) const { return y * n + x; }
  // Plane point of local (u, v) on face f.
  void ToPlane(int f, double u, double v, double& x, double& y) const {
    double a = u, b = v;
    for (int r = 0; r < turn[std::size_t(f)]; ++r) {  // one quarter turn: (u, v) -> (1 - v, u)
      const double t = a;
      a = 1 - b;
      b = t;
    }
    x = f % n + a;
    y = f / n + b;
  }
};

// Edge e of an unturned face lies on plane side e; turned by r, local edge e lies on plane
// side (e + r) % 4.
Grid MakeGrid(int n, const std::vector<int>& turn, const std::vector<std::array<int, 2>>& log2s,
              double (*field)(double, double)) {
  Grid g;
  g.n = n;
  g.turn = turn;
  g.faces.resize(std::size_t(n * n));
  g.texels.resize(g.faces.size());
  const int dx[4] = {0, 1, 0, -1}, dy[4] = {-1, 0, 1, 0};
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int f = g.Id(x, y);
      PtexFaceInfo& info = g.faces[std::size_t(f)];
      info.ulog2 = std::int8_t(log2s[std::size_t(f)][0]);
      info.vlog2 = std::int8_t(log2s[std::size_t(f)][1]);
      for (int e = 0; e < 4; ++e) {
        const int side = (e + turn[std::size_t(f)]) % 4;
        const int ax = x + dx[side], ay = y + dy[side];
        if (ax < 0 || ay < 0 || ax >= n || ay >= n) continue;
        const int a = g.Id(ax, ay);
        info.adjfaces[std::size_t(e)] = a;
        const int aside = (side + 2) % 4;
        info.adjedges[std::size_t(e)] = std::uint8_t((aside - turn[std::size_t(a)] + 4) % 4);
      }
      auto& t = g.texels[std::size_t(f)];
      t.resize(info.num_texels());
      for (int j = 0; j < info.vres(); ++j) {
        for (int i = 0; i < info.ures(); ++i) {
          double px = 0, py = 0;
          g.ToPlane(f, (i + 0.5) / info.ures(), (j + 0.5) / info.vres(), px, py);
          t[std::size_t(j * info.ures() + i)] = float(field(px, py));
        }
      }
    }
  }
  return g;
}

double Linear(double x, double y) {
  return 0.25 * x - 0.5 * y + 2;
}

// Inside the grid (every face the kernel reaches exists and every vertex is regular) the
// filter reproduces a linear function exactly, at any point of the centre faces, their edges
// and corners, whichever way the faces are turned. A wrong rotation, offset or corner face
// reads the wrong texels and misses by a texel's worth of slope.
TEST(PtexMapSampler, CrossFaceFilterIsExactForLinearDataOnATurnedGrid) {
  std::mt19937 rng(7);
  std::vector<int> turn(16);
  for (int& r : turn) r = int(rng() % 4);
  const std::vector<std::array<int, 2>> res(16, {3, 3});
  const Grid g = MakeGrid(4, turn, res, Linear);
  const PtexMapSampler sampler(g.faces, g.texels);
  for (int f : {g.Id(1, 1), g.Id(2, 1), g.Id(1, 2), g.Id(2, 2)}) {
    for (double u : {0.0, 0.03, 0.0625, 0.3, 0.5, 0.97, 1.0}) {
      for (double v : {0.0, 0.01, 0.5, 0.9375, 1.0}) {
        double x = 0, y = 0;
        g.ToPlane(f, u, v, x, y);
        EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(f), u, v), Linear(x, y), 1e-6)
            << "face " << f << " turn " << turn[std::size_t(f)] << " at " << u << ", " << v;
      }
    }
  }
}

// The per-face reader clamps to the outermost texel centres: half a texel short of the edge
// it reads the value there, not the linear function's.
TEST(PtexMapSampler, PerFaceReaderClampsHalfATexelFromTheEdge) {
  const Grid g = MakeGrid(2, {0, 0, 0, 0}, {{2, 2}, {2, 2}, {2, 2}, {2, 2}}, Linear);
  const PtexMapSampler sampler(g.faces, g.texels);
  EXPECT_NEAR(sampler.SampleFace(PtexFaceId(0), 0.5, 0.5), Linear(0.5, 0.5), 1e-6);
  EXPECT_NEAR(sampler.SampleFace(PtexFaceId(0), 1.0, 0.5), Linear(0.875, 0.5), 1e-6);
  EXPECT_NEAR(sampler.SampleFace(PtexFaceId(0), 0.9, 0.5), Linear(0.875, 0.5), 1e-6);
  EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(0), 1.0, 0.5), Linear(1.0, 0.5), 1e-6);
}

// Worked by hand from the reference filter's rules: face A (4 x 1: 0, 1, 2, 3) left of face
// B (1 x 1: 10). At A's right edge the kernel takes A's last texel and, merged down to B's
// resolution, B's texel: (3 + 10) / 2. At B's left edge B's kernel reads A box-reduced to
// B's resolution, (0 + 1 + 2 + 3) / 4: (10 + 1.5) / 2. The step between them is what a
// coarse neighbour does not hold.
TEST(PtexMapSampler, CoarserNeighbourIsReadAtTheCoarserResolution) {
  std::vector<PtexFaceInfo> faces(2);
  faces[0].ulog2 = 2;
  faces[0].adjfaces = {-1, 1, -1, -1};
  faces[0].adjedges = {0, 3, 0, 0};
  faces[1].adjfaces = {-1, -1, -1, 0};
  faces[1].adjedges = {0, 0, 0, 1};
  const std::vector<std::vector<float>> texels = {{0, 1, 2, 3}, {10}};
  const PtexMapSampler sampler(faces, texels);
  EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(0), 1.0, 0.5), 6.5, 1e-12);
  EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(1), 0.0, 0.5), 5.75, 1e-12);
  EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(0), 0.5, 0.5), 1.5, 1e-12);
  EXPECT_NEAR(sampler.SampleFace(PtexFaceId(0), 1.0, 0.5), 3, 1e-12);
}

// Mixed resolutions on the turned grid: readings stay within the data's range and each
// point's reading is a weighted mean (a constant map reads as the constant).
TEST(PtexMapSampler, MixedResolutionsKeepConstantsConstant) {
  std::mt19937 rng(3);
  std::vector<int> turn(25);
  std::vector<std::array<int, 2>> res(25);
  for (int f = 0; f < 25; ++f) {
    turn[std::size_t(f)] = int(rng() % 4);
    res[std::size_t(f)] = {int(rng() % 5), int(rng() % 5)};
  }
  const Grid g = MakeGrid(5, turn, res, [](double, double) { return 0.75; });
  const PtexMapSampler sampler(g.faces, g.texels);
  for (int f = 0; f < 25; ++f) {
    for (double u : {0.0, 0.02, 0.5, 1.0}) {
      for (double v : {0.0, 0.4, 0.99, 1.0}) {
        EXPECT_NEAR(sampler.SampleAcrossFaces(PtexFaceId(f), u, v), 0.75, 1e-12);
      }
    }
  }
}

// A 4 x 4 grid of faces turned and at resolutions drawn from `seed`, holding sin(2x) y: steps
// that are not zero at its edges.
Grid TurnedMixedGrid(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<int> turn(16);
  std::vector<std::array<int, 2>> res(16);
  for (int f = 0; f < 16; ++f) {
    turn[std::size_t(f)] = int(rng() % 4);
    res[std::size_t(f)] = {int(rng() % 4), int(rng() % 4)};
  }
  const Grid g = MakeGrid(4, turn, res, [](double x, double y) { return std::sin(2 * x) * y; });
  return g;
}

// A vector field's step is the length of its components' steps at each point: components
// (s, 2s, 2s) of a field s step 3 times as far as s does (the largest component would read 2
// times, their sum 5), and one component reads as the scalar measure. The grid is turned and of
// mixed resolutions, so the steps are not zero.
TEST(PtexEdgeSteps, VectorStepIsTheLengthOfTheComponentsSteps) {
  const Grid g = TurnedMixedGrid(5);
  std::vector<std::vector<std::vector<float>>> components(3, g.texels);
  for (std::size_t c = 1; c < 3; ++c) {
    for (auto& face : components[c]) {
      for (float& x : face) x *= 2;  // exact
    }
  }
  const std::vector<std::uint8_t> none(g.faces.size(), 0);
  const PtexEdgeSteps scalar = MeasurePtexEdgeSteps(g.faces, g.texels, none, none);
  const PtexEdgeSteps vector = MeasurePtexVectorEdgeSteps(g.faces, components, none, none);
  const PtexEdgeSteps one =
      MeasurePtexVectorEdgeSteps(g.faces, std::span(components.data(), 1), none, none);
  ASSERT_EQ(scalar.edges, 24u);
  ASSERT_EQ(vector.across_faces.size(), scalar.across_faces.size());
  ASSERT_EQ(vector.edge_max.size(), scalar.edge_max.size());
  float largest = 0;
  for (std::size_t i = 0; i < scalar.across_faces.size(); ++i) {
    largest = std::max(largest, scalar.across_faces[i]);
    EXPECT_NEAR(vector.across_faces[i], 3 * scalar.across_faces[i], 1e-6) << "point " << i;
    EXPECT_NEAR(vector.per_face[i], 3 * scalar.per_face[i], 1e-6) << "point " << i;
    EXPECT_EQ(one.across_faces[i], scalar.across_faces[i]);
    EXPECT_EQ(one.per_face[i], scalar.per_face[i]);
  }
  EXPECT_GT(largest, 0.05f) << "the case must step";
  for (std::size_t e = 0; e < scalar.edge_max.size(); ++e) {
    EXPECT_NEAR(vector.edge_max[e].across_faces, 3 * scalar.edge_max[e].across_faces, 1e-6);
    EXPECT_EQ(vector.edge_max[e].t_across_faces, scalar.edge_max[e].t_across_faces);
  }
}

// Steps known from before are taken for the edges with no changed face on either side, and
// those edges only: each taken edge reads its known values back (marked so that a measured one
// cannot pass for them), every other edge its own measurement, and PtexFacesSampled names the
// faces of the edges measured. An edge whose known steps are NaN is measured.
TEST(PtexEdgeSteps, KnownStepsAreTakenForEdgesAwayFromChangedFaces) {
  const Grid g = TurnedMixedGrid(7);
  const std::vector<std::uint8_t> none(g.faces.size(), 0);
  const PtexEdgeSteps all = MeasurePtexEdgeSteps(g.faces, g.texels, none, none);
  ASSERT_EQ(all.edges, 24u);
  std::vector<double> known = PtexEdgeStepsByFace(all.edge_max, g.faces.size());
  std::size_t stored = 0;
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (std::isnan(known[i])) continue;
    known[i] = 100.0 + double(i);  // a step no measurement of this field gives
    ++stored;
  }
  EXPECT_EQ(stored, 2 * all.edge_max.size());
  const int unknown_face = g.Id(3, 3), unknown_edge = all.edge_max.back().edge;
  ASSERT_EQ(all.edge_max.back().face, unknown_face - 1);
  known[8 * std::size_t(unknown_face - 1) + 2 * std::size_t(unknown_edge)] =
      std::numeric_limits<double>::quiet_NaN();

  std::vector<std::uint8_t> changed(g.faces.size(), 0);
  changed[std::size_t(g.Id(0, 0))] = changed[std::size_t(g.Id(1, 0))] = 1;
  PtexEdgeMeasure measure;
  measure.known = known;
  measure.changed = changed;
  const PtexEdgeSteps steps = MeasurePtexEdgeSteps(g.faces, g.texels, none, none, measure);
  const std::vector<std::uint8_t> sampled = PtexFacesSampled(g.faces, none, none, measure);
  EXPECT_EQ(steps.edges, 24u);
  ASSERT_EQ(steps.edge_max.size(), all.edge_max.size());
  std::vector<std::uint8_t> expect_sampled(g.faces.size(), 0);
  std::size_t taken = 0;
  for (std::size_t k = 0; k < steps.edge_max.size(); ++k) {
    const PtexEdgeStep& s = steps.edge_max[k];
    const PtexEdgeStep& fresh = all.edge_max[k];
    ASSERT_EQ(s.face, fresh.face);
    ASSERT_EQ(s.edge, fresh.edge);
    const bool near = changed[std::size_t(s.face)] || changed[std::size_t(s.neighbour)];
    const bool take = !near && !(s.face == unknown_face - 1 && s.edge == unknown_edge);
    if (take) {
      ++taken;
      const std::size_t at = 8 * std::size_t(s.face) + 2 * std::size_t(s.edge);
      EXPECT_EQ(s.per_face, known[at]) << "edge " << k;
      EXPECT_EQ(s.across_faces, known[at + 1]) << "edge " << k;
    } else {
      EXPECT_EQ(s.per_face, fresh.per_face) << "edge " << k;
      EXPECT_EQ(s.across_faces, fresh.across_faces) << "edge " << k;
      expect_sampled[std::size_t(s.face)] = expect_sampled[std::size_t(s.neighbour)] = 1;
    }
  }
  EXPECT_EQ(steps.known_edges, taken);
  EXPECT_EQ(taken, 24u - 4u - 1u);  // 4 edges touch the two changed faces; one is unknown
  EXPECT_EQ(sampled, expect_sampled);
}

// The cage's face table with every face at a random level (rng) or at level 3, sub-faces at 2.
std::vector<PtexFaceInfo> FacesOf(const LimitSurface& surface, std::mt19937* rng) {
  std::vector<PtexFaceInfo> faces = PtexFaceTable(surface);
  for (PtexFaceInfo& info : faces) {
    // A sub-face is a quarter of a quad to the filter: at one level less they match.
    const int level = rng ? int((*rng)() % 4) : info.subface ? 2 : 3;
    info.ulog2 = info.vlog2 = std::int8_t(level);
  }
  return faces;
}

// On real cages (n-gons, extraordinary vertices, boundaries): the filter's weights always sum
// to one (constants read back exactly at edges and corners of every face), and between two
// quads or two sub-faces of equal resolution, or a quad and the sub-faces one level below it,
// the two sides of an edge read the same value.
TEST(PtexMapSampler, RealCagesAreContinuousBetweenEqualResolutions) {
  for (const char* cage :
       {"meshes/opensubdiv/catmark_fan.obj", "meshes/keenan_spot/spot_control_mesh.obj",
        "meshes/opensubdiv/catmark_car.obj"}) {
    SCOPED_TRACE(cage);
    auto mesh = ReadMesh((std::filesystem::path(DISPEX_TEST_DATA_DIR) / cage).string());
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    auto surface = LimitSurface::Build(*mesh);
    ASSERT_TRUE(surface.ok()) << surface.status().message();
    std::mt19937 rng(11);
    const std::vector<PtexFaceInfo> mixed = FacesOf(*surface, &rng);
    std::vector<std::vector<float>> constant(mixed.size());
    for (std::size_t f = 0; f < mixed.size(); ++f) constant[f].assign(mixed[f].num_texels(), -2.5f);
    const PtexMapSampler constant_sampler(mixed, constant);

    const std::vector<PtexFaceInfo> equal = FacesOf(*surface, nullptr);
    std::vector<std::vector<float>> noise(equal.size());
    std::uniform_real_distribution<float> value(-1, 1);
    for (std::size_t f = 0; f < equal.size(); ++f) {
      noise[f].resize(equal[f].num_texels());
      for (float& x : noise[f]) x = value(rng);
    }
    const PtexMapSampler noise_sampler(equal, noise);

    int checked = 0;
    for (int f = 0; f < int(equal.size()); ++f) {
      for (int e = 0; e < 4; ++e) {
        for (double t : {0.0, 0.1, 0.5, 0.77, 1.0}) {
          double u = 0, v = 0;
          PtexEdgePoint(e, t, u, v);
          ASSERT_NEAR(constant_sampler.SampleAcrossFaces(PtexFaceId(f), u, v), -2.5, 1e-9)
              << "face " << f << " edge " << e << " t " << t;
          PtexEdgeSide other;
          if (!PtexAcrossEdge(equal, PtexFaceId(f), e, t, other)) continue;
          if (t == 0 || t == 1) continue;  // corners: valence-3 vertices drop weight unevenly
          double ou = 0, ov = 0;
          PtexEdgePoint(other.edge, other.t, ou, ov);
          ASSERT_NEAR(noise_sampler.SampleAcrossFaces(PtexFaceId(f), u, v),
                      noise_sampler.SampleAcrossFaces(other.face, ou, ov), 1e-9)
              << "face " << f << " edge " << e << " t " << t << " neighbour " << other.face.value;
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 0);
  }
}

}  // namespace
}  // namespace dispex
