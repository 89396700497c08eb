// BuildVertexPrims (src/trace/vertex_prims.h), the table the tie rule reads: every vertex lists
// exactly the primitives with a corner there, and a primitive is folded exactly when two of the
// triangles around one of its corners face against each other -- checked here pair by pair, on
// a grid of quads and triangles with some vertices pushed across their neighbours.
#include "trace/vertex_prims.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace dispex::trace {
namespace {

Float3 Normal(const std::vector<Float3>& p, std::int32_t a, std::int32_t b, std::int32_t c) {
  const Float3 e1{p[b].x - p[a].x, p[b].y - p[a].y, p[b].z - p[a].z};
  const Float3 e2{p[c].x - p[a].x, p[c].y - p[a].y, p[c].z - p[a].z};
  return {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
}

TEST(VertexPrims, FoldedWhereTwoTrianglesAroundAVertexFaceAgainstEachOther) {
  constexpr int n = 40;  // vertices per side
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  std::vector<Float3> p;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) p.push_back({float(x), float(y), noise(rng)});
  }
  // Some vertices pushed past their neighbours: the triangles around them turn over.
  for (int k = 0; k < 12; ++k) p[rng() % p.size()].x += 1.6f;
  std::vector<std::int32_t> quads, triangles;
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const std::int32_t a = y * n + x, b = a + 1, c = a + n + 1, d = a + n;
      if ((x + 3 * y) % 7 == 0) {
        triangles.insert(triangles.end(), {a, b, c, a, c, d});
      } else {
        quads.insert(quads.end(), {a, b, c, d});
      }
    }
  }
  const std::size_t num_quads = quads.size() / 4, num_triangles = triangles.size() / 3;
  const VertexPrims vp = BuildVertexPrims(quads.data(), num_quads, triangles.data(), num_triangles,
                                          p.data(), p.size());
  auto corners = [&](std::size_t g) {
    return g < num_quads
               ? std::vector<std::int32_t>(quads.begin() + 4 * g, quads.begin() + 4 * g + 4)
               : std::vector<std::int32_t>(triangles.begin() + 3 * (g - num_quads),
                                           triangles.begin() + 3 * (g - num_quads) + 3);
  };
  std::vector<std::vector<std::uint32_t>> around(p.size());
  for (std::size_t g = 0; g < num_quads + num_triangles; ++g) {
    for (std::int32_t v : corners(g)) around[std::size_t(v)].push_back(std::uint32_t(g));
  }
  std::vector<std::uint8_t> folded(num_quads + num_triangles, 0);
  for (std::size_t v = 0; v < p.size(); ++v) {
    std::vector<std::uint32_t> listed(vp.around(std::int32_t(v)).begin(),
                                      vp.around(std::int32_t(v)).end());
    std::sort(listed.begin(), listed.end());
    ASSERT_EQ(listed, around[v]) << "vertex " << v;
    // The triangles that hold v: a quad's halves (c0 c1 c3) and (c2 c3 c1).
    std::vector<Float3> normals;
    for (std::uint32_t g : around[v]) {
      const std::vector<std::int32_t> c = corners(g);
      if (c.size() == 3) {
        normals.push_back(Normal(p, c[0], c[1], c[2]));
        continue;
      }
      if (c[2] != std::int32_t(v)) normals.push_back(Normal(p, c[0], c[1], c[3]));
      if (c[0] != std::int32_t(v)) normals.push_back(Normal(p, c[2], c[3], c[1]));
    }
    bool against = false;
    for (std::size_t i = 0; i < normals.size(); ++i) {
      for (std::size_t j = i + 1; j < normals.size(); ++j) {
        const Float3 &a = normals[i], &b = normals[j];
        against = against || a.x * b.x + a.y * b.y + a.z * b.z < 0;
      }
    }
    if (!against) continue;
    for (std::uint32_t g : around[v]) folded[g] = 1;
  }
  const auto count = std::count(folded.begin(), folded.end(), 1);
  EXPECT_GT(count, 12);
  EXPECT_LT(count, static_cast<std::ptrdiff_t>(folded.size() / 4));
  EXPECT_EQ(vp.folded, folded);
}

}  // namespace
}  // namespace dispex::trace
