// The reader on files written by the reference Ptex library (tests/data/ptex): every value
// that tests/data/ptex/README.md states is checked, computed here from the README's
// formulas, never from the files.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

using ptex_test::FixturePath;
using ptex_test::FixtureT;

PtexFile OpenFixture(const std::string& name) {
  StatusOr<PtexFile> f = PtexFile::Open(FixturePath(name));
  EXPECT_TRUE(f.ok()) << f.status().message();
  return std::move(f).value();
}

struct Adj {
  int face, edge;
};
constexpr Adj kNone{-1, 0};

void ExpectFace(const PtexFile& file, int f, int ulog2, int vlog2, bool constant, bool subface,
                std::vector<Adj> adj) {
  SCOPED_TRACE("face " + std::to_string(f));
  const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
  EXPECT_EQ(info.ulog2, ulog2);
  EXPECT_EQ(info.vlog2, vlog2);
  EXPECT_EQ(info.constant, constant);
  EXPECT_EQ(info.subface, subface);
  EXPECT_FALSE(info.neighborhood_constant);
  EXPECT_FALSE(info.has_edits);
  for (std::size_t e = 0; e < adj.size(); ++e) {
    EXPECT_EQ(info.adjfaces[e], adj[e].face) << "edge " << e;
    if (adj[e].face >= 0) {
      EXPECT_EQ(info.adjedges[e], adj[e].edge) << "edge " << e;
    }
  }
}

float Avg(const PtexFile& file, int f, int channel = 0) {
  std::vector<float> v(static_cast<std::size_t>(file.header().num_channels));
  file.ConstantValue(PtexFaceId(f), v.data());
  return v[static_cast<std::size_t>(channel)];
}

// Level-0 texels must equal `expected` (interleaved) exactly.
void ExpectTexels(const PtexFile& file, int f, int level, const std::vector<float>& expected) {
  std::vector<float> t;
  Status s = file.ReadFace(PtexFaceId(f), level, t);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(t.size(), expected.size()) << "face " << f << " level " << level;
  for (std::size_t i = 0; i < t.size(); ++i) {
    ASSERT_EQ(t[i], expected[i]) << "face " << f << " level " << level << " value " << i;
  }
}

// The 2^L x 2^L block means of a level-0 face: what the README says quad reductions equal.
std::vector<float> BoxMean(const std::vector<float>& t, int ures, int vres, int nch, int level) {
  const int k = 1 << level, ru = ures / k, rv = vres / k;
  std::vector<float> out;
  for (int j = 0; j < rv; ++j) {
    for (int i = 0; i < ru; ++i) {
      for (int c = 0; c < nch; ++c) {
        double sum = 0;
        for (int y = 0; y < k; ++y) {
          for (int x = 0; x < k; ++x) sum += t[((j * k + y) * ures + i * k + x) * nch + c];
        }
        out.push_back(static_cast<float>(sum / (k * k)));
      }
    }
  }
  return out;
}

// Level entries in stored order, as (face, ulog2, vlog2) from BlockInfo.
void ExpectLevel(const PtexFile& file, int level, std::vector<std::array<int, 3>> entries) {
  SCOPED_TRACE("level " + std::to_string(level));
  ASSERT_LT(level, file.header().num_levels);
  EXPECT_EQ(file.levels()[std::size_t(level)].num_entries, static_cast<int>(entries.size()));
  for (const auto& [face, ulog2, vlog2] : entries) {
    ASSERT_GT(file.NumStoredLevels(PtexFaceId(face)), level) << "face " << face;
    PtexBlockInfo b = file.BlockInfo(PtexFaceId(face), level);
    EXPECT_EQ(b.ulog2, ulog2) << "face " << face;
    EXPECT_EQ(b.vlog2, vlog2) << "face " << face;
  }
}

