// Inputs that do not belong together (ExtractOptions::check_inputs, extract/input_checks.h):
// a sculpt moved, scaled or turned against its base as a whole stops the run with one line
// naming the transform, through the correspondence (scalar and vector maps) and through rays;
// the same sculpt as made, whose displacement is its own detail, extracts; check_inputs off
// extracts the moved one. Base and sculpt swapped stop the run too.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/verify.h"
#include "e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::TempDir;

enum class Move { kNone, kTranslate, kScale, kTurn };

// `sculpt` moved as a whole about its box's centre: by 3.6% of its diagonal along x, scaled by
// 1.05, or turned 5 degrees about y.
std::string Moved(const TempDir& dir, const std::string& sculpt, Move move) {
  auto mesh = ReadMesh(sculpt);
  EXPECT_TRUE(mesh.ok());
  const BoundingBox box = ComputeBounds(*mesh);
  const double diagonal = box.diagonal();
  const double c[3] = {0.5 * (double(box.min.x) + box.max.x), 0.5 * (double(box.min.y) + box.max.y),
                       0.5 * (double(box.min.z) + box.max.z)};
  const double a = 5 * M_PI / 180;
  for (Float3& p : mesh->positions) {
    double x = p.x - c[0], y = p.y - c[1], z = p.z - c[2];
    if (move == Move::kTranslate) x += 0.036 * diagonal;
    if (move == Move::kScale) x *= 1.05, y *= 1.05, z *= 1.05;
    if (move == Move::kTurn) {
      const double tx = std::cos(a) * x + std::sin(a) * z, tz = -std::sin(a) * x + std::cos(a) * z;
      x = tx, z = tz;
    }
    p = {float(x + c[0]), float(y + c[1]), float(z + c[2])};
  }
  const std::string path = dir / "moved.obj";
  EXPECT_TRUE(WriteObj(path, *mesh).ok());
  return path;
}

StatusOr<ExtractReport> ExtractWith(const std::string& base, const std::string& sculpt,
                                    const TempDir& dir, bool vector = false, bool check = true) {
  ExtractOptions o;
  o.base_path = base;
  o.sculpt_path = sculpt;
  o.output_path = dir / "map.ptx";
  if (vector) o.vector = VectorSpace::kTangent;
  o.check_inputs = check;
  return Extract(o);
}

class InputChecks : public ::testing::TestWithParam<bool> {};  // jittered: through rays

TEST_P(InputChecks, ASculptMovedAsAWholeIsRefusedAndItsOwnDetailIsNot) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  const bool jittered = GetParam();
  MakeSculptOptions make =
      jittered ? testing::JitteredSculptOptions(cage, dir / "s.obj", 12, Pattern::kDetail, 0)
               : testing::SculptOptions(cage, dir / "s.obj", 3, Pattern::kDetail, 0);
  ASSERT_TRUE(MakeSculpt(make).ok());
  auto made = ExtractWith(cage, dir / "s.obj", dir);
  ASSERT_TRUE(made.ok()) << made.status().message();
  EXPECT_EQ(made->method.used, jittered ? ExtractMethod::kRays : ExtractMethod::kInterpolate);
  testing::fs::remove(dir / "map.ptx");
  struct Case {
    Move move;
    const char* says;
  };
  // Through rays the fit sees only the normal part: a translation of 3.6%, not the smaller
  // scale and turn (extract/input_checks.h has the measured fractions).
  const Case cases[] = {
      {Move::kTranslate, "(3."}, {Move::kScale, "a scale by 1.05"}, {Move::kTurn, "a turn by 5"}};
  for (const Case& c : cases) {
    if (jittered && c.move != Move::kTranslate) continue;
    SCOPED_TRACE(c.says);
    const std::string moved = Moved(dir, dir / "s.obj", c.move);
    auto refused = ExtractWith(cage, moved, dir);
    ASSERT_FALSE(refused.ok());
    const std::string& message = refused.status().message();
    EXPECT_NE(message.find("moved.obj: the sculpt looks moved against its base"), std::string::npos)
        << message;
    EXPECT_NE(message.find(c.says), std::string::npos) << message;
    EXPECT_NE(message.find("check_inputs off"), std::string::npos) << message;
    EXPECT_FALSE(testing::fs::exists(dir / "map.ptx"));
    if (!jittered) {
      auto vector = ExtractWith(cage, moved, dir, /*vector=*/true);
      EXPECT_FALSE(vector.ok()) << "vector maps check it too";
    }
    auto meant = ExtractWith(cage, moved, dir, /*vector=*/false, /*check=*/false);
    EXPECT_TRUE(meant.ok()) << meant.status().message();
    testing::fs::remove(dir / "map.ptx");
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, InputChecks, ::testing::Values(false, true),
                         [](const auto& param) { return param.param ? "jittered" : "refined"; });

