// Vector displacement frames: the definitions of include/dispex/vector_space.h on a skewed
// frame, the round trip channels -> D -> channels, and the names.
#include <gtest/gtest.h>

#include <cmath>

#include "dispex/vector_space.h"

namespace dispex {
namespace {

// A sheared, stretched frame: dP/du and dP/dv neither unit nor orthogonal.
SurfaceFrame Skewed() {
  SurfaceFrame f;
  f.du = {2.0f, 0.0f, 0.5f};
  f.dv = {0.7f, 1.5f, 0.0f};
  const double cx = 0 * 0.0 - 0.5 * 1.5, cy = 0.5 * 0.7 - 2.0 * 0.0, cz = 2.0 * 1.5 - 0.0 * 0.7;
  const double len = std::sqrt(cx * cx + cy * cy + cz * cz);
  f.normal = {static_cast<float>(cx / len), static_cast<float>(cy / len),
              static_cast<float>(cz / len)};
  return f;
}

TEST(VectorSpaceTest, Definitions) {
  const SurfaceFrame f = Skewed();
  const float c[3] = {0.3f, -0.2f, 0.7f};
  // Parametric: c0 du + c1 dv + c2 n, by hand.
  const Float3 p = VectorFromChannels(VectorSpace::kParametric, f, c);
  EXPECT_NEAR(p.x, 0.3 * 2.0 - 0.2 * 0.7 + 0.7 * f.normal.x, 1e-6);
  EXPECT_NEAR(p.y, -0.2 * 1.5 + 0.7 * f.normal.y, 1e-6);
  EXPECT_NEAR(p.z, 0.3 * 0.5 + 0.7 * f.normal.z, 1e-6);
  // Tangent: T along du, unit; B = N x T; |D| = |c| since the frame is orthonormal.
  const float along_t[3] = {1, 0, 0};
  const Float3 t = VectorFromChannels(VectorSpace::kTangent, f, along_t);
  const double du_len = std::sqrt(4.0 + 0.25);
  EXPECT_NEAR(t.x, 2.0 / du_len, 1e-6);
  EXPECT_NEAR(t.z, 0.5 / du_len, 1e-6);
  const Float3 d = VectorFromChannels(VectorSpace::kTangent, f, c);
  EXPECT_NEAR(d.x * d.x + d.y * d.y + d.z * d.z, 0.09 + 0.04 + 0.49, 1e-6);
  // B is right-handed: N x T, so T x B = N.
  const float along_b[3] = {0, 1, 0};
  const Float3 b = VectorFromChannels(VectorSpace::kTangent, f, along_b);
  EXPECT_NEAR(t.y * b.z - t.z * b.y, f.normal.x, 1e-6);
  EXPECT_NEAR(t.z * b.x - t.x * b.z, f.normal.y, 1e-6);
  EXPECT_NEAR(t.x * b.y - t.y * b.x, f.normal.z, 1e-6);
  const Float3 o = VectorFromChannels(VectorSpace::kObject, f, c);
  EXPECT_EQ(o.x, 0.3f);
  EXPECT_EQ(o.z, 0.7f);
}

TEST(VectorSpaceTest, RoundTrip) {
  const SurfaceFrame f = Skewed();
  const Float3 d = {0.25f, -1.5f, 0.75f};
  for (VectorSpace space : {VectorSpace::kTangent, VectorSpace::kParametric, VectorSpace::kObject}) {
    float c[3];
    VectorToChannels(space, f, d, c);
    const Float3 back = VectorFromChannels(space, f, c);
    EXPECT_NEAR(back.x, d.x, 1e-6) << VectorSpaceName(space);
    EXPECT_NEAR(back.y, d.y, 1e-6) << VectorSpaceName(space);
    EXPECT_NEAR(back.z, d.z, 1e-6) << VectorSpaceName(space);
  }
}

TEST(VectorSpaceTest, DegenerateDerivativesStayFinite) {
  SurfaceFrame f;
  f.du = {0, 0, 0};
  f.dv = {0, 0, 0};
  f.normal = {0, 0, 1};
  const Float3 d = {0.5f, 0.25f, 1.0f};
  float c[3];
  VectorToChannels(VectorSpace::kTangent, f, d, c);
  const Float3 back = VectorFromChannels(VectorSpace::kTangent, f, c);
  EXPECT_NEAR(back.x, d.x, 1e-6);
  EXPECT_NEAR(back.y, d.y, 1e-6);
  EXPECT_NEAR(back.z, d.z, 1e-6);
  VectorToChannels(VectorSpace::kParametric, f, d, c);
  EXPECT_EQ(c[0], 0.0f);
  EXPECT_EQ(c[2], 1.0f);
}

TEST(VectorSpaceTest, Names) {
  EXPECT_EQ(VectorSpaceName(VectorSpace::kParametric), "parametric");
  EXPECT_EQ(VectorSpaceChannels(VectorSpace::kTangent), "T,B,N");
  EXPECT_EQ(ParseVectorSpace("object").value(), VectorSpace::kObject);
  EXPECT_EQ(ParseVectorSpace("world").status().message(),
            "unknown vector space 'world' (valid: tangent, parametric, object)");
}

}  // namespace
}  // namespace dispex