TEST(PtexFixtureRead, Example2Faces) {
  PtexFile file = OpenFixture("example_2faces.ptx");
  const PtexHeaderInfo& h = file.header();
  EXPECT_EQ(h.mesh_type, PtexMeshType::kQuad);
  EXPECT_EQ(h.data_type, PtexDataType::kFloat);
  EXPECT_EQ(h.num_channels, 1);
  EXPECT_EQ(h.alpha_channel, -1);
  EXPECT_EQ(h.num_faces, 2);
  EXPECT_EQ(h.num_levels, 1);
  EXPECT_EQ(h.minor_version, 4);
  EXPECT_EQ(h.file_size, 235u);
  EXPECT_EQ(h.u_border, PtexBorderMode::kClamp);
  EXPECT_EQ(h.v_border, PtexBorderMode::kClamp);
  EXPECT_EQ(h.edge_filter, PtexEdgeFilterMode::kNone);
  EXPECT_FALSE(h.has_edits);
  EXPECT_TRUE(file.meta_data().empty());
  ExpectFace(file, 0, 2, 2, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 2, 2, true, false, {kNone, kNone, kNone, {0, 1}});
  ExpectTexels(file, 0, 0, ptex_test::FixtureFace(0, 4, 4));
  ExpectTexels(file, 1, 0, std::vector<float>(16, 2.5f));
  EXPECT_EQ(Avg(file, 0), 0.04541015625f);
  EXPECT_EQ(Avg(file, 1), 2.5f);
  PtexBlockInfo b = file.BlockInfo(PtexFaceId(0), 0);
  EXPECT_EQ(b.encoding, PtexBlockInfo::Encoding::kZipped);
  EXPECT_EQ(b.size, 55u);
  EXPECT_EQ(file.levels()[0].header_size, 14u);
  EXPECT_EQ(file.levels()[0].data_size, 69u);
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(0)), 1);
  EXPECT_TRUE(file.Validate().ok());
}

TEST(PtexFixtureRead, QuadFloat1) {
  PtexFile file = OpenFixture("quad_float1.ptx");
  EXPECT_EQ(file.header().num_faces, 4);
  EXPECT_EQ(file.header().num_levels, 3);
  EXPECT_TRUE(file.meta_data().empty());
  ExpectFace(file, 0, 3, 3, false, false, {kNone, {1, 3}, {2, 0}, kNone});
  ExpectFace(file, 1, 2, 4, false, false, {kNone, kNone, {3, 0}, {0, 1}});
  ExpectFace(file, 2, 2, 1, true, false, {{0, 2}, {3, 3}, kNone, kNone});
  ExpectFace(file, 3, 5, 4, false, false, {{1, 2}, kNone, kNone, {2, 1}});
  const std::vector<float> t0 = ptex_test::FixtureFace(0, 8, 8);
  const std::vector<float> t1 = ptex_test::FixtureFace(1, 4, 16);
  const std::vector<float> t3 = ptex_test::FixtureFace(3, 32, 16);
  ExpectTexels(file, 0, 0, t0);
  ExpectTexels(file, 1, 0, t1);
  ExpectTexels(file, 2, 0, std::vector<float>(8, 2.5f));
  ExpectTexels(file, 3, 0, t3);
  EXPECT_EQ(Avg(file, 0), 0.10595703125f);
  EXPECT_EQ(Avg(file, 1), 1.03955078125f);
  EXPECT_EQ(Avg(file, 2), 2.5f);
  EXPECT_EQ(Avg(file, 3), 3.47705078125f);
  // Reduction order 3, 0, 1, 2: level 1 = [3 at 16x8, 0 at 4x4], level 2 = [3 at 8x4].
  ExpectLevel(file, 1, {{3, 4, 3}, {0, 2, 2}});
  ExpectLevel(file, 2, {{3, 3, 2}});
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(0)), 2);
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(1)), 1);
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(2)), 1);
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(3)), 3);
  ExpectTexels(file, 3, 1, BoxMean(t3, 32, 16, 1, 1));
  ExpectTexels(file, 3, 2, BoxMean(t3, 32, 16, 1, 2));
  ExpectTexels(file, 0, 1, BoxMean(t0, 8, 8, 1, 1));
  std::vector<float> dummy;
  EXPECT_FALSE(file.ReadFace(PtexFaceId(1), 1, dummy).ok());  // not stored
  EXPECT_TRUE(file.Validate().ok());
}