TEST(InputChecks, BaseAndSculptSwappedAreRefused) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  ASSERT_TRUE(MakeSculpt(testing::SculptOptions(cage, dir / "s.obj", 2, Pattern::kDetail, 0)).ok());
  auto swapped = ExtractWith(dir / "s.obj", cage, dir);
  ASSERT_FALSE(swapped.ok());
  EXPECT_NE(swapped.status().message().find("fewer than the base"), std::string::npos)
      << swapped.status().message();
  EXPECT_FALSE(testing::fs::exists(dir / "map.ptx"));
}

// verify with no bound given judges the sculpt's points' distances by the map's own tolerance:
// a map against another asset's sculpt fails (hundreds of tolerances), against its own passes
// (0.14), and the report says when the sculpt is not the one the map was made from.
TEST(InputChecks, VerifyJudgesByTheMapsToleranceAndNamesAnotherSculpt) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  ASSERT_TRUE(MakeSculpt(testing::SculptOptions(cage, dir / "s.obj", 3, Pattern::kDetail, 0)).ok());
  ASSERT_TRUE(ExtractWith(cage, dir / "s.obj", dir).ok());
  VerifyOptions v;
  v.base_path = cage;
  v.map_path = dir / "map.ptx";
  v.sculpt_path = dir / "s.obj";
  auto own = Verify(v);
  ASSERT_TRUE(own.ok()) << own.status().message();
  EXPECT_TRUE(own->passed) << own->failure;
  EXPECT_GT(own->distance_tolerance, 0);
  EXPECT_LT(own->sculpt_to_map.mean, 0.5 * own->distance_tolerance);
  EXPECT_TRUE(own->warnings.empty());
  v.sculpt_path = DataPath("meshes/stanford_bunny/bun_zipper.ply");
  auto other = Verify(v);
  ASSERT_TRUE(other.ok()) << other.status().message();
  EXPECT_FALSE(other->passed);
  EXPECT_NE(other->failure.find("is this the sculpt the map was made from?"), std::string::npos)
      << other->failure;
  ASSERT_EQ(other->warnings.size(), 1u);
  EXPECT_NE(other->warnings[0].find("not the sculpt"), std::string::npos);
  v.max_mean_tolerances = 0;  // off: no bound, passed
  auto unbounded = Verify(v);
  ASSERT_TRUE(unbounded.ok());
  EXPECT_TRUE(unbounded->passed);
  // A truth file of another sculpt of the same cage (another vertex count) is named as such.
  ASSERT_TRUE(
      MakeSculpt(testing::JitteredSculptOptions(cage, dir / "j.obj", 12, Pattern::kDetail, 0))
          .ok());
  VerifyOptions t;
  t.base_path = cage;
  t.map_path = dir / "map.ptx";
  t.truth_path = dir / "j.obj.truth";
  auto wrong_truth = Verify(t);
  ASSERT_FALSE(wrong_truth.ok());
  EXPECT_NE(wrong_truth.status().message().find("the truth of another sculpt"), std::string::npos)
      << wrong_truth.status().message();
  t.truth_path = dir / "s.obj.truth";
  auto own_truth = Verify(t);
  ASSERT_TRUE(own_truth.ok()) << own_truth.status().message();
  EXPECT_TRUE(own_truth->passed) << own_truth->failure;
}

}  // namespace
}  // namespace dispex
