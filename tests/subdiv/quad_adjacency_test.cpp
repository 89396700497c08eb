// The sculpt's half-edge adjacency (subdiv/quad_adjacency.h) on small meshes.
#include "subdiv/quad_adjacency.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "subdiv/adjacency_cache.h"

namespace dispex::subdiv {
namespace {

Mesh Quads(int num_vertices, const std::vector<std::int32_t>& corners) {
  Mesh mesh;
  mesh.source = "quads.obj";
  mesh.positions.resize(num_vertices);
  mesh.face_indices = corners;
  for (std::size_t f = 0; f <= corners.size() / 4; ++f) {
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(4 * f));
  }
  return mesh;
}

// A 2 x 2 grid of quads: vertices 0..8 row by row.
const std::vector<std::int32_t> kGrid = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 7, 6, 4, 5, 8, 7};

TEST(QuadAdjacency, GridOfFourQuads) {
  auto adjacency = BuildQuadAdjacency(Quads(9, kGrid));
  ASSERT_TRUE(adjacency.ok()) << adjacency.status().message();
  // Quad 0's edge 1 (1 -> 4) is quad 1's edge 3 (4 -> 1); its edge 2 (4 -> 3) quad 2's 0.
  EXPECT_EQ(adjacency->opposite[1], 4u * 1 + 3);
  EXPECT_EQ(adjacency->opposite[4 * 1 + 3], 1u);
  EXPECT_EQ(adjacency->opposite[2], 4u * 2 + 0);
  EXPECT_EQ(adjacency->opposite[0], kNoHalfEdge);
  EXPECT_EQ(adjacency->valence, (std::vector<std::uint16_t>{1, 2, 1, 2, 4, 2, 1, 2, 1}));
  EXPECT_EQ(adjacency->boundary, (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 1, 1, 1, 1}));
  EXPECT_EQ(adjacency->first_half_edge[4], 2u);  // quad 0's corner 2
  std::uint32_t count = 0;
  EXPECT_EQ(QuadComponents(*adjacency, count), (std::vector<std::uint32_t>{0, 0, 0, 0}));
  EXPECT_EQ(count, 1u);
}

TEST(QuadAdjacency, ComponentsNumberedByTheirLowestQuad) {
  // Quads 0 and 2 share an edge; quad 1 is apart.
  auto adjacency = BuildQuadAdjacency(Quads(10, {0, 1, 2, 3, 6, 7, 8, 9, 1, 4, 5, 2}));
  ASSERT_TRUE(adjacency.ok());
  std::uint32_t count = 0;
  EXPECT_EQ(QuadComponents(*adjacency, count), (std::vector<std::uint32_t>{0, 1, 0}));
  EXPECT_EQ(count, 2u);
}

TEST(QuadAdjacency, Errors) {
  std::vector<std::int32_t> flipped = kGrid;
  std::swap(flipped[4 * 3 + 1], flipped[4 * 3 + 3]);  // quad 3 wound the other way
  std::vector<std::int32_t> fin = kGrid;
  fin.insert(fin.end(), {4, 1, 9, 10});  // a third quad on edge 1-4
  // In one pass, and in passes of one vertex's half-edges or a few.
  for (const std::size_t entries : {kAdjacencyBucketEntries, std::size_t{1}, std::size_t{5}}) {
    SCOPED_TRACE(entries);
    EXPECT_EQ(BuildQuadAdjacency(Quads(9, flipped), entries).status().message(),
              "quads.obj: faces 1 and 3 both run edge 5-4 from 5 to 4 (their windings disagree)");
    EXPECT_EQ(BuildQuadAdjacency(Quads(11, fin), entries).status().message(),
              "quads.obj: edge 1-4 has more than two faces (0, 1, 4)");
  }
  EXPECT_EQ(BuildQuadAdjacency(Quads(10, kGrid)).status().message(),
            "quads.obj: vertex 9 is used by no face");
  EXPECT_EQ(BuildQuadAdjacency(Quads(4, {0, 1, 2, 1})).status().message(),
            "quads.obj: face 0 uses vertex 1 twice");
}