TEST(PtexFixtureRead, QuadHalf1) {
  PtexFile file = OpenFixture("quad_half1.ptx");
  EXPECT_EQ(file.header().data_type, PtexDataType::kHalf);
  EXPECT_EQ(file.header().num_faces, 3);
  EXPECT_EQ(file.header().num_levels, 3);
  auto H = [](int f, int u, int v) {
    return static_cast<float>(f - 1) + static_cast<float>(u) / 16.0f -
           static_cast<float>(v) / 256.0f;
  };
  ExpectFace(file, 0, 3, 2, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 4, 4, false, false, {kNone, {2, 3}, kNone, {0, 1}});
  ExpectFace(file, 2, 3, 3, true, false, {kNone, kNone, kNone, {1, 1}});
  std::vector<float> t0, t1;
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 8; ++u) t0.push_back(H(0, u, v));
  for (int v = 0; v < 16; ++v)
    for (int u = 0; u < 16; ++u) t1.push_back(H(1, u, v));
  ExpectTexels(file, 0, 0, t0);
  ExpectTexels(file, 1, 0, t1);
  ExpectTexels(file, 2, 0, std::vector<float>(64, 0.75f));
  EXPECT_EQ(Avg(file, 0), -0.787109375f);
  EXPECT_EQ(Avg(file, 1), 0.439453125f);
  EXPECT_EQ(Avg(file, 2), 0.75f);
  // Bit patterns.
  std::vector<std::uint8_t> raw;
  ASSERT_TRUE(file.ReadFaceRaw(PtexFaceId(0), 0, raw).ok());
  EXPECT_EQ(ptex_test::LoadLE<std::uint16_t>(&raw[0]), 0xbc00);
  ASSERT_TRUE(file.ReadFaceRaw(PtexFaceId(1), 0, raw).ok());
  EXPECT_EQ(ptex_test::LoadLE<std::uint16_t>(&raw[2 * 1]), 0x2c00);   // (u=1, v=0)
  EXPECT_EQ(ptex_test::LoadLE<std::uint16_t>(&raw[2 * 16]), 0x9c00);  // (u=0, v=1)
  EXPECT_EQ(ptex_test::LoadLE<std::uint16_t>(file.ConstantValueRaw(PtexFaceId(2)).data()), 0x3a00);
  ExpectLevel(file, 1, {{1, 3, 3}});
  ExpectLevel(file, 2, {{1, 2, 2}});
  ExpectTexels(file, 1, 1, BoxMean(t1, 16, 16, 1, 1));
  ExpectTexels(file, 1, 2, BoxMean(t1, 16, 16, 1, 2));
  EXPECT_EQ(file.NumStoredLevels(PtexFaceId(0)), 1);
}

TEST(PtexFixtureRead, QuadFloat3) {
  PtexFile file = OpenFixture("quad_float3.ptx");
  EXPECT_EQ(file.header().num_channels, 3);
  EXPECT_EQ(file.header().alpha_channel, -1);
  EXPECT_EQ(file.header().num_levels, 2);
  auto C = [](int f, int u, int v, int c) {
    return static_cast<float>(f) + static_cast<float>(c) / 4.0f +
           static_cast<float>((c + 1) * u) / 64.0f - static_cast<float>(v) / 1024.0f;
  };
  ExpectFace(file, 0, 3, 3, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 2, 3, false, false, {kNone, kNone, kNone, {0, 1}});
  std::vector<float> t0, t1;
  for (int v = 0; v < 8; ++v)
    for (int u = 0; u < 8; ++u)
      for (int c = 0; c < 3; ++c) t0.push_back(C(0, u, v, c));
  for (int v = 0; v < 8; ++v)
    for (int u = 0; u < 4; ++u)
      for (int c = 0; c < 3; ++c) t1.push_back(C(1, u, v, c));
  ExpectTexels(file, 0, 0, t0);
  ExpectTexels(file, 1, 0, t1);
  const float avg0[3] = {0.05126953125f, 0.35595703125f, 0.66064453125f};
  const float avg1[3] = {1.02001953125f, 1.29345703125f, 1.56689453125f};
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(Avg(file, 0, c), avg0[c]);
    EXPECT_EQ(Avg(file, 1, c), avg1[c]);
  }
  ExpectLevel(file, 1, {{0, 2, 2}});
  ExpectTexels(file, 0, 1, BoxMean(t0, 8, 8, 3, 1));
  // In the file, the block holds channel 0 of all texels, then channel 1, then channel 2.
  const ptex_test::Sections s =
      ptex_test::ReadSections(ptex_test::ReadBytes(FixturePath("quad_float3.ptx")));
  const auto& block = s.levels[0].blocks[0];
  std::vector<std::uint8_t> planes = ptex_test::ZlibInflate(block.data(), block.size(), 64 * 12);
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i < 64; ++i) {
      ASSERT_EQ(ptex_test::LoadLE<float>(&planes[4 * (c * 64 + i)]), C(0, i % 8, i / 8, c));
    }
  }
}

