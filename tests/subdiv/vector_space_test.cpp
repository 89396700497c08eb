// Vector displacement frames: the definitions of include/dispex/vector_space.h on a skewed
// frame, the round trip channels -> D -> channels, and the names.
#include "dispex/vector_space.h"

#include <gtest/gtest.h>

#include <cmath>

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
  for (VectorSpace space :
       {VectorSpace::kTangent, VectorSpace::kParametric, VectorSpace::kObject}) {
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
            "unknown vector space 'world' (expected tangent, parametric or object)");
}

// What a map holds, from its channels and meta data: each rule of DisplacementMapSpace, with
// the one-line message naming the map. Rejects a reader that takes a 3-channel map without
// dispex:vector_space for a vector map (or its channel 0 for a scalar map), that ignores
// dispex:channels or an alpha channel, or that accepts other channel counts.
TEST(VectorSpaceTest, DisplacementMapSpace) {
  const std::string tangent = "tangent", object = "object", names = "T,B,N", bad = "x,y,z";
  auto scalar = DisplacementMapSpace("m.ptx", 1, -1, nullptr, nullptr);
  ASSERT_TRUE(scalar.ok());
  EXPECT_FALSE(scalar->has_value());
  auto vector = DisplacementMapSpace("m.ptx", 3, -1, &tangent, &names);
  ASSERT_TRUE(vector.ok());
  EXPECT_EQ(**vector, VectorSpace::kTangent);
  auto unnamed = DisplacementMapSpace("m.ptx", 3, -1, &object, nullptr);  // names optional
  ASSERT_TRUE(unnamed.ok());
  EXPECT_EQ(**unnamed, VectorSpace::kObject);
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 3, -1, nullptr, nullptr).status().message(),
            "m.ptx: 3 channels but no dispex:vector_space meta data: not a vector displacement "
            "map");
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 2, -1, nullptr, nullptr).status().message(),
            "m.ptx: 2 channels: a displacement map has 1 (scalar) or 3 (vector, with "
            "dispex:vector_space)");
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 4, -1, &tangent, nullptr).status().message(),
            "m.ptx: 4 channels: a displacement map has 1 (scalar) or 3 (vector, with "
            "dispex:vector_space)");
  const std::string world = "world";
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 3, -1, &world, nullptr).status().message(),
            "m.ptx: dispex:vector_space: unknown vector space 'world' (expected tangent, "
            "parametric or object)");
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 3, -1, &tangent, &bad).status().message(),
            "m.ptx: dispex:channels 'x,y,z' does not match dispex:vector_space 'tangent' "
            "(expected 'T,B,N')");
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 3, 2, &tangent, &names).status().message(),
            "m.ptx: alpha channel 2: a vector displacement map has none");
  EXPECT_EQ(DisplacementMapSpace("m.ptx", 1, -1, &tangent, nullptr).status().message(),
            "m.ptx: 1 channel, but dispex:vector_space 'tangent' (a vector map has 3 channels)");
}

}  // namespace
}  // namespace dispex
