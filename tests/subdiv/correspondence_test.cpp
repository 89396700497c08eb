// MatchRefinedSculpt on sculpts made by MakeSculpt (the cage refined L times, displaced), as
// they come and with their vertices and faces shuffled and each face's corner list rotated:
// every vertex must land on the grid point its truth record names. Near misses must be
// rejected with their reason, and the position check must tell a wrong boundary rule.
#include "dispex/correspondence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <sstream>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::TempDir;

std::string Cage(const std::string& name) {
  return name.find('/') != std::string::npos ? DataPath("meshes/" + name)
                                             : DataPath("meshes/opensubdiv/" + name + ".obj");
}

// A sculpt of a cage with the truth of every vertex.
struct Sculpt {
  Mesh mesh;
  std::vector<PtexFaceId> faces;  // per vertex: its truth record
  std::vector<float> uvs;
};

Sculpt MakeRefined(const TempDir& dir, const std::string& cage_path, int levels,
                   Pattern pattern = Pattern::kDetail, double amplitude = 0) {
  MakeSculptOptions options;
  options.cage_path = cage_path;
  options.output_path = dir / "sculpt.obj";
  options.levels = levels;
  options.pattern = pattern;
  options.amplitude = amplitude;
  auto made = MakeSculpt(options);
  EXPECT_TRUE(made.ok()) << made.status().message();
  Sculpt out;
  if (!made.ok()) return out;
  auto mesh = ReadMesh(options.output_path);
  auto truth = ReadGroundTruth(options.output_path + ".truth");
  EXPECT_TRUE(mesh.ok() && truth.ok());
  out.mesh = std::move(mesh).value();
  out.faces = truth->faces;
  out.uvs = truth->uvs;
  return out;
}

LimitSurface Surface(const std::string& cage_path) {
  auto cage = ReadMesh(cage_path);
  EXPECT_TRUE(cage.ok()) << cage.status().message();
  auto surface = LimitSurface::Build(*cage);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  return std::move(surface).value();
}

// The sculpt renumbered and reordered the way a sculpting tool might: vertices and faces
// permuted, each face's corner list started at a random corner. `new_vertex` maps old ids.
struct Shuffled {
  Mesh mesh;
  std::vector<std::int32_t> new_vertex;
};

Shuffled Shuffle(const Mesh& mesh, std::uint32_t seed) {
  std::mt19937 random(seed);
  Shuffled out;
  out.mesh.source = mesh.source;
  out.new_vertex.resize(mesh.num_vertices());
  std::iota(out.new_vertex.begin(), out.new_vertex.end(), 0);
  std::shuffle(out.new_vertex.begin(), out.new_vertex.end(), random);
  out.mesh.positions.resize(mesh.num_vertices());
  for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
    out.mesh.positions[out.new_vertex[v]] = mesh.positions[v];
  }
  std::vector<std::size_t> order(mesh.num_faces());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), random);
  out.mesh.face_offsets.push_back(0);
  for (std::size_t f : order) {
    const auto corners = mesh.face(f);
    const int n = static_cast<int>(corners.size());
    const int start = static_cast<int>(random() % n);
    for (int k = 0; k < n; ++k) {
      out.mesh.face_indices.push_back(out.new_vertex[corners[(start + k) % n]]);
    }
    out.mesh.face_offsets.push_back(static_cast<std::uint32_t>(out.mesh.face_indices.size()));
  }
  return out;
}

// Every sculpt vertex is on the grid point of its truth record; every face's label names its
// corners; homes are the first Ptex face holding the vertex.
void ExpectFitsTruth(const SculptCorrespondence& c, const LimitSurface& surface, const Mesh& mesh,
                     const Sculpt& truth, const std::vector<std::int32_t>& new_vertex, int levels) {
  ASSERT_EQ(c.levels, levels);
  const int num_ptex = surface.num_ptex_faces();
  ASSERT_EQ(c.grid_sizes.size(), static_cast<std::size_t>(num_ptex));
  for (int p = 0; p < num_ptex; ++p) {
    const PtexFaceId face(p);
    const int expected = surface.is_hole(face)                                  ? 0
                         : surface.num_ptex_faces(surface.base_face(face)) == 1 ? 1 << levels
                                                                                : 1 << (levels - 1);
    ASSERT_EQ(c.grid_size(face), expected) << "Ptex face " << p;
  }
  for (std::size_t v = 0; v < truth.faces.size(); ++v) {
    const PtexFaceId face = truth.faces[v];
    const int n = c.grid_size(face);
    const float i = truth.uvs[2 * v] * n, j = truth.uvs[2 * v + 1] * n;
    ASSERT_EQ(i, std::floor(i));
    ASSERT_EQ(j, std::floor(j));
    ASSERT_EQ(c.vertex(face, static_cast<int>(i), static_cast<int>(j)).value, new_vertex[v])
        << "vertex " << v << " at Ptex face " << face.value << " (" << i << ", " << j << ")";
  }
  std::vector<int> first_face(mesh.num_vertices(), -1);
  for (int p = num_ptex - 1; p >= 0; --p) {
    const int n = c.grid_size(PtexFaceId(p));
    for (int j = 0; j <= n && n > 0; ++j) {
      for (int i = 0; i <= n; ++i) first_face[c.vertex(PtexFaceId(p), i, j).value] = p;
    }
  }
  for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
    ASSERT_EQ(c.vertex_faces[v].value, first_face[v]) << "vertex " << v;
    const int n = c.grid_size(c.vertex_faces[v]);
    const float u = c.vertex_uvs[2 * v] * n, w = c.vertex_uvs[2 * v + 1] * n;
    ASSERT_EQ(c.vertex(c.vertex_faces[v], static_cast<int>(u), static_cast<int>(w)).value,
              static_cast<int>(v));
  }
  static constexpr int kCorner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const int n = c.grid_size(c.face_ptex[f]);
    const int i = c.face_cell[f] % n, j = c.face_cell[f] / n;
    for (int k = 0; k < 4; ++k) {
      ASSERT_EQ(mesh.face(f)[(c.face_rotation[f] + k) % 4],
                c.vertex(c.face_ptex[f], i + kCorner[k][0], j + kCorner[k][1]).value)
          << "face " << f << " corner " << k;
    }
  }
}