TEST(PtexFixtureRead, TriangleFloat1) {
  PtexFile file = OpenFixture("tri_float1.ptx");
  EXPECT_EQ(file.header().mesh_type, PtexMeshType::kTriangle);
  EXPECT_EQ(file.header().num_faces, 4);
  EXPECT_EQ(file.header().num_levels, 3);
  ExpectFace(file, 0, 3, 3, false, false, {{2, 2}, {3, 0}, {1, 0}, kNone});
  ExpectFace(file, 1, 2, 2, false, false, {{0, 2}, {3, 2}, {2, 0}, kNone});
  ExpectFace(file, 2, 2, 2, true, false, {{1, 2}, {3, 1}, {0, 0}, kNone});
  ExpectFace(file, 3, 4, 4, false, false, {{0, 1}, {2, 1}, {1, 1}, kNone});
  for (int f = 0; f < 4; ++f) EXPECT_EQ(file.face_info(PtexFaceId(f)).adjfaces[3], -1);
  const std::vector<float> t0 = ptex_test::FixtureFace(0, 8, 8);
  const std::vector<float> t3 = ptex_test::FixtureFace(3, 16, 16);
  ExpectTexels(file, 0, 0, t0);
  ExpectTexels(file, 1, 0, ptex_test::FixtureFace(1, 4, 4));
  ExpectTexels(file, 2, 0, std::vector<float>(16, -1.5f));
  ExpectTexels(file, 3, 0, t3);
  EXPECT_EQ(Avg(file, 0), 0.10595703125f);
  EXPECT_EQ(Avg(file, 1), 1.04541015625f);
  EXPECT_EQ(Avg(file, 2), -1.5f);
  EXPECT_EQ(Avg(file, 3), 3.22705078125f);
  ExpectLevel(file, 1, {{3, 3, 3}, {0, 2, 2}});
  ExpectLevel(file, 2, {{3, 2, 2}});
  // Triangle rule (docs/ptex.md, "The triangle rule"), written out here independently of the
  // library.
  auto tri = [](const std::vector<float>& s, int n) {
    std::vector<float> r;
    auto at = [&](int u, int v) { return static_cast<double>(s[std::size_t(v * n + u)]); };
    for (int y = 0; y < n / 2; ++y)
      for (int x = 0; x < n / 2; ++x)
        r.push_back(static_cast<float>((at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) +
                                        at(2 * x, 2 * y + 1) + at(n - 1 - 2 * y, n - 1 - 2 * x)) /
                                       4));
    return r;
  };
  ExpectTexels(file, 3, 1, tri(t3, 16));
  ExpectTexels(file, 3, 2, tri(tri(t3, 16), 8));
  ExpectTexels(file, 0, 1, tri(t0, 8));
}

