// The welded tessellation: closed cages stay closed and consistently oriented with any mix of
// per-face densities (no cracks, no T-junctions), Euler characteristics match the cage's
// topology, vertices lie on the limit surface, a constant map moves every vertex by exactly
// that value, normals are unit, and threads do not change the result.
#include "render/tessellation.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "render_test_util.h"

namespace dispex::render {
namespace {

using render_test::DataPath;
using render_test::TempDir;

struct EdgeUse {
  int forward = 0, backward = 0;  // uses as (a, b) with a < b, and as (b, a)
};

// Directed-edge census of a triangle mesh.
std::map<std::pair<int, int>, EdgeUse> Edges(const Mesh& mesh) {
  std::map<std::pair<int, int>, EdgeUse> edges;
  for (std::size_t t = 0; t < mesh.num_faces(); ++t) {
    const auto f = mesh.face(t);
    for (int k = 0; k < 3; ++k) {
      const int a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 3)];
      if (a < b)
        ++edges[{a, b}].forward;
      else
        ++edges[{b, a}].backward;
    }
  }
  return edges;
}

std::vector<std::array<int, 2>> MixedDensities(int faces, int seed) {
  std::vector<std::array<int, 2>> d(static_cast<std::size_t>(faces));
  for (int f = 0; f < faces; ++f) {
    const int a = ((f + seed) * 7) % 5, b = ((f + seed) * 3) % 4;
    d[static_cast<std::size_t>(f)] = {1 << a, (1 << b) + (f % 3 == 0 ? 1 : 0)};  // some odd
  }
  return d;
}

struct Tessellated {
  Mesh cage;
  std::optional<LimitSurface> surface;
  ShadedMesh mesh;
};

Tessellated Tessellate(const std::string& path, int seed, const PtexFile* map = nullptr,
                       int uniform = 0) {
  Tessellated t;
  auto cage = ReadMesh(path);
  EXPECT_TRUE(cage.ok()) << cage.status().message();
  t.cage = std::move(*cage);
  auto surface = LimitSurface::Build(t.cage);
  EXPECT_TRUE(surface.ok()) << surface.status().message();
  t.surface.emplace(std::move(*surface));
  auto density = MixedDensities(t.surface->num_ptex_faces(), seed);
  if (uniform > 0) density.assign(density.size(), {uniform, uniform});
  auto mesh = TessellateLimitSurface(t.cage, *t.surface, density, map, 0);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  t.mesh = std::move(*mesh);
  return t;
}

// Closed cages (no boundary, no holes), including n-gons and creases.
TEST(Tessellation, ClosedCagesGiveClosedConsistentMeshes) {
  for (const char* name :
       {"meshes/keenan_spot/spot_control_mesh.obj", "meshes/opensubdiv/catmark_cube.obj",
        "meshes/opensubdiv/catmark_pyramid.obj", "meshes/opensubdiv/catmark_gregory_test8.obj",
        "meshes/opensubdiv/catmark_smoothtris0.obj", "meshes/opensubdiv/catmark_cube_creases1.obj",
        "meshes/opensubdiv/catmark_cubes_infsharp.obj", "meshes/opensubdiv/catmark_torus.obj"}) {
    for (int seed : {0, 1}) {
      SCOPED_TRACE(std::string(name) + " seed " + std::to_string(seed));
      const Tessellated t = Tessellate(DataPath(name), seed);
      const auto edges = Edges(t.mesh.mesh);
      int bad = 0;
      for (const auto& [edge, use] : edges) {
        if (use.forward != 1 || use.backward != 1) ++bad;
      }
      EXPECT_EQ(bad, 0) << "edges not shared by exactly two opposite triangles";
      // Every vertex is used.
      std::vector<bool> used(t.mesh.mesh.num_vertices(), false);
      for (std::int32_t v : t.mesh.mesh.face_indices) used[static_cast<std::size_t>(v)] = true;
      EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
      // Euler characteristic equals the cage's (the tessellation is a subdivision of it).
      std::set<std::pair<int, int>> cage_edges;
      for (std::size_t f = 0; f < t.cage.num_faces(); ++f) {
        const auto verts = t.cage.face(f);
        for (std::size_t k = 0; k < verts.size(); ++k) {
          const int a = verts[k], b = verts[(k + 1) % verts.size()];
          cage_edges.insert({std::min(a, b), std::max(a, b)});
        }
      }
      const long cage_chi =
          long(t.cage.num_vertices()) - long(cage_edges.size()) + long(t.cage.num_faces());
      const long chi =
          long(t.mesh.mesh.num_vertices()) - long(edges.size()) + long(t.mesh.mesh.num_faces());
      EXPECT_EQ(chi, cage_chi);
    }
  }
}