// Against a map of the directed edges, on a grid with holes, numbered at random: every
// opposite, valence, boundary flag and lowest half-edge. Rejects an opposite that is another
// half-edge of the right vertices' quads, a boundary vertex not flagged, and a first half-edge
// that is not the lowest.
TEST(QuadAdjacency, AgreesWithAMapOfEdgesOnAShuffledGridWithHoles) {
  constexpr int kSide = 40;
  std::mt19937 random(7);
  std::vector<std::int32_t> label((kSide + 1) * (kSide + 1));
  std::iota(label.begin(), label.end(), 0);
  std::shuffle(label.begin(), label.end(), random);
  std::vector<std::array<std::int32_t, 4>> quads;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      if ((i * 7 + j * 3) % 11 == 0) continue;  // holes, some meeting at a corner only
      const auto at = [&](int x, int y) { return label[y * (kSide + 1) + x]; };
      std::array<std::int32_t, 4> q{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
      std::rotate(q.begin(), q.begin() + random() % 4, q.end());
      quads.push_back(q);
    }
  }
  std::shuffle(quads.begin(), quads.end(), random);
  // Vertices no quad uses are dropped (the adjacency rejects them), keeping the shuffle.
  std::vector<std::int32_t> renumber(label.size(), -1);
  int used = 0;
  for (int v = 0; v < static_cast<int>(label.size()); ++v) {
    for (const auto& q : quads) {
      if (std::find(q.begin(), q.end(), v) != q.end()) {
        renumber[v] = used++;
        break;
      }
    }
  }
  std::vector<std::int32_t> corners;
  for (const auto& q : quads) {
    for (std::int32_t v : q) corners.push_back(renumber[v]);
  }
  const Mesh mesh = Quads(used, corners);
  auto adjacency = BuildQuadAdjacency(mesh);
  ASSERT_TRUE(adjacency.ok()) << adjacency.status().message();

  std::map<std::pair<std::int32_t, std::int32_t>, std::uint32_t> edges;
  for (std::uint32_t h = 0; h < corners.size(); ++h) {
    edges[{corners[h], corners[QuadAdjacency::Next(h)]}] = h;
  }
  std::vector<std::uint16_t> valence(used, 0);
  std::vector<std::uint8_t> boundary(used, 0);
  std::vector<std::uint32_t> first(used, kNoHalfEdge);
  int boundary_edges = 0;
  for (std::uint32_t h = 0; h < corners.size(); ++h) {
    const std::int32_t a = corners[h], b = corners[QuadAdjacency::Next(h)];
    const auto other = edges.find({b, a});
    const std::uint32_t expected = other == edges.end() ? kNoHalfEdge : other->second;
    ASSERT_EQ(adjacency->opposite[h], expected) << "half-edge " << h;
    ++valence[a];
    first[a] = std::min(first[a], h);
    if (other == edges.end()) {
      boundary[a] = boundary[b] = 1;
      ++boundary_edges;
    }
  }
  EXPECT_GT(boundary_edges, 4 * kSide);  // the holes made boundaries inside too
  EXPECT_EQ(adjacency->valence, valence);
  EXPECT_EQ(adjacency->boundary, boundary);
  EXPECT_EQ(adjacency->first_half_edge, first);

  // Bucketed a pass of vertices at a time: every pass boundary, from one vertex a pass
  // (entries 1: each vertex alone) to a few passes, gives the same adjacency. A pass that
  // reads another's bucket entries, or resolves a vertex against the wrong bucket start,
  // changes an opposite.
  for (const std::size_t entries : {1, 3, 64, 1000, 4000}) {
    SCOPED_TRACE(entries);
    auto passes = BuildQuadAdjacency(mesh, entries);
    ASSERT_TRUE(passes.ok()) << passes.status().message();
    EXPECT_EQ(passes->opposite, adjacency->opposite);
    EXPECT_EQ(passes->valence, valence);
    EXPECT_EQ(passes->boundary, boundary);
    EXPECT_EQ(passes->first_half_edge, first);
  }
}

// The cache gives back what BuildQuadAdjacency builds: the first call builds and writes it, the
// second reads it; a damaged file (one byte of the opposites flipped, which would misguide the
// match) and a mesh of other faces are built again. A cache that returned a stale or damaged
// adjacency fails the comparisons.
TEST(QuadAdjacencyCache, ReadBackEqualsBuiltAndDamageIsRebuilt) {
  namespace fs = std::filesystem;
  const fs::path folder =
      fs::path(::testing::TempDir()) / ("dispex_adjacency_" + std::to_string(::getpid()));
  fs::remove_all(folder);
  const Mesh mesh = Quads(9, kGrid);
  const auto built = BuildQuadAdjacency(mesh);
  ASSERT_TRUE(built.ok());
  const auto same = [&](const QuadAdjacency& a) {
    return std::equal(a.opposite.begin(), a.opposite.end(), built->opposite.begin(),
                      built->opposite.end()) &&
           a.first_half_edge == built->first_half_edge && a.valence == built->valence &&
           a.boundary == built->boundary;
  };
  bool from_cache = true;
  auto first = CachedQuadAdjacency(mesh, folder.string(), from_cache);
  ASSERT_TRUE(first.ok());
  EXPECT_FALSE(from_cache);
  EXPECT_TRUE(same(*first));
  auto second = CachedQuadAdjacency(mesh, folder.string(), from_cache);
  ASSERT_TRUE(second.ok());
  EXPECT_TRUE(from_cache);
  EXPECT_TRUE(same(*second));

  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) files.push_back(entry.path());
  ASSERT_EQ(files.size(), 1u);
  {
    std::fstream file(files[0], std::ios::in | std::ios::out | std::ios::binary);
    file.seekg(8 + 16 + 16 + 4);  // magic, key, counts: the opposite of half-edge 1
    const char byte = static_cast<char>(file.get() ^ 1);
    file.seekp(8 + 16 + 16 + 4);
    file.put(byte);
  }
  auto damaged = CachedQuadAdjacency(mesh, folder.string(), from_cache);
  ASSERT_TRUE(damaged.ok());
  EXPECT_FALSE(from_cache);
  EXPECT_TRUE(same(*damaged));

  // The same vertices, one quad wound from another corner: other faces, another file.
  std::vector<std::int32_t> turned = kGrid;
  std::rotate(turned.begin(), turned.begin() + 1, turned.begin() + 4);
  auto other = CachedQuadAdjacency(Quads(9, turned), folder.string(), from_cache);
  ASSERT_TRUE(other.ok());
  EXPECT_FALSE(from_cache);
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator()), 2);
  fs::remove_all(folder);
}

}  // namespace
}  // namespace dispex::subdiv