TEST(PtexFixtureRead, QuadMetaEveryType) {
  PtexFile file = OpenFixture("quad_meta.ptx");
  const PtexHeaderInfo& h = file.header();
  EXPECT_EQ(h.u_border, PtexBorderMode::kBlack);
  EXPECT_EQ(h.v_border, PtexBorderMode::kPeriodic);
  EXPECT_EQ(h.edge_filter, PtexEdgeFilterMode::kTangentVector);
  EXPECT_EQ(h.num_levels, 1);
  ExpectFace(file, 0, 2, 2, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 1, 2, false, false, {kNone, kNone, kNone, {0, 1}});
  ExpectTexels(file, 0, 0, ptex_test::FixtureFace(0, 4, 4));
  ExpectTexels(file, 1, 0, ptex_test::FixtureFace(1, 2, 4));
  EXPECT_EQ(Avg(file, 0), 0.04541015625f);
  EXPECT_EQ(Avg(file, 1), 1.01416015625f);

  auto meta = file.meta_data();
  ASSERT_EQ(meta.size(), 11u);
  const char* keys[] = {"author",
                        "empty",
                        "int8s",
                        "int16s",
                        "int32s",
                        "floats",
                        "doubles",
                        "PtexFaceVertCounts",
                        "PtexFaceVertIndices",
                        "PtexVertPositions",
                        "big_floats"};
  const PtexMetaType types[] = {PtexMetaType::kString, PtexMetaType::kString, PtexMetaType::kInt8,
                                PtexMetaType::kInt16,  PtexMetaType::kInt32,  PtexMetaType::kFloat,
                                PtexMetaType::kDouble, PtexMetaType::kInt32,  PtexMetaType::kInt32,
                                PtexMetaType::kFloat,  PtexMetaType::kFloat};
  for (std::size_t i = 0; i < 11; ++i) {
    EXPECT_EQ(meta[i].key, keys[i]);
    EXPECT_EQ(meta[i].type, types[i]) << keys[i];
    EXPECT_EQ(meta[i].large, i == 10) << keys[i];
  }
  EXPECT_EQ(meta[0].AsString(), "ptexcheck fixture");
  EXPECT_EQ(meta[0].bytes.size(), 18u);
  EXPECT_EQ(meta[1].AsString(), "");
  EXPECT_EQ(meta[1].bytes.size(), 1u);
  EXPECT_EQ(meta[2].AsInt8(), (std::vector<std::int8_t>{-128, -1, 0, 1, 127}));
  EXPECT_EQ(meta[3].AsInt16(), (std::vector<std::int16_t>{-32768, -2, 0, 2, 32767}));
  EXPECT_EQ(meta[4].AsInt32(), (std::vector<std::int32_t>{-2147483647 - 1, -3, 0, 3, 2147483647}));
  std::vector<float> floats = meta[5].AsFloat();
  ASSERT_EQ(floats.size(), 4u);
  EXPECT_EQ(floats[0], 0.5f);
  EXPECT_EQ(floats[1], -1.25f);
  EXPECT_EQ(floats[2], 1024.0f);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(floats[3]), 0x3dcccccdu);
  EXPECT_EQ(meta[6].AsDouble(), (std::vector<double>{3.141592653589793, -2.5, 1e100}));
  EXPECT_EQ(meta[7].AsInt32(), (std::vector<std::int32_t>{4, 4}));
  EXPECT_EQ(meta[8].AsInt32(), (std::vector<std::int32_t>{0, 1, 4, 3, 1, 2, 5, 4}));
  EXPECT_EQ(meta[9].AsFloat(),
            (std::vector<float>{0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0}));
  std::vector<float> big = meta[10].AsFloat();
  ASSERT_EQ(big.size(), 300u);
  for (int k = 0; k < 300; ++k) ASSERT_EQ(big[std::size_t(k)], static_cast<float>(k) * 0.5f);
  EXPECT_EQ(meta[10].count(), 300u);
  ASSERT_NE(file.FindMetaData("doubles"), nullptr);
  EXPECT_EQ(file.FindMetaData("doubles")->count(), 3u);
  EXPECT_EQ(file.FindMetaData("missing"), nullptr);
  // Header fields the README states.
  const std::vector<std::uint8_t> bytes = ptex_test::ReadBytes(FixturePath("quad_meta.ptx"));
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&bytes[60]), 371u);      // metadatamemsize
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&bytes[64 + 12]), 21u);  // lmdheadermemsize
  const ptex_test::Sections s = ptex_test::ReadSections(bytes);
  EXPECT_EQ(s.barrier, std::vector<std::uint8_t>(8, 0));
}