struct Case {
  std::string cage;
  int levels;
  Pattern pattern = Pattern::kDetail;
  double amplitude = 0;  // 0: MakeSculpt's default, 1% of the bounding-box diagonal
};

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = info.param.cage.substr(info.param.cage.rfind('/') + 1);
  name = name.substr(0, name.find('.'));
  return name + "_L" + std::to_string(info.param.levels) + "_" +
         std::string(PatternName(info.param.pattern));
}

// catmark_torus at level 5 with noise of amplitude 0.1 (2.8% of the diagonal, 3 to 8 sculpt
// edges): the refined torus maps onto itself shifted by any number of cells, and only the
// positions tell the right shift.
class RefinedSculpts : public ::testing::TestWithParam<Case> {};

TEST_P(RefinedSculpts, AsMadeAndShuffledLandOnTheirTruth) {
  TempDir dir;
  const std::string cage = Cage(GetParam().cage);
  const int levels = GetParam().levels;
  const Sculpt sculpt = MakeRefined(dir, cage, levels, GetParam().pattern, GetParam().amplitude);
  const LimitSurface surface = Surface(cage);

  std::vector<std::int32_t> identity(sculpt.mesh.num_vertices());
  std::iota(identity.begin(), identity.end(), 0);
  auto as_made = MatchRefinedSculpt(surface, sculpt.mesh);
  ASSERT_TRUE(as_made.ok()) << as_made.status().message();
  ExpectFitsTruth(*as_made, surface, sculpt.mesh, sculpt, identity, levels);
  // Grids of up to 8 x 8 are checked whole; larger ones on a lattice of rows and columns.
  if (levels <= 3) {
    EXPECT_EQ(as_made->checked_vertices, sculpt.mesh.num_vertices());
  } else {
    EXPECT_LT(as_made->checked_vertices, sculpt.mesh.num_vertices() / 2);
  }
  EXPECT_LE(as_made->max_offset, as_made->offset_limit);

  for (std::uint32_t seed : {1u, 2u}) {
    const Shuffled shuffled = Shuffle(sculpt.mesh, seed);
    auto matched = MatchRefinedSculpt(surface, shuffled.mesh);
    ASSERT_TRUE(matched.ok()) << matched.status().message();
    ExpectFitsTruth(*matched, surface, shuffled.mesh, sculpt, shuffled.new_vertex, levels);
    EXPECT_EQ(matched->components, as_made->components);
    EXPECT_DOUBLE_EQ(matched->max_offset, as_made->max_offset);
  }
}

// Every field of two matches equal (how they were found aside).
void ExpectSameMatch(const SculptCorrespondence& a, const SculptCorrespondence& b,
                     const std::string& what, bool homes = true) {
  EXPECT_EQ(a.levels, b.levels) << what;
  EXPECT_EQ(a.reversed, b.reversed) << what;
  EXPECT_EQ(a.grid_offsets, b.grid_offsets) << what;
  EXPECT_EQ(a.grid_vertices, b.grid_vertices) << what;
  EXPECT_EQ(a.grid_sizes, b.grid_sizes) << what;
  if (homes) {
    EXPECT_EQ(a.vertex_faces, b.vertex_faces) << what;
    EXPECT_EQ(a.vertex_uvs, b.vertex_uvs) << what;
  } else {
    EXPECT_TRUE(a.vertex_faces.empty() && a.vertex_uvs.empty()) << what;
  }
  EXPECT_EQ(a.face_ptex, b.face_ptex) << what;
  EXPECT_EQ(a.face_cell, b.face_cell) << what;
  EXPECT_EQ(a.face_rotation, b.face_rotation) << what;
  EXPECT_EQ(a.cell_labels, b.cell_labels) << what;
  EXPECT_EQ(a.components, b.components) << what;
  EXPECT_EQ(a.checked_vertices, b.checked_vertices) << what;
  EXPECT_EQ(a.max_offset, b.max_offset) << what;
  EXPECT_EQ(a.rms_offset, b.rms_offset) << what;
  EXPECT_EQ(a.worst_vertex, b.worst_vertex) << what;
}

