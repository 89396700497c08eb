// The search distance: parsing the user's spec and the automatic estimate, on a sculpt whose
// distance from the base surface is known analytically.
#include <gtest/gtest.h>

#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

TEST(SearchDistanceTest, Parse) {
  auto spec = ParseSearchDistance("auto");
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->kind, SearchDistanceSpec::Kind::kAuto);
  spec = ParseSearchDistance("0.05");
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->kind, SearchDistanceSpec::Kind::kAbsolute);
  EXPECT_DOUBLE_EQ(spec->value, 0.05);
  spec = ParseSearchDistance("2.5%");
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->kind, SearchDistanceSpec::Kind::kRelative);
  EXPECT_DOUBLE_EQ(spec->value, 0.025);
  EXPECT_DOUBLE_EQ(ResolveSearchDistance(*spec, 4.0).value(), 0.1);
  EXPECT_DOUBLE_EQ(
      ResolveSearchDistance(SearchDistanceSpec{SearchDistanceSpec::Kind::kAbsolute, 0.3}, 4.0)
          .value(),
      0.3);
  EXPECT_FALSE(ResolveSearchDistance(SearchDistanceSpec{}, 4.0).ok());
  EXPECT_FALSE(ResolveSearchDistance(*spec, 0.0).ok());
  for (const char* bad : {"", "%", "abc", "1.5x", "-1", "0", "0%", "nan", "inf", " 1", "1 "}) {
    const auto parsed = ParseSearchDistance(bad);
    EXPECT_FALSE(parsed.ok()) << "'" << bad << "'";
  }
  EXPECT_EQ(ParseSearchDistance("abc").status().message(),
            "search distance 'abc' is not 'auto', a length (0.05) or a percentage of the base "
            "mesh's bounding-box diagonal (2%)");
}

// Base points on the unit sphere with radial normals; the sculpt a cube-sphere of radius R,
// so every |t| lies in [R cos(half the largest facet angle) - 1, R - 1].
struct Samples {
  std::vector<Float3> origins, normals;
};
Samples UnitSphereSamples(int count) {
  std::mt19937 rng(8);
  std::normal_distribution<double> g;
  Samples s;
  for (int k = 0; k < count; ++k) {
    Vec3 d{g(rng), g(rng), g(rng)};
    d = (1 / trace_test::Length(d)) * d;
    s.origins.push_back(trace_test::ToFloat3(d));
    s.normals.push_back(trace_test::ToFloat3(d));
  }
  return s;
}

const double kDiagonal = 2 * std::sqrt(3.0);  // the unit sphere's bounding box

TEST(SearchDistanceTest, EstimateFromAnOffsetSphere) {
  const Mesh sculpt = trace_test::CubeSphere(32, 1.1, false);
  auto tracer = MakeEmbreeTracer(sculpt);
  ASSERT_TRUE(tracer.ok());
  const Samples s = UnitSphereSamples(5000);
  auto estimate = EstimateSearchDistance(**tracer, s.origins, s.normals, kDiagonal);
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  EXPECT_EQ(estimate->samples, 5000u);
  EXPECT_EQ(estimate->hits, 5000u);
  // The facets' sagitta at n = 32 is below 0.003 of the radius.
  EXPECT_GT(estimate->median_abs_t, 0.095);
  EXPECT_LE(estimate->max_abs_t, 0.1 + 1e-6);
  EXPECT_NEAR(estimate->percentile_abs_t, 0.1, 0.004);
  EXPECT_NEAR(estimate->distance, 1.5 * estimate->percentile_abs_t, 1e-12);
  EXPECT_DOUBLE_EQ(estimate->ray_length, 0.15 * kDiagonal);
  EXPECT_FALSE(estimate->floored);
  EXPECT_FALSE(estimate->capped);
}

TEST(SearchDistanceTest, EstimateIsFlooredAndCapped) {
  const Samples s = UnitSphereSamples(2000);
  // A sculpt through the base points: |t| is tiny, the floor applies.
  {
    const Mesh sculpt = trace_test::CubeSphere(32, 1.0, false);
    auto tracer = MakeEmbreeTracer(sculpt);
    ASSERT_TRUE(tracer.ok());
    SearchDistanceOptions options;
    options.min_fraction = 0.01;
    auto estimate = EstimateSearchDistance(**tracer, s.origins, s.normals, kDiagonal, options);
    ASSERT_TRUE(estimate.ok()) << estimate.status().message();
    EXPECT_TRUE(estimate->floored);
    EXPECT_DOUBLE_EQ(estimate->distance, 0.01 * kDiagonal);
  }
  // Rays barely longer than the offset: 1.5 x 0.1 is cut to the ray length.
  {
    const Mesh sculpt = trace_test::CubeSphere(32, 1.1, false);
    auto tracer = MakeEmbreeTracer(sculpt);
    ASSERT_TRUE(tracer.ok());
    SearchDistanceOptions options;
    options.ray_fraction = 0.12 / kDiagonal;
    auto estimate = EstimateSearchDistance(**tracer, s.origins, s.normals, kDiagonal, options);
    ASSERT_TRUE(estimate.ok()) << estimate.status().message();
    EXPECT_TRUE(estimate->capped);
    EXPECT_NEAR(estimate->distance, 0.12, 1e-12);
  }
}

TEST(SearchDistanceTest, Errors) {
  const Samples s = UnitSphereSamples(100);
  Mesh far = trace_test::CubeSphere(8, 1.0, false);
  for (Float3& p : far.positions) p.x += 10;
  auto tracer = MakeEmbreeTracer(far);
  ASSERT_TRUE(tracer.ok());
  auto estimate = EstimateSearchDistance(**tracer, s.origins, s.normals, kDiagonal);
  ASSERT_FALSE(estimate.ok());
  EXPECT_EQ(
      estimate.status().message(),
      "search distance estimate: none of 100 samples of the base surface hit the sculpt "
      "within 0.519615 (15% of the base diagonal); is the sculpt aligned with the base mesh?");
  EXPECT_FALSE(EstimateSearchDistance(**tracer, {}, {}, kDiagonal).ok());
  EXPECT_FALSE(
      EstimateSearchDistance(**tracer, s.origins, std::span(s.normals).first(5), kDiagonal).ok());
  EXPECT_FALSE(EstimateSearchDistance(**tracer, s.origins, s.normals, 0.0).ok());
  SearchDistanceOptions bad;
  bad.percentile = 1.5;
  EXPECT_FALSE(EstimateSearchDistance(**tracer, s.origins, s.normals, kDiagonal, bad).ok());
}

}  // namespace
}  // namespace dispex