TEST(PtexFixtureRead, CatmullClarkPentagonTriangle) {
  PtexFile file = OpenFixture("cc_pentagon_triangle.ptx");
  EXPECT_EQ(file.header().num_faces, 10);
  EXPECT_EQ(file.header().num_levels, 2);
  ExpectFace(file, 0, 3, 3, false, false, {kNone, {1, 3}, {6, 0}, kNone});
  ExpectFace(file, 1, 2, 2, false, true, {kNone, {2, 2}, {5, 1}, {0, 1}});
  ExpectFace(file, 2, 2, 2, false, true, {kNone, {3, 2}, {1, 1}, kNone});
  ExpectFace(file, 3, 2, 2, true, true, {{7, 3}, {4, 2}, {2, 1}, kNone});
  ExpectFace(file, 4, 1, 2, false, true, {{6, 1}, {5, 2}, {3, 1}, {9, 0}});
  ExpectFace(file, 5, 2, 2, false, true, {{0, 1}, {1, 2}, {4, 1}, {6, 1}});
  ExpectFace(file, 6, 4, 3, false, false, {{0, 2}, {5, 3}, kNone, kNone});
  ExpectFace(file, 7, 2, 2, false, true, {kNone, {8, 2}, {9, 1}, {3, 0}});
  ExpectFace(file, 8, 2, 1, false, true, {kNone, {9, 2}, {7, 1}, kNone});
  ExpectFace(file, 9, 1, 2, false, true, {{4, 3}, {7, 2}, {8, 1}, kNone});
  const float avg[10] = {0.10595703125f, 1.04541015625f, 2.04541015625f, 3.5f,
                         4.01416015625f, 5.04541015625f, 6.23095703125f, 7.04541015625f,
                         8.04638671875f, 9.01416015625f};
  for (int f = 0; f < 10; ++f) {
    EXPECT_EQ(Avg(file, f), avg[f]) << "face " << f;
    const PtexFaceInfo& info = file.face_info(PtexFaceId(f));
    if (f == 3) {
      ExpectTexels(file, f, 0, std::vector<float>(16, 3.5f));
    } else {
      ExpectTexels(file, f, 0, ptex_test::FixtureFace(f, info.ures(), info.vres()));
    }
  }
  ExpectLevel(file, 1, {{0, 2, 2}, {6, 3, 2}});
  ExpectTexels(file, 6, 1, BoxMean(ptex_test::FixtureFace(6, 16, 8), 16, 8, 1, 1));
  const PtexMetaItem* counts = file.FindMetaData("PtexFaceVertCounts");
  const PtexMetaItem* indices = file.FindMetaData("PtexFaceVertIndices");
  const PtexMetaItem* positions = file.FindMetaData("PtexVertPositions");
  ASSERT_TRUE(counts && indices && positions);
  EXPECT_EQ(counts->AsInt32(), (std::vector<std::int32_t>{4, 5, 4, 3}));
  EXPECT_EQ(indices->AsInt32(),
            (std::vector<std::int32_t>{0, 1, 4, 3, 1, 2, 5, 7, 4, 3, 4, 7, 6, 5, 8, 7}));
  EXPECT_EQ(positions->AsFloat(),
            (std::vector<float>{0, 0, 0, 1, 0,    0, 2, 0,    0, 0, 1,    0,    1, 1,
                                0, 2, 1, 0, 0.5f, 2, 0, 1.5f, 2, 0, 2.5f, 1.5f, 0}));
}

TEST(PtexFixtureRead, TiledFaceWithConstantTile) {
  PtexFile file = OpenFixture("quad_float1_tiled.ptx");
  EXPECT_EQ(file.header().num_faces, 2);
  EXPECT_EQ(file.header().num_levels, 6);
  ExpectFace(file, 0, 8, 7, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 2, 2, false, false, {kNone, kNone, kNone, {0, 1}});
  std::vector<float> w;
  for (int v = 0; v < 128; ++v) {
    for (int u = 0; u < 256; ++u) {
      w.push_back(u < 128 ? 1.0f
                          : static_cast<float>(u / 16) / 8.0f + static_cast<float>(v / 16) / 64.0f);
    }
  }
  ExpectTexels(file, 0, 0, w);
  ExpectTexels(file, 1, 0, ptex_test::FixtureFace(1, 4, 4));
  EXPECT_EQ(Avg(file, 0), 1.24609375f);
  EXPECT_EQ(Avg(file, 1), 1.04541015625f);
  PtexBlockInfo b = file.BlockInfo(PtexFaceId(0), 0);
  EXPECT_EQ(b.encoding, PtexBlockInfo::Encoding::kTiled);
  EXPECT_EQ(b.num_tiles, 2);
  EXPECT_EQ(b.tile_ulog2, 7);
  EXPECT_EQ(b.tile_vlog2, 7);
  EXPECT_EQ(b.size, 479u);
  EXPECT_EQ(file.BlockInfo(PtexFaceId(1), 0).encoding, PtexBlockInfo::Encoding::kZipped);
  for (int l = 1; l <= 5; ++l) {
    ExpectLevel(file, l, {{0, 8 - l, 7 - l}});
    EXPECT_NE(file.BlockInfo(PtexFaceId(0), l).encoding, PtexBlockInfo::Encoding::kTiled);
    ExpectTexels(file, 0, l, BoxMean(w, 256, 128, 1, l));
  }
  // The tile header as the README gives it: tile 0 constant (4 bytes), tile 1 zipped (453).
  const ptex_test::Sections s =
      ptex_test::ReadSections(ptex_test::ReadBytes(FixturePath("quad_float1_tiled.ptx")));
  const auto& blk = s.levels[0].blocks[0];
  ASSERT_EQ(blk.size(), 479u);
  EXPECT_EQ(blk[0], 7);
  EXPECT_EQ(blk[1], 7);
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&blk[2]), 16u);
  std::vector<std::uint8_t> th = ptex_test::ZlibInflate(&blk[6], 16, 8);
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&th[0]), 4u);
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&th[4]), 0x400001c5u);
}