TEST(Tessellation, OpenAndNonManifoldCagesKeepTheirTopology) {
  struct Case {
    const char* name;
    bool manifold;
  };
  for (const Case& c : {Case{"meshes/opensubdiv/catmark_hole_test1.obj", true},
                        Case{"meshes/opensubdiv/catmark_hole_test2.obj", true},
                        Case{"meshes/opensubdiv/catmark_nonquads.obj", true},
                        Case{"meshes/opensubdiv/catmark_val2_interior.obj", true},
                        Case{"meshes/opensubdiv/catmark_xord_boundary.obj", true},
                        Case{"meshes/opensubdiv/catmark_fan.obj", false},
                        Case{"meshes/opensubdiv/catmark_nonman_verts.obj", false}}) {
    for (int seed : {0, 3}) {
      SCOPED_TRACE(std::string(c.name) + " seed " + std::to_string(seed));
      const Tessellated t = Tessellate(DataPath(c.name), seed);
      const auto edges = Edges(t.mesh.mesh);
      if (c.manifold) {
        int bad = 0;
        for (const auto& [edge, use] : edges) bad += use.forward > 1 || use.backward > 1;
        EXPECT_EQ(bad, 0) << "edges used twice in one direction";
      }
      // The Euler characteristic of the faces that have a surface: subdividing a complex keeps
      // it, and a crack or a T-junction would change it.
      std::set<std::pair<int, int>> cage_edges;
      std::set<int> cage_vertices;
      long cage_faces = 0;
      for (std::size_t f = 0; f < t.cage.num_faces(); ++f) {
        const BaseFaceId base(static_cast<std::int32_t>(f));
        if (t.surface->is_hole(t.surface->first_ptex_face(base))) continue;
        ++cage_faces;
        const auto verts = t.cage.face(f);
        for (std::size_t k = 0; k < verts.size(); ++k) {
          const int a = verts[k], b = verts[(k + 1) % verts.size()];
          cage_edges.insert({std::min(a, b), std::max(a, b)});
          cage_vertices.insert(a);
        }
      }
      const long cage_chi = long(cage_vertices.size()) - long(cage_edges.size()) + cage_faces;
      const long chi =
          long(t.mesh.mesh.num_vertices()) - long(edges.size()) + long(t.mesh.mesh.num_faces());
      EXPECT_EQ(chi, cage_chi);
    }
  }
}

TEST(Tessellation, UniformGridOfAPlaneIsExact) {
  TempDir dir;
  render_test::WriteText(dir / "grid.obj", render_test::GridCageObj(4));
  const Tessellated t = Tessellate(dir / "grid.obj", 0, nullptr, 8);
  // 16 faces of 8x8 quads, 2 triangles each; (4*8+1)^2 vertices.
  EXPECT_EQ(t.mesh.mesh.num_faces(), 16u * 64 * 2);
  EXPECT_EQ(t.mesh.mesh.num_vertices(), 33u * 33);
  std::set<std::pair<long, long>> grid;
  for (const Float3& p : t.mesh.mesh.positions) {
    EXPECT_NEAR(p.y, 0, 1e-6);
    // On the 1/16 lattice (the limit of a uniform grid is linear in u, v).
    EXPECT_NEAR(p.x * 16, std::round(p.x * 16), 2e-4);
    EXPECT_NEAR(p.z * 16, std::round(p.z * 16), 2e-4);
    grid.insert({std::lround(p.x * 16), std::lround(p.z * 16)});
  }
  EXPECT_EQ(grid.size(), 33u * 33);  // welded: no point twice
  for (const Float3& n : t.mesh.normals) {
    EXPECT_NEAR(n.y, 1, 1e-6);
  }
}

TEST(Tessellation, VerticesLieOnTheLimitSurface) {
  const Tessellated t = Tessellate(DataPath("meshes/opensubdiv/catmark_pyramid.obj"), 2);
  // Each face's own grid points, evaluated independently, are vertices of the mesh.
  LimitEvaluator evaluator(*t.surface);
  std::vector<float> uv, p(3 * 9);
  for (float v : {0.0f, 0.5f, 1.0f}) {
    for (float u : {0.0f, 0.5f, 1.0f}) {
      uv.push_back(u);
      uv.push_back(v);
    }
  }
  const auto& positions = t.mesh.mesh.positions;
  for (int f = 0; f < t.surface->num_ptex_faces(); ++f) {
    ASSERT_TRUE(evaluator.EvaluatePoints(PtexFaceId(f), uv, p, {}).ok());
    for (int k = 0; k < 9; ++k) {
      // Corners are on every face's grid; the nearest vertex is within rounding.
      if (k != 0 && k != 2 && k != 6 && k != 8) continue;
      double best = 1e30;
      for (const Float3& q : positions) {
        best = std::min(best,
                        double(std::hypot(q.x - p[3 * k], q.y - p[3 * k + 1], q.z - p[3 * k + 2])));
      }
      EXPECT_LT(best, 1e-5) << "face " << f << " corner " << k;
    }
  }
}