// The match kept in a cache folder: the next match of the same sculpt takes it; after the
// positions moved by a small smooth field, it is taken only when the seeds' choice is still
// the one these positions make, and the result is always the match without a cache.
TEST_P(RefinedSculpts, AKeptMatchIsTheMatchOfTheNewPositions) {
  TempDir dir;
  const std::string cage = Cage(GetParam().cage);
  Sculpt sculpt =
      MakeRefined(dir, cage, GetParam().levels, GetParam().pattern, GetParam().amplitude);
  const LimitSurface surface = Surface(cage);
  MatchOptions cached;
  cached.cache_dir = dir / "cache";
  auto fresh = MatchRefinedSculpt(surface, sculpt.mesh);
  ASSERT_TRUE(fresh.ok()) << fresh.status().message();
  auto first = MatchRefinedSculpt(surface, sculpt.mesh, cached);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_FALSE(first->labelling_from_cache);
  ExpectSameMatch(*first, *fresh, "the match that keeps it");
  auto again = MatchRefinedSculpt(surface, sculpt.mesh, cached);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_TRUE(again->labelling_from_cache);
  EXPECT_FALSE(again->adjacency_from_cache);  // not needed
  ExpectSameMatch(*again, *fresh, "the same sculpt again");

  // Every vertex moved along a smooth field of 0.1% of the box (the seeds' scores change).
  Mesh moved = sculpt.mesh;
  for (Float3& p : moved.positions) {
    p.x += 0.002f * std::sin(3 * p.y);
    p.z += 0.002f * std::cos(2 * p.x);
  }
  auto moved_fresh = MatchRefinedSculpt(surface, moved);
  auto moved_cached = MatchRefinedSculpt(surface, moved, cached);
  ASSERT_EQ(moved_fresh.ok(), moved_cached.ok());
  if (moved_fresh.ok()) ExpectSameMatch(*moved_cached, *moved_fresh, "positions moved");

  // The vertices in a ball moved (the position check measured again on the faces there, taken
  // as kept elsewhere), with and without the homes filled.
  Mesh bumped = sculpt.mesh;
  const Float3 c = bumped.positions[bumped.num_vertices() / 2];
  for (Float3& p : bumped.positions) {
    if (std::hypot(p.x - c.x, p.y - c.y, p.z - c.z) < 0.3f) p.y += 0.003f;
  }
  auto bumped_fresh = MatchRefinedSculpt(surface, bumped);
  ASSERT_TRUE(bumped_fresh.ok()) << bumped_fresh.status().message();
  MatchOptions no_homes = cached;
  no_homes.vertex_homes = false;
  std::size_t checked_again = 0;
  for (const MatchOptions& options : {cached, no_homes}) {
    // The kept match is the one of the sculpt as made: keep it again.
    std::filesystem::remove_all(cached.cache_dir);
    ASSERT_TRUE(MatchRefinedSculpt(surface, sculpt.mesh, cached).ok());
    auto bumped_cached = MatchRefinedSculpt(surface, bumped, options);
    ASSERT_TRUE(bumped_cached.ok()) << bumped_cached.status().message();
    ExpectSameMatch(*bumped_cached, *bumped_fresh, "a ball moved", options.vertex_homes);
    ASSERT_TRUE(bumped_cached->labelling_from_cache);
    EXPECT_GT(bumped_cached->faces_checked_again, 0u);
    checked_again = bumped_cached->faces_checked_again;
  }
  // With more than 1/16 of the faces measured again, the kept match is kept again with the
  // checks of these positions, so that the same positions once more measure none again; with
  // fewer the file stays, and they measure the same faces again.
  auto bumped_again = MatchRefinedSculpt(surface, bumped, no_homes);
  ASSERT_TRUE(bumped_again.ok()) << bumped_again.status().message();
  ExpectSameMatch(*bumped_again, *bumped_fresh, "a ball moved, matched again", false);
  const bool kept_again = 16 * checked_again > static_cast<std::size_t>(surface.num_ptex_faces());
  EXPECT_EQ(bumped_again->faces_checked_again, kept_again ? 0 : checked_again);
  std::printf("%s: %zu of %d faces checked again%s\n", GetParam().cage.c_str(), checked_again,
              surface.num_ptex_faces(), kept_again ? ", kept again" : "");
}

