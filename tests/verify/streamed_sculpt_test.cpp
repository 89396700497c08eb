// The streamed refinement (MakeSculptOptions::streamed) against MakeSculpt's refined layout,
// which OpenSubdiv refines: the same vertices to rounding and the same quads, corner for corner
// in the same turning order, only numbered differently. A streamed sculpt whose slots or (u, v)
// were off by one step, whose quads turned the other way, or whose edges were walked from the
// wrong end would fail. Cages that are not quads only, or have holes, are refused before any
// file is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <set>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::SculptOptions;
using testing::TempDir;

struct StreamCase {
  const char* name;
  const char* cage;
  int levels;
  Pattern pattern;
};

class StreamedSculpt : public ::testing::TestWithParam<StreamCase> {};

// Each sculpt vertex's nearest vertex of `to`, and the largest distance between them.
std::vector<std::int32_t> NearestVertices(const Mesh& from, const Mesh& to, double& largest) {
  std::vector<std::int32_t> nearest(from.num_vertices());
  largest = 0;
  for (std::size_t v = 0; v < from.num_vertices(); ++v) {
    double best = INFINITY;
    for (std::size_t w = 0; w < to.num_vertices(); ++w) {
      const Float3 a = from.positions[v], b = to.positions[w];
      const double d = std::hypot(double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z);
      if (d < best) best = d, nearest[v] = static_cast<std::int32_t>(w);
    }
    largest = std::max(largest, best);
  }
  return nearest;
}

// A quad as its corners from the smallest id on, keeping its turning order.
std::array<std::int32_t, 4> Canonical(std::array<std::int32_t, 4> q) {
  std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
  return q;
}

TEST_P(StreamedSculpt, IsTheRefinedSculptWithItsVerticesInAnotherOrder) {
  const StreamCase& c = GetParam();
  TempDir dir;
  const std::string cage = DataPath(c.cage);
  const MakeSculptOptions refined =
      SculptOptions(cage, dir / "refined.ply", c.levels, c.pattern, 0);
  MakeSculptOptions streamed = SculptOptions(cage, dir / "streamed.ply", c.levels, c.pattern, 0);
  streamed.streamed = true;
  auto made_refined = MakeSculpt(refined);
  ASSERT_TRUE(made_refined.ok()) << made_refined.status().message();
  auto made_streamed = MakeSculpt(streamed);
  ASSERT_TRUE(made_streamed.ok()) << made_streamed.status().message();
  EXPECT_FALSE(std::filesystem::exists(dir / "streamed.ply.truth"));
  EXPECT_TRUE(std::isnan(made_streamed->linear_error));
  EXPECT_NEAR(made_streamed->h_min, made_refined->h_min, 1e-6 * made_refined->amplitude);
  EXPECT_NEAR(made_streamed->h_max, made_refined->h_max, 1e-6 * made_refined->amplitude);
  EXPECT_NEAR(made_streamed->max_displacement, made_refined->max_displacement,
              1e-6 * made_refined->amplitude);
  EXPECT_GT(made_streamed->max_displacement, 0.1 * made_refined->amplitude);

  auto a = ReadMesh(refined.output_path);
  auto b = ReadMesh(streamed.output_path);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(b->num_vertices(), a->num_vertices());
  ASSERT_EQ(b->num_faces(), a->num_faces());
  EXPECT_EQ(made_streamed->vertices, a->num_vertices());
  EXPECT_EQ(made_streamed->faces, a->num_faces());

  double largest = 0;
  const std::vector<std::int32_t> to_refined = NearestVertices(*b, *a, largest);
  EXPECT_LT(largest, 1e-5 * made_refined->diagonal);
  EXPECT_EQ(std::set<std::int32_t>(to_refined.begin(), to_refined.end()).size(), a->num_vertices());

  std::multiset<std::array<std::int32_t, 4>> refined_quads, streamed_quads;
  for (std::size_t f = 0; f < a->num_faces(); ++f) {
    auto q = a->face(f), r = b->face(f);
    ASSERT_EQ(q.size(), 4u);
    ASSERT_EQ(r.size(), 4u);
    refined_quads.insert(Canonical({q[0], q[1], q[2], q[3]}));
    streamed_quads.insert(
        Canonical({to_refined[std::size_t(r[0])], to_refined[std::size_t(r[1])],
                   to_refined[std::size_t(r[2])], to_refined[std::size_t(r[3])]}));
  }
  EXPECT_TRUE(streamed_quads == refined_quads);
}

INSTANTIATE_TEST_SUITE_P(
    Cages, StreamedSculpt,
    ::testing::Values(
        // Creases and valence-3 corners.
        StreamCase{"cube_creases", "meshes/opensubdiv/catmark_cube_creases1.obj", 3,
                   Pattern::kDetail},
        // Boundaries and extraordinary vertices.
        StreamCase{"helmet", "meshes/opensubdiv/catmark_helmet.obj", 2, Pattern::kRidges},
        StreamCase{"xord_boundary", "meshes/opensubdiv/catmark_xord_boundary.obj", 3,
                   Pattern::kSideways}),
    [](const ::testing::TestParamInfo<StreamCase>& c) { return std::string(c.param.name); });

TEST(StreamedSculptRefusals, NonQuadsHolesAndObjWriteNothing) {
  TempDir dir;
  struct Refusal {
    const char* cage;
    const char* output;
    const char* says;
  };
  for (const Refusal& r : {
           Refusal{"catmark_nonquads.obj", "s.ply",
                   "corners: a streamed sculpt needs a cage of quads"},
           Refusal{"catmark_hole_test1.obj", "s.ply", "is a hole"},
           Refusal{"catmark_cube.obj", "s.obj", "written as PLY"},
       }) {
    MakeSculptOptions options = SculptOptions(DataPath(std::string("meshes/opensubdiv/") + r.cage),
                                              dir / r.output, 2, Pattern::kDetail, 0);
    options.streamed = true;
    auto made = MakeSculpt(options);
    ASSERT_FALSE(made.ok()) << r.cage;
    EXPECT_NE(made.status().message().find(r.says), std::string::npos) << made.status().message();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

}  // namespace
}  // namespace dispex
