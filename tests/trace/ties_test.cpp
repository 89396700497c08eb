// Normal queries aimed exactly at the shared edges and vertices of a bumpy height field: every
// face there is hit at once, and the answer (t to the last bit, the flags, the face) must not
// depend on which one Embree reports. So the same queries give the same answers under every
// RayMode, and against a BVH of the whole field or of only the part around the targets (a
// farm shard's or an incremental run's BVH).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

constexpr int kCells = 24;  // per side, over [-1, 1]^2
constexpr RayMode kRayModes[] = {RayMode::kSingle, RayMode::kPacket4, RayMode::kPacket8,
                                 RayMode::kPacket16, RayMode::kStream};

// z = a few waves plus noise of 5% of a cell; quads in rows j % 3 == 0, pairs of triangles
// along alternating diagonals otherwise (so edges meet 4 to 8 faces at a vertex).
Mesh BumpyField() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  std::vector<Float3> positions;
  const float cell = 2.0f / kCells;
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      const float x = -1 + cell * static_cast<float>(i), y = -1 + cell * static_cast<float>(j);
      positions.push_back({x, y, 0.2f * std::sin(3 * x) * std::cos(2 * y) + cell * noise(rng)});
    }
  }
  Mesh mesh = trace_test::NewMesh(std::move(positions));
  auto at = [](int i, int j) { return j * (kCells + 1) + i; };
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (j % 3 == 0) {
        trace_test::AddFace(mesh, {a, b, c, d});
      } else if ((i + j) % 2 == 0) {
        trace_test::AddFace(mesh, {a, b, c});
        trace_test::AddFace(mesh, {a, c, d});
      } else {
        trace_test::AddFace(mesh, {a, b, d});
        trace_test::AddFace(mesh, {b, c, d});
      }
    }
  }
  return mesh;
}

// The faces whose first vertex lies within `half` of the origin in x and y, in their order,
// with their vertices renumbered in order (as a shard cuts the sculpt), and each kept face's
// index in the whole mesh.
Mesh CentrePart(const Mesh& mesh, float half, std::vector<std::int32_t>* whole_face) {
  std::vector<std::int32_t> renumber(mesh.num_vertices(), -1);
  std::vector<std::size_t> kept;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const Float3& p = mesh.positions[static_cast<std::size_t>(mesh.face(f)[0])];
    if (std::fabs(p.x) > half || std::fabs(p.y) > half) continue;
    kept.push_back(f);
    for (std::int32_t v : mesh.face(f)) renumber[static_cast<std::size_t>(v)] = 0;
  }
  std::vector<Float3> positions;
  for (std::size_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] < 0) continue;
    renumber[v] = static_cast<std::int32_t>(positions.size());
    positions.push_back(mesh.positions[v]);
  }
  Mesh part = trace_test::NewMesh(std::move(positions));
  for (std::size_t f : kept) {
    for (std::int32_t v : mesh.face(f)) {
      part.face_indices.push_back(renumber[static_cast<std::size_t>(v)]);
    }
    part.face_offsets.push_back(static_cast<std::uint32_t>(part.face_indices.size()));
    whole_face->push_back(static_cast<std::int32_t>(f));
  }
  return part;
}

struct Answers {
  std::vector<float> t;
  std::vector<std::uint8_t> flags;
  std::vector<SculptPrimId> prim;
  TraceCounters counters;
};

// With `table` false the scene is built for other queries and makes the tie rule's table
// on the first normal query.
Answers Trace(const Mesh& mesh, RayMode mode, const std::vector<Float3>& origins,
              const std::vector<Float3>& normals, bool table = true) {
  TracerOptions options;
  options.ray_mode = mode;
  options.normal_queries = table;
  options.scale = 2;  // as extraction gives it, from the base: the same for whole and part
  auto tracer = MakeEmbreeTracer(mesh, options);
  EXPECT_TRUE(tracer.ok()) << tracer.status().message();
  Answers a;
  if (!tracer.ok()) return a;
  a.t.resize(origins.size());
  a.flags.resize(origins.size());
  a.prim.resize(origins.size());
  NormalQuery query;
  query.distance = 4;
  (*tracer)->TraceNormals(origins, normals, query, NormalHits{a.t, a.prim, a.flags}, a.counters);
  return a;
}