// A cube refined, its positions turned a quarter about z: the same faces, but every vertex now
// lies where another labelling puts it (the cube's symmetry), so the seeds' choice moves. The
// kept match of the unturned sculpt must not be taken; taking it would keep the old labels.
TEST(MatchRefinedSculpt, AKeptMatchIsNotTakenWhenTheSymmetryChosenMoves) {
  TempDir dir;
  const std::string cage = Cage("catmark_cube");
  Sculpt sculpt = MakeRefined(dir, cage, 3, Pattern::kDetail, 0.001);
  const LimitSurface surface = Surface(cage);
  MatchOptions cached;
  cached.cache_dir = dir / "cache";
  auto first = MatchRefinedSculpt(surface, sculpt.mesh, cached);
  ASSERT_TRUE(first.ok()) << first.status().message();
  Mesh turned = sculpt.mesh;
  for (Float3& p : turned.positions) p = {-p.y, p.x, p.z};
  auto fresh = MatchRefinedSculpt(surface, turned);
  ASSERT_TRUE(fresh.ok()) << fresh.status().message();
  ASSERT_NE(fresh->cell_labels, first->cell_labels) << "the turn did not change the labelling";
  auto again = MatchRefinedSculpt(surface, turned, cached);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_FALSE(again->labelling_from_cache);
  EXPECT_TRUE(again->adjacency_from_cache);
  ExpectSameMatch(*again, *fresh, "turned");
  // Kept again for the turned sculpt, the next match takes it.
  auto third = MatchRefinedSculpt(surface, turned, cached);
  ASSERT_TRUE(third.ok());
  EXPECT_TRUE(third->labelling_from_cache);
  ExpectSameMatch(*third, *fresh, "turned, again");
  // A kept match damaged since is matched again.
  for (const auto& entry : std::filesystem::directory_iterator(cached.cache_dir)) {
    if (entry.path().filename().string().rfind("match-", 0) != 0) continue;
    std::fstream f(entry.path(), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('!');
  }
  auto fourth = MatchRefinedSculpt(surface, turned, cached);
  ASSERT_TRUE(fourth.ok());
  EXPECT_FALSE(fourth->labelling_from_cache);
  ExpectSameMatch(*fourth, *fresh, "turned, the kept match damaged");
}

INSTANTIATE_TEST_SUITE_P(
    Cages, RefinedSculpts,
    ::testing::Values(Case{"catmark_cube", 1}, Case{"catmark_cube", 3}, Case{"catmark_nonquads", 1},
                      Case{"catmark_nonquads", 2}, Case{"catmark_nonquads", 3},
                      Case{"catmark_cube_creases0", 2}, Case{"catmark_hole_test1", 2},
                      Case{"catmark_hole_test2", 2}, Case{"catmark_edgecorner", 2},
                      Case{"catmark_tent", 2}, Case{"catmark_flap", 3}, Case{"catmark_pole8", 2},
                      Case{"catmark_pole64", 1}, Case{"catmark_torus", 1}, Case{"catmark_torus", 3},
                      Case{"catmark_torus", 5, Pattern::kNoise, 0.1},
                      Case{"catmark_cubes_semisharp", 2}, Case{"catmark_val2_interior", 2},
                      Case{"catmark_nonman_verts", 2}, Case{"catmark_smoothtris0", 1},
                      Case{"keenan_spot/spot_control_mesh.obj", 1},
                      Case{"keenan_spot/spot_control_mesh.obj", 3},
                      Case{"jerry_the_ogre/controlmesh.obj", 2}, Case{"catmark_car", 1},
                      // Vector sculpts: vertices moved far across the surface (0.16 on a cage
                      // 2 across), where the seeds' (0,0) corners alone admit a wrong labelling.
                      Case{"catmark_nonquads", 3, Pattern::kOverhang, 0.02},
                      Case{"keenan_spot/spot_control_mesh.obj", 3, Pattern::kSideways, 0.01}),
    CaseName);

// Level 0: the cage's own faces (all quads) with the vertices on the limit surface.
TEST(MatchRefinedSculpt, LevelZeroIsTheCageItself) {
  const LimitSurface surface = Surface(Cage("catmark_torus"));
  auto refined = RefineUniform(surface, 0);
  ASSERT_TRUE(refined.ok());
  Sculpt truth{refined->mesh, refined->ptex_faces, refined->uvs};
  const Shuffled shuffled = Shuffle(refined->mesh, 5);
  auto matched = MatchRefinedSculpt(surface, shuffled.mesh);
  ASSERT_TRUE(matched.ok()) << matched.status().message();
  ExpectFitsTruth(*matched, surface, shuffled.mesh, truth, shuffled.new_vertex, 0);
  EXPECT_LT(matched->max_offset, 1e-5);
}

TEST(MatchRefinedSculpt, SameResultAtAnyThreadCount) {
  TempDir dir;
  const std::string cage = Cage("keenan_spot/spot_control_mesh.obj");
  const Sculpt sculpt = MakeRefined(dir, cage, 3);
  const LimitSurface surface = Surface(cage);
  const Shuffled shuffled = Shuffle(sculpt.mesh, 7);
  MatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  auto a = MatchRefinedSculpt(surface, shuffled.mesh, one);
  auto b = MatchRefinedSculpt(surface, shuffled.mesh, two);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->grid_vertices, b->grid_vertices);
  EXPECT_EQ(a->vertex_faces, b->vertex_faces);
  EXPECT_EQ(a->vertex_uvs, b->vertex_uvs);
  EXPECT_EQ(a->face_ptex, b->face_ptex);
  EXPECT_EQ(a->face_cell, b->face_cell);
  EXPECT_EQ(a->face_rotation, b->face_rotation);
  EXPECT_EQ(a->max_offset, b->max_offset);
  EXPECT_EQ(a->rms_offset, b->rms_offset);
  EXPECT_EQ(a->worst_vertex, b->worst_vertex);
}

