// How `verify --truth` reads a scalar Ptex map: as a renderer reads it, with the reference Ptex
// filter that blends over face edges. The per-face read is clamped to the outermost texel
// centre within half a texel of a face edge, so a steep displacement there is off by its slope
// times that distance: a good map failed its per-vertex bound on face edges of the bench
// assets (cape 1 record, head 20) though every record away from the borders was within it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"
#include "vector_map_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::TempDir;

// A displacement along the normal that grows linearly with x: its slope is the same
// everywhere, so the clamped read's error at a face edge is the slope times half a texel.
constexpr double kSlope = 0.2;
void Ramp(const float p[3], const float n[3], double d[3]) {
  for (int k = 0; k < 3; ++k) d[k] = kSlope * p[0] * n[k];
}

// Truth records on every face's border and inside it: (u, v) on a 9 x 9 grid of [0, 1]^2.
GroundTruth RampTruth(const LimitSurface& surface) {
  GroundTruth truth;
  LimitEvaluator evaluator(surface);
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    for (int j = 0; j <= 8; ++j) {
      for (int i = 0; i <= 8; ++i) {
        const float uv[2] = {float(i) / 8, float(j) / 8};
        float p[3], n[3];
        EXPECT_TRUE(evaluator.EvaluatePoints(PtexFaceId(f), uv, p, n).ok());
        truth.faces.push_back(PtexFaceId(f));
        truth.uvs.insert(truth.uvs.end(), {uv[0], uv[1]});
        truth.h.push_back(static_cast<float>(kSlope * p[0]));
        truth.local_error.push_back(0);  // no sculpt: the map is checked against h alone
      }
    }
  }
  return truth;
}

TEST(TruthRead, ScalarMapsAreReadAcrossFaceEdgesAsARendererReadsThem) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_cube.obj");
  auto mesh = ReadMesh(cage);
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  auto surface = LimitSurface::Build(*mesh);
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  const GroundTruth truth = RampTruth(*surface);
  ASSERT_TRUE(WriteGroundTruth(dir / "ramp.truth", truth).ok());
  testing::PatternMapOptions o;
  o.space = std::nullopt;  // a scalar map of D.N
  o.log2 = 4;
  testing::WriteVectorFieldMap(cage, Ramp, dir / "ramp.ptx", o);

  // The per-face read at every record: within a face it is the map itself; at the borders
  // it is the outermost texel centre's value, half a texel (1/32 of the face) inwards.
  auto map = PtexFile::Open(dir / "ramp.ptx");
  ASSERT_TRUE(map.ok()) << map.status().message();
  double inside = 0, border = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const float u = truth.uvs[2 * i], v = truth.uvs[2 * i + 1];
    const double error = std::abs(map->Sample(truth.faces[i], u, v) - truth.h[i]);
    const bool on_border = u == 0 || u == 1 || v == 0 || v == 1;
    (on_border ? border : inside) = std::max(on_border ? border : inside, error);
  }
  // tau between the two: the map is within it inside every face, the clamped read is not.
  const double tau = 0.5 * border;
  ASSERT_LT(1.5 * inside, tau) << "inside " << inside << ", border " << border;

  VerifyOptions verify;
  verify.base_path = cage;
  verify.map_path = dir / "ramp.ptx";
  verify.truth_path = dir / "ramp.truth";
  verify.tolerance = tau;
  auto r = Verify(verify);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->passed) << r->failure;
  EXPECT_EQ(r->truth_over_bound, 0u);
  // Read across the edges, the borders are as close as the inside (measured: the worst record
  // 4.3e-4, the inside 4.0e-4, the clamped read at the borders 8.1e-3: 0.054 of it). With the
  // per-face read this test fails (checked): every border record is over the bound.
  EXPECT_LT(r->truth.max, 0.1 * border) << "inside " << inside << ", border " << border;
}

}  // namespace
}  // namespace dispex