TEST(Tessellation, ConstantMapMovesEveryVertexByItsValue) {
  TempDir dir;
  const std::string cage = DataPath("meshes/opensubdiv/catmark_pyramid.obj");
  auto mesh = ReadMesh(cage);
  ASSERT_TRUE(mesh.ok());
  auto surface = LimitSurface::Build(*mesh);
  ASSERT_TRUE(surface.ok());
  render_test::WriteMap(dir / "c.ptx", surface->num_ptex_faces(), 2,
                        [](int, double, double) { return 0.125f; });
  auto map = PtexFile::Open(dir / "c.ptx");
  ASSERT_TRUE(map.ok());
  const Tessellated flat = Tessellate(cage, 4);
  const Tessellated moved = Tessellate(cage, 4, &*map);
  // The same vertices in the same order (quads may split along the other diagonal).
  ASSERT_EQ(flat.mesh.mesh.num_faces(), moved.mesh.mesh.num_faces());
  ASSERT_EQ(flat.mesh.mesh.num_vertices(), moved.mesh.mesh.num_vertices());
  for (std::size_t v = 0; v < flat.mesh.mesh.num_vertices(); ++v) {
    const Float3& a = flat.mesh.mesh.positions[v];
    const Float3& b = moved.mesh.mesh.positions[v];
    EXPECT_NEAR(std::hypot(b.x - a.x, b.y - a.y, b.z - a.z), 0.125, 1e-5) << v;
  }
}

TEST(Tessellation, NormalsAreUnitAndPointOutwards) {
  const Tessellated t = Tessellate(DataPath("meshes/opensubdiv/catmark_cube.obj"), 1);
  Float3 centre{0, 0, 0};
  for (const Float3& p : t.mesh.mesh.positions) {
    centre.x += p.x, centre.y += p.y, centre.z += p.z;
  }
  const float n = static_cast<float>(t.mesh.mesh.num_vertices());
  centre = {centre.x / n, centre.y / n, centre.z / n};
  for (std::size_t v = 0; v < t.mesh.normals.size(); ++v) {
    const Float3& q = t.mesh.normals[v];
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z, 1.0, 1e-5);
    const Float3& p = t.mesh.mesh.positions[v];
    EXPECT_GT(q.x * (p.x - centre.x) + q.y * (p.y - centre.y) + q.z * (p.z - centre.z), 0) << v;
  }
}

TEST(Tessellation, SameMeshWithOneOrTwoThreads) {
  const std::string cage = DataPath("meshes/opensubdiv/catmark_fan.obj");
  Tessellated one, two;
  tbb::task_arena(1).execute([&] { one = Tessellate(cage, 5); });
  tbb::task_arena(2).execute([&] { two = Tessellate(cage, 5); });
  EXPECT_EQ(one.mesh.mesh.face_indices, two.mesh.mesh.face_indices);
  ASSERT_EQ(one.mesh.mesh.positions.size(), two.mesh.mesh.positions.size());
  for (std::size_t v = 0; v < one.mesh.mesh.positions.size(); ++v) {
    EXPECT_EQ(std::memcmp(&one.mesh.mesh.positions[v], &two.mesh.mesh.positions[v], sizeof(Float3)),
              0);
    EXPECT_EQ(std::memcmp(&one.mesh.normals[v], &two.mesh.normals[v], sizeof(Float3)), 0);
  }
}

TEST(Tessellation, PolygonMeshNormalsAndFans) {
  TempDir dir;
  // A pentagon and a quad sharing an edge, both facing +z.
  render_test::WriteText(
      dir / "p.obj",
      "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.5 0\nv -0.5 1 0\nv 2 0 0\nv 2.5 1 0\n"
      "f 1 2 3 4 5\nf 2 6 7 3\n");
  auto mesh = ReadMesh(dir / "p.obj");
  ASSERT_TRUE(mesh.ok());
  const ShadedMesh shaded = ShadePolygonMesh(*mesh);
  EXPECT_EQ(shaded.mesh.num_faces(), 3u + 2u);
  EXPECT_GT(shaded.mesh.positions.capacity(), shaded.mesh.positions.size());
  for (const Float3& n : shaded.normals) EXPECT_NEAR(n.z, 1, 1e-6);
}

}  // namespace
}  // namespace dispex::render