TEST(Ties, AnswersAtSharedEdgesAndVerticesDoNotDependOnTheBvhOrTheRayMode) {
  const Mesh field = BumpyField();
  std::vector<std::int32_t> whole_face;
  const Mesh part = CentrePart(field, 0.6f, &whole_face);
  ASSERT_LT(part.num_faces(), field.num_faces() / 2);

  // Targets: every vertex and every float edge midpoint within [-0.45, 0.45]^2 (all faces
  // around them are in the part), each met by a vertical query and by a tilted one whose
  // origin lies on the line through the target.
  // Also points 1e-4 of the way from each edge midpoint towards the face's centre: within the
  // tie band, but on one face only, whose plane must give t.
  std::vector<Float3> targets;
  for (std::size_t f = 0; f < field.num_faces(); ++f) {
    const auto ids = field.face(f);
    Float3 centre{0, 0, 0};
    for (std::int32_t v : ids) {
      const Float3& p = field.positions[static_cast<std::size_t>(v)];
      centre = {centre.x + p.x / 4, centre.y + p.y / 4, centre.z + p.z / 4};
    }
    if (ids.size() == 3) centre = {centre.x * 4 / 3, centre.y * 4 / 3, centre.z * 4 / 3};
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const Float3& a = field.positions[static_cast<std::size_t>(ids[k])];
      const Float3& b = field.positions[static_cast<std::size_t>(ids[(k + 1) % ids.size()])];
      const Float3 mid{(a.x + b.x) / 2, (a.y + b.y) / 2, (a.z + b.z) / 2};
      targets.push_back(a);
      targets.push_back(mid);
      targets.push_back({mid.x + 1e-4f * (centre.x - mid.x), mid.y + 1e-4f * (centre.y - mid.y),
                         mid.z + 1e-4f * (centre.z - mid.z)});
    }
  }
  std::vector<Float3> origins, normals;
  const Float3 tilted = {0.3f, -0.2f, 0.93f};
  for (const Float3& p : targets) {
    if (std::fabs(p.x) > 0.45f || std::fabs(p.y) > 0.45f) continue;
    origins.push_back({p.x, p.y, 1.5f});
    normals.push_back({0, 0, 1});
    origins.push_back({p.x + 0.5f * tilted.x, p.y + 0.5f * tilted.y, p.z + 0.5f * tilted.z});
    normals.push_back(tilted);
  }
  ASSERT_GT(origins.size(), 1000u);

  const Answers reference = Trace(field, RayMode::kSingle, origins, normals);
  ASSERT_EQ(reference.t.size(), origins.size());
  EXPECT_EQ(reference.counters.hits, origins.size());
  // t is the plane's of a face the line meets (a double-precision oracle's, to float
  // rounding): a rule picking any face around the edge would miss the off-edge targets.
  const auto triangles = trace_test::OracleTriangles(field);
  int wrong = 0;
  for (std::size_t i = 0; i < origins.size(); ++i) {
    const trace_test::Vec3 down = -1.0 * trace_test::ToVec3(normals[i]);
    const auto hit = trace_test::OracleRay(triangles, trace_test::ToVec3(origins[i]), down, 0, 4);
    ASSERT_TRUE(hit.has_value()) << "query " << i;
    if (std::fabs(reference.t[i] + hit->t) > 4e-7 && ++wrong <= 3) {
      ADD_FAILURE() << "query " << i << ": t " << reference.t[i] << ", the oracle " << -hit->t;
    }
  }
  EXPECT_EQ(wrong, 0);
  // Most queries are ties (the tilted ones through edge midpoints may pass beside).
  EXPECT_GT(reference.counters.tie_hits, origins.size() / 2);
  for (RayMode mode : kRayModes) {
    for (const bool use_part : {false, true}) {
      SCOPED_TRACE(fmt::format("{}, {}", RayModeName(mode), use_part ? "part" : "whole"));
      // The part's scene makes its table on its first normal query, the whole's with the BVH.
      const Answers a = Trace(use_part ? part : field, mode, origins, normals, !use_part);
      ASSERT_EQ(a.t.size(), origins.size());
      int differ = 0;
      for (std::size_t i = 0; i < origins.size(); ++i) {
        const SculptPrimId face =
            use_part && a.prim[i].valid()
                ? SculptPrimId(whole_face[static_cast<std::size_t>(a.prim[i].value)])
                : a.prim[i];
        const bool same =
            std::bit_cast<std::uint32_t>(a.t[i]) == std::bit_cast<std::uint32_t>(reference.t[i]) &&
            a.flags[i] == reference.flags[i] && face == reference.prim[i];
        if (!same && ++differ <= 3) {
          ADD_FAILURE() << "query " << i << ": t " << a.t[i] << " face " << face.value << " flags "
                        << int(a.flags[i]) << ", against t " << reference.t[i] << " face "
                        << reference.prim[i].value << " flags " << int(reference.flags[i]);
        }
      }
      EXPECT_EQ(differ, 0);
    }
  }
}