// cell_labels state, cell by cell, what the face tables state face by face, with or without
// the tables; rejects labels in another cell order, with another rotation, or a match whose
// result depends on whether the tables are filled.
TEST(MatchRefinedSculpt, CellLabelsAgreeWithTheFaceTables) {
  TempDir dir;
  const std::string cage = Cage("keenan_spot/spot_control_mesh.obj");
  const Sculpt sculpt = MakeRefined(dir, cage, 2);
  const LimitSurface surface = Surface(cage);
  const Shuffled shuffled = Shuffle(sculpt.mesh, 11);
  MatchOptions without;
  without.face_tables = false;
  auto a = MatchRefinedSculpt(surface, shuffled.mesh);
  auto b = MatchRefinedSculpt(surface, shuffled.mesh, without);
  ASSERT_TRUE(a.ok() && b.ok());
  const std::size_t num_faces = shuffled.mesh.num_faces();
  ASSERT_EQ(a->cell_labels.size(), num_faces);
  std::vector<std::int64_t> cell_offsets(a->grid_sizes.size() + 1, 0);
  for (std::size_t p = 0; p < a->grid_sizes.size(); ++p) {
    cell_offsets[p + 1] = cell_offsets[p] + std::int64_t{a->grid_sizes[p]} * a->grid_sizes[p];
  }
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::int64_t c = cell_offsets[a->face_ptex[f].value] + a->face_cell[f];
    ASSERT_EQ(a->cell_labels[c], 4 * f + a->face_rotation[f]) << "face " << f;
  }
  EXPECT_EQ(a->cell_labels, b->cell_labels);
  EXPECT_TRUE(b->face_ptex.empty() && b->face_cell.empty() && b->face_rotation.empty());
  EXPECT_EQ(a->grid_vertices, b->grid_vertices);
  EXPECT_EQ(a->vertex_faces, b->vertex_faces);
  EXPECT_EQ(a->vertex_uvs, b->vertex_uvs);
  EXPECT_EQ(a->rms_offset, b->rms_offset);
  EXPECT_EQ(a->worst_vertex, b->worst_vertex);
}

TEST(MatchRefinedSculpt, SculptPointAtIsBilinearOverTheGrid) {
  TempDir dir;
  const std::string cage = Cage("catmark_nonquads");
  const Sculpt sculpt = MakeRefined(dir, cage, 2);
  const LimitSurface surface = Surface(cage);
  auto c = MatchRefinedSculpt(surface, sculpt.mesh);
  ASSERT_TRUE(c.ok()) << c.status().message();
  for (int p = 0; p < surface.num_ptex_faces(); ++p) {
    const PtexFaceId face(p);
    const int n = c->grid_size(face);
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Float3 at = SculptPointAt(*c, sculpt.mesh, face, float(i) / n, float(j) / n);
        const Float3& vertex = sculpt.mesh.positions[c->vertex(face, i, j).value];
        EXPECT_FLOAT_EQ(at.x, vertex.x);
        EXPECT_FLOAT_EQ(at.y, vertex.y);
        EXPECT_FLOAT_EQ(at.z, vertex.z);
      }
    }
    // The centre of cell (0, 0): the mean of its corners.
    const Float3 centre = SculptPointAt(*c, sculpt.mesh, face, 0.5f / n, 0.5f / n);
    float mean = 0;
    for (auto [i, j] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
      mean += sculpt.mesh.positions[c->vertex(face, i, j).value].x / 4;
    }
    EXPECT_NEAR(centre.x, mean, 1e-6);
  }
}

// ---- Near misses ---------------------------------------------------------------------------

class NearMiss : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = Cage("keenan_spot/spot_control_mesh.obj");
    sculpt_ = MakeRefined(dir_, cage_, 2).mesh;
    surface_.emplace(Surface(cage_));
  }

  // The reason `mesh` is not the cage refined: one line that names the sculpt.
  std::string Reason(const Mesh& mesh, const MatchOptions& options = {}) {
    auto matched = MatchRefinedSculpt(*surface_, mesh, options);
    EXPECT_FALSE(matched.ok());
    if (matched.ok()) return "";
    const std::string& message = matched.status().message();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(mesh.source + ": ", 0), 0u) << message;
    return message;
  }

  static Mesh WithFaces(const Mesh& mesh, const std::vector<std::vector<std::int32_t>>& faces) {
    Mesh out;
    out.source = mesh.source;
    out.positions = mesh.positions;
    out.face_offsets.push_back(0);
    for (const auto& face : faces) {
      out.face_indices.insert(out.face_indices.end(), face.begin(), face.end());
      out.face_offsets.push_back(static_cast<std::uint32_t>(out.face_indices.size()));
    }
    return out;
  }
  static std::vector<std::vector<std::int32_t>> Faces(const Mesh& mesh) {
    std::vector<std::vector<std::int32_t>> faces;
    for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
      faces.emplace_back(mesh.face(f).begin(), mesh.face(f).end());
    }
    return faces;
  }

  TempDir dir_;
  std::string cage_;
  Mesh sculpt_;
  std::optional<LimitSurface> surface_;
};