TEST(PtexFixtureRead, Uint8RgbaWithAlpha) {
  PtexFile file = OpenFixture("quad_uint8_rgba.ptx");
  const PtexHeaderInfo& h = file.header();
  EXPECT_EQ(h.data_type, PtexDataType::kUint8);
  EXPECT_EQ(h.num_channels, 4);
  EXPECT_EQ(h.alpha_channel, 3);
  EXPECT_EQ(h.num_levels, 2);
  ExpectFace(file, 0, 3, 3, false, false, {kNone, {1, 3}, kNone, kNone});
  ExpectFace(file, 1, 2, 2, true, false, {kNone, kNone, kNone, {0, 1}});
  std::vector<std::uint8_t> expect0;
  for (int v = 0; v < 8; ++v) {
    for (int u = 0; u < 8; ++u) {
      expect0.push_back(static_cast<std::uint8_t>(32 * u));
      expect0.push_back(static_cast<std::uint8_t>(32 * v));
      expect0.push_back(static_cast<std::uint8_t>(255 - 16 * (u + v)));
      expect0.push_back(u < 4 ? 255 : 128);
    }
  }
  std::vector<std::uint8_t> raw;
  ASSERT_TRUE(file.ReadFaceRaw(PtexFaceId(0), 0, raw).ok());
  EXPECT_EQ(raw, expect0);
  EXPECT_EQ(file.BlockInfo(PtexFaceId(0), 0).encoding, PtexBlockInfo::Encoding::kDiffZipped);
  ASSERT_TRUE(file.ReadFaceRaw(PtexFaceId(1), 0, raw).ok());
  for (int t = 0; t < 16; ++t) {
    EXPECT_EQ(raw[std::size_t(4 * t)], 10);
    EXPECT_EQ(raw[std::size_t(4 * t + 3)], 255);
  }
  auto cv = file.ConstantValueRaw(PtexFaceId(0));
  EXPECT_EQ(std::vector<std::uint8_t>(cv.begin(), cv.end()),
            (std::vector<std::uint8_t>{90, 112, 153, 191}));
  cv = file.ConstantValueRaw(PtexFaceId(1));
  EXPECT_EQ(std::vector<std::uint8_t>(cv.begin(), cv.end()),
            (std::vector<std::uint8_t>{10, 20, 30, 255}));
  // Level 1: premultiplied (floor(c * a / 255)), then floor-averaged 2x2.
  ExpectLevel(file, 1, {{0, 2, 2}});
  std::vector<std::uint8_t> level1;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) {
      for (int c = 0; c < 4; ++c) {
        int sum = 0;
        for (int y = 0; y < 2; ++y) {
          for (int x = 0; x < 2; ++x) {
            const std::size_t t = std::size_t((2 * j + y) * 8 + 2 * i + x) * 4;
            const int a = expect0[t + 3];
            sum += c == 3 ? a : expect0[t + std::size_t(c)] * a / 255;
          }
        }
        level1.push_back(static_cast<std::uint8_t>(sum / 4));
      }
    }
  }
  ASSERT_TRUE(file.ReadFaceRaw(PtexFaceId(0), 1, raw).ok());
  EXPECT_EQ(raw, level1);
  // Float reads normalise by 255.
  std::vector<float> f;
  ASSERT_TRUE(file.ReadFace(PtexFaceId(0), 0, f).ok());
  EXPECT_EQ(f[2], 255.0f / 255.0f);
  EXPECT_FLOAT_EQ(f[4], 32.0f / 255.0f);
}

}  // namespace
}  // namespace dispex