// Folds: pairs of triangles sharing an edge, the second turned back over the first (it faces
// the other way) and lifted by at most 2e-8 at its far corner. A query from above through
// both meets them within float rounding of each other: Embree's order between them is its
// kernels' and its BVH's, the tie rule's is the nearer plane in double.
TEST(Ties, AtAFoldTheNearerSheetIsKeptWhateverTheBvhOrTheRayMode) {
  constexpr int kPairs = 40;
  std::vector<Float3> positions;
  for (int k = 0; k < kPairs; ++k) {
    const float x = 2.0f * static_cast<float>(k);
    positions.insert(positions.end(),
                     {{x, 0, 0}, {x + 1, 0, 0}, {x + 0.5f, 1, 0}, {x + 0.5f, 1, 2e-8f}});
  }
  // The first `pairs` pairs as a mesh.
  const auto pairs_mesh = [&](int pairs) {
    Mesh mesh = trace_test::NewMesh({positions.begin(), positions.begin() + 4 * pairs});
    for (int k = 0; k < pairs; ++k) {
      const int a = 4 * k;
      trace_test::AddFace(mesh, {a, a + 1, a + 2});  // faces +z
      trace_test::AddFace(mesh, {a + 1, a, a + 3});  // turned back: faces -z
    }
    return mesh;
  };
  const Mesh folds = pairs_mesh(kPairs);
  const Mesh part = pairs_mesh(kPairs / 2);  // the part: the first half of the pairs
  std::vector<Float3> origins, normals;
  for (int k = 0; k < kPairs / 2; ++k) {
    for (int j = 1; j <= 9; ++j) {
      const float y = 0.1f * static_cast<float>(j);
      for (int i = 1; i <= 9; ++i) {
        const float x =
            2.0f * static_cast<float>(k) + 0.5f + (0.05f * static_cast<float>(i - 5)) * (1 - y);
        origins.push_back({x, y, 1});
        normals.push_back({0, 0, 1});
      }
    }
  }
  // The oracle's nearest sheet is the lifted one, met from its back (it faces -z: the query's
  // -n ray meets its front). Every answer must say so.
  const auto triangles = trace_test::OracleTriangles(folds);
  for (RayMode mode : kRayModes) {
    for (const bool use_part : {false, true}) {
      SCOPED_TRACE(fmt::format("{}, {}", RayModeName(mode), use_part ? "part" : "whole"));
      const Answers a = Trace(use_part ? part : folds, mode, origins, normals);
      ASSERT_EQ(a.t.size(), origins.size());
      int wrong = 0;
      for (std::size_t i = 0; i < origins.size(); ++i) {
        const auto hit =
            trace_test::OracleRay(triangles, trace_test::ToVec3(origins[i]), {0, 0, -1}, 0, 4);
        ASSERT_TRUE(hit.has_value());
        ASSERT_EQ(hit->face % 2, 1) << "the oracle meets the lifted sheet first";
        const bool back = (a.flags[i] & HitFlags::kBackFace) != 0;
        const bool oracle_back = hit->normal.z < 0;  // the ray runs along -z
        const int face = a.prim[i].value;            // the part keeps the first pairs' ids
        if ((back != oracle_back || face != hit->face) && ++wrong <= 3) {
          ADD_FAILURE() << "query " << i << ": face " << face << (back ? " back" : " front")
                        << ", the oracle's " << hit->face << (oracle_back ? " back" : " front");
        }
      }
      EXPECT_EQ(wrong, 0);
    }
  }
}

}  // namespace
}  // namespace dispex