TEST_F(NearMiss, OneQuadSplitInTwo) {
  auto faces = Faces(sculpt_);
  Mesh mesh = sculpt_;
  const std::vector<std::int32_t> q = faces[100];
  const auto mid = [&](int a, int b) {
    const Float3 &p = mesh.positions[q[a]], &r = mesh.positions[q[b]];
    mesh.positions.push_back({(p.x + r.x) / 2, (p.y + r.y) / 2, (p.z + r.z) / 2});
    return static_cast<std::int32_t>(mesh.positions.size() - 1);
  };
  const std::int32_t e = mid(0, 1), f = mid(2, 3);
  faces[100] = {q[0], e, f, q[3]};
  faces.push_back({e, q[1], q[2], f});
  EXPECT_NE(Reason(WithFaces(mesh, faces)).find("counts fit no level"), std::string::npos);
}

TEST_F(NearMiss, OneVertexAndItsFacesRemoved) {
  const std::int32_t gone = sculpt_.face(500)[0];
  std::vector<std::vector<std::int32_t>> faces;
  for (auto face : Faces(sculpt_)) {
    if (std::find(face.begin(), face.end(), gone) != face.end()) continue;
    for (std::int32_t& v : face) v -= v > gone;
    faces.push_back(face);
  }
  Mesh mesh = WithFaces(sculpt_, faces);
  mesh.positions.erase(mesh.positions.begin() + gone);
  EXPECT_NE(Reason(mesh).find("counts fit no level"), std::string::npos);
}

TEST_F(NearMiss, Triangulated) {
  std::vector<std::vector<std::int32_t>> faces;
  for (const auto& q : Faces(sculpt_)) {
    faces.push_back({q[0], q[1], q[2]});
    faces.push_back({q[0], q[2], q[3]});
  }
  EXPECT_NE(Reason(WithFaces(sculpt_, faces)).find("face 0 has 3 vertices"), std::string::npos);
}

TEST_F(NearMiss, OneGridRowWoundTheOtherWay) {
  auto c = MatchRefinedSculpt(*surface_, sculpt_);
  ASSERT_TRUE(c.ok());
  auto faces = Faces(sculpt_);
  const int n = c->grid_size(PtexFaceId(10));
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (c->face_ptex[f].value == 10 && c->face_cell[f] / n == 1) {
      std::reverse(faces[f].begin(), faces[f].end());
    }
  }
  EXPECT_NE(Reason(WithFaces(sculpt_, faces)).find("(their windings disagree)"), std::string::npos);
}

// The edge two quads share turned to the hexagon's other diagonal: the counts stay, the
// topology does not.
TEST_F(NearMiss, OneEdgeTurned) {
  auto faces = Faces(sculpt_);
  const std::vector<std::int32_t> s = faces[300];
  std::size_t t = 0;
  int k = -1;
  for (std::size_t g = 0; g < faces.size() && k < 0; ++g) {
    for (int m = 0; m < 4; ++m) {
      if (faces[g][m] == s[2] && faces[g][(m + 1) % 4] == s[1]) {
        t = g;
        k = m;
      }
    }
  }
  ASSERT_GE(k, 0);
  const std::vector<std::int32_t> h = {
      s[2], s[3], s[0], s[1], faces[t][(k + 2) % 4], faces[t][(k + 3) % 4]};
  faces[300] = {h[1], h[2], h[3], h[4]};
  faces[t] = {h[4], h[5], h[0], h[1]};
  const std::string reason = Reason(WithFaces(sculpt_, faces));
  EXPECT_TRUE(reason.find("valence") != std::string::npos ||
              reason.find("does not fit") != std::string::npos)
      << reason;
}

// The same deep inside a Ptex face's grid, away from the walk that seeds the grids: the
// grid of that face is found not to close.
TEST_F(NearMiss, OneEdgeTurnedInsideAGrid) {
  TempDir dir;
  const Mesh sculpt = MakeRefined(dir, cage_, 3).mesh;
  auto c = MatchRefinedSculpt(*surface_, sculpt);
  ASSERT_TRUE(c.ok());
  auto faces = Faces(sculpt);
  // Cells (4, 4) and (5, 4) of the first quad Ptex face share the cell edge 1 of the first.
  int ptex = 0;
  while (c->grid_size(PtexFaceId(ptex)) != 8) ++ptex;
  std::size_t s_face = 0, t_face = 0;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (c->face_ptex[f].value != ptex) continue;
    if (c->face_cell[f] == 4 + 4 * 8) s_face = f;
    if (c->face_cell[f] == 5 + 4 * 8) t_face = f;
  }
  const int r = c->face_rotation[s_face], q = c->face_rotation[t_face];
  const auto corner = [&](std::size_t f, int rotation, int k) {
    return faces[f][(rotation + k) % 4];
  };
  // The hexagon around the two cells, counter-clockwise from the first cell's (i, j) corner.
  const std::vector<std::int32_t> h = {corner(s_face, r, 0), corner(t_face, q, 0),
                                       corner(t_face, q, 1), corner(t_face, q, 2),
                                       corner(t_face, q, 3), corner(s_face, r, 3)};
  faces[s_face] = {h[0], h[1], h[2], h[5]};
  faces[t_face] = {h[2], h[3], h[4], h[5]};
  Mesh turned = WithFaces(sculpt, faces);
  auto matched = MatchRefinedSculpt(*surface_, turned);
  ASSERT_FALSE(matched.ok());
  EXPECT_NE(matched.status().message().find("does not fit the grid of Ptex face " +
                                            std::to_string(ptex) + " (8x8)"),
            std::string::npos)
      << matched.status().message();
}

TEST_F(NearMiss, TwoVerticesSwapped) {
  Mesh mesh = sculpt_;
  std::swap(mesh.positions[sculpt_.face(10)[0]], mesh.positions[sculpt_.face(2000)[2]]);
  EXPECT_NE(Reason(mesh).find("the position check failed: vertex"), std::string::npos);
}

TEST_F(NearMiss, EveryFaceWoundTheOtherWay) {
  auto faces = Faces(sculpt_);
  for (auto& face : faces) std::reverse(face.begin(), face.end());
  const Mesh flipped = WithFaces(sculpt_, faces);
  EXPECT_NE(Reason(flipped).find("every face winds the other way from the cage's (flipped "
                                 "normals); reversed, it is the cage refined 2 times"),
            std::string::npos);

  // Accepted, it is the correspondence of the sculpt wound back (which is not the original's
  // corner lists: each face is reversed keeping its first corner, so its rotations differ).
  MatchOptions accept;
  accept.accept_reversed = true;
  auto matched = MatchRefinedSculpt(*surface_, flipped, accept);
  ASSERT_TRUE(matched.ok()) << matched.status().message();
  EXPECT_TRUE(matched->reversed);
  Mesh wound_back = flipped;
  ReverseWinding(wound_back);
  auto direct = MatchRefinedSculpt(*surface_, wound_back);
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  EXPECT_FALSE(direct->reversed);
  EXPECT_EQ(matched->levels, 2);
  EXPECT_EQ(matched->grid_vertices, direct->grid_vertices);
  EXPECT_EQ(matched->cell_labels, direct->cell_labels);
  EXPECT_EQ(matched->vertex_faces, direct->vertex_faces);
  EXPECT_EQ(matched->vertex_uvs, direct->vertex_uvs);
  // The grids are the original sculpt's: the same vertices at the same (u, v).
  auto original = MatchRefinedSculpt(*surface_, sculpt_);
  ASSERT_TRUE(original.ok());
  EXPECT_EQ(matched->grid_vertices, original->grid_vertices);

  // A sculpt that is not the cage refined either way still fails with its reason.
  faces[7].pop_back();
  EXPECT_FALSE(MatchRefinedSculpt(*surface_, WithFaces(sculpt_, faces), accept).ok());
}

TEST_F(NearMiss, SculptOfAnotherCage) {
  TempDir other;
  const Sculpt torus = MakeRefined(other, Cage("catmark_torus"), 2);
  EXPECT_NE(Reason(torus.mesh).find("counts fit no level"), std::string::npos);
}

TEST(MatchRefinedSculpt, SameCountsOtherTopology) {
  TempDir dir;
  // Three quads in a row, and three in an L: 8 vertices and 10 edges each.
  std::ofstream(dir / "strip.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\n"
                                      "v 0 1 0\nv 1 1 0\nv 2 1 0\nv 3 1 0\n"
                                      "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\n";
  std::ofstream(dir / "ell.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\n"
                                    "v 1 1 0\nv 2 1 0\nv 1 2 0\nv 2 2 0\n"
                                    "f 1 2 5 4\nf 2 3 6 5\nf 5 6 8 7\n";
  const Sculpt strip = MakeRefined(dir, dir / "strip.obj", 2, Pattern::kNone);
  const LimitSurface ell = Surface(dir / "ell.obj");
  auto matched = MatchRefinedSculpt(ell, strip.mesh);
  ASSERT_FALSE(matched.ok());
  EXPECT_NE(matched.status().message().find("no boundary vertex of valence 3 like base vertex 4"),
            std::string::npos)
      << matched.status().message();
}

TEST(MatchRefinedSculpt, ComponentsMustMatch) {
  TempDir dir;
  // Two strips of two quads, against a quad beside a strip of three: 12 vertices, 14 edges and
  // 4 faces both, so every level has the same counts.
  std::ofstream(dir / "two_strips.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                                           "v 0 3 0\nv 1 3 0\nv 2 3 0\nv 0 4 0\nv 1 4 0\nv 2 4 0\n"
                                           "f 1 2 5 4\nf 2 3 6 5\nf 7 8 11 10\nf 8 9 12 11\n";
  std::ofstream(dir / "quad_and_strip.obj")
      << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
         "v 0 3 0\nv 1 3 0\nv 2 3 0\nv 3 3 0\nv 0 4 0\nv 1 4 0\nv 2 4 0\nv 3 4 0\n"
         "f 1 2 4 3\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\n";
  const Sculpt sculpt = MakeRefined(dir, dir / "quad_and_strip.obj", 2, Pattern::kNone);
  const LimitSurface strips = Surface(dir / "two_strips.obj");
  auto matched = MatchRefinedSculpt(strips, sculpt.mesh);
  ASSERT_FALSE(matched.ok());
  EXPECT_NE(matched.status().message().find(
                "the components differ: the sculpt has 2 connected components of 16, 48 faces"),
            std::string::npos)
      << matched.status().message();
}

// A base of one component trusts the sculpt to be connected until a step fails: a sculpt of
// the right counts in two pieces must still be named as such, not by the step that stumbled.
TEST(MatchRefinedSculpt, ComponentsMustMatchForOneBaseComponent) {
  TempDir dir;
  // A strip of two quads: level 1 has 15 vertices and 8 faces. So has a 2 x 2 grid beside a
  // closed sphere of four quads (two poles, four vertices around).
  std::ofstream(dir / "strip.obj") << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\n"
                                      "f 1 2 5 4\nf 2 3 6 5\n";
  std::ofstream pieces(dir / "pieces.obj");
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 3; ++x) pieces << "v " << x * 0.5 << " " << y * 0.5 << " 0\n";
  }
  pieces << "v 1.5 0.5 1\nv 1.5 0.5 -1\nv 2 0.5 0\nv 1.5 1 0\nv 1 0.5 0\nv 1.5 0 0\n";
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 2; ++x) {
      const int a = 1 + y * 3 + x;
      pieces << "f " << a << " " << a + 1 << " " << a + 4 << " " << a + 3 << "\n";
    }
  }
  for (int i = 0; i < 4; ++i) {
    pieces << "f 10 " << 12 + i << " 11 " << 12 + (i + 1) % 4 << "\n";
  }
  pieces.close();
  const LimitSurface strip = Surface(dir / "strip.obj");
  auto sculpt = ReadMesh(dir / "pieces.obj");
  ASSERT_TRUE(sculpt.ok()) << sculpt.status().message();
  auto matched = MatchRefinedSculpt(strip, *sculpt);
  ASSERT_FALSE(matched.ok());
  EXPECT_NE(matched.status().message().find(
                "the components differ: the sculpt has 2 connected components of 4, 4 faces"),
            std::string::npos)
      << matched.status().message();
}

// catmark_fan: three faces on one edge.
TEST(MatchRefinedSculpt, NonManifoldCageIsRefused) {
  TempDir dir;
  const std::string cage = Cage("catmark_fan");
  const Sculpt sculpt = MakeRefined(dir, cage, 1, Pattern::kNone);
  const LimitSurface surface = Surface(cage);
  auto matched = MatchRefinedSculpt(surface, sculpt.mesh);
  ASSERT_FALSE(matched.ok());
  EXPECT_NE(matched.status().message().find("matching a sculpt needs a manifold cage"),
            std::string::npos)
      << matched.status().message();
}

TEST(MatchRefinedSculpt, BadOptionsAndEmptySculpt) {
  const LimitSurface surface = Surface(Cage("catmark_cube"));
  Mesh empty;
  empty.source = "empty.obj";
  MatchOptions options;
  EXPECT_EQ(MatchRefinedSculpt(surface, empty).status().message(),
            "empty.obj: the sculpt has no faces");
  options.max_levels = 8;
  EXPECT_NE(MatchRefinedSculpt(surface, empty, options).status().message().find("max_levels"),
            std::string::npos);
  options = {};
  options.max_offset = -1;
  EXPECT_NE(MatchRefinedSculpt(surface, empty, options).status().message().find("max_offset"),
            std::string::npos);
}

// ---- The position check --------------------------------------------------------------------

// A sculpt refined with the edge-only boundary rule, matched against the cage with its own
// rule (edge and corner): the same topology, other positions at the boundary's corners.
TEST(MatchRefinedSculpt, PositionCheckTellsTheBoundaryRule) {
  TempDir dir;
  // catmark_edgecorner as it is (edge and corner) and with the edge-only rule.
  std::ifstream in(Cage("catmark_edgecorner"));
  std::stringstream text;
  text << in.rdbuf();
  std::string edge_only = text.str();
  const std::string tag = "t interpolateboundary 1/0/0 1";
  ASSERT_NE(edge_only.find(tag), std::string::npos);
  edge_only.replace(edge_only.find(tag), tag.size(), "t interpolateboundary 1/0/0 2");
  std::ofstream(dir / "edge_only.obj") << edge_only;

  const Sculpt sculpt = MakeRefined(dir, dir / "edge_only.obj", 3, Pattern::kSmooth, 0.01);
  const LimitSurface right = Surface(dir / "edge_only.obj");
  const LimitSurface wrong = Surface(Cage("catmark_edgecorner"));
  MatchOptions options;
  options.max_offset = 0.05;
  auto good = MatchRefinedSculpt(right, sculpt.mesh, options);
  ASSERT_TRUE(good.ok()) << good.status().message();
  auto bad = MatchRefinedSculpt(wrong, sculpt.mesh, options);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("the position check failed"), std::string::npos)
      << bad.status().message();
  // Measured: the right rule 0.0095 at most (the pattern's amplitude), RMS 0.0044; the wrong
  // one 0.236 at most (at a corner of the boundary), RMS 0.023. The default limit, 15% of the
  // diagonal (3.54), is 0.53: it takes both; the topology alone cannot tell them apart.
  EXPECT_LT(good->max_offset, 0.01);
  options.max_offset = 1;
  auto loose = MatchRefinedSculpt(wrong, sculpt.mesh, options);
  ASSERT_TRUE(loose.ok()) << loose.status().message();
  EXPECT_GT(loose->max_offset, 0.2);
  EXPECT_TRUE(MatchRefinedSculpt(wrong, sculpt.mesh).ok());
}

}  // namespace
}  // namespace dispex
