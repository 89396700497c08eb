// The writer against the reference writer: each fixture's content (from its README) is
// written by dispex and compared with the file the reference library wrote.
//
// With zlib at level 6 (the reference's compressor and level) the files must be identical byte for
// byte, except that dispex always writes the 8-byte barrier, which the reference omits without meta
// data (docs/ptex.md, "File layout"): then ours = reference + 8 zero bytes, with editdatapos moved
// by 8. With libdeflate (the default) compressed bytes differ, so everything else is compared:
// header fields other than sizes, and every section inflated by zlib.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "ptex/zlib_block.h"
#include "ptex_test_util.h"
#include "subdiv_ptex_faces.h"

namespace dispex {
namespace {

using ptex_test::FixturePath;
using ptex_test::LoadLE;
using ptex_test::ReadBytes;
using ptex_test::TempDir;

PtexFaceInfo Face(int ulog2, int vlog2, std::array<int, 4> adj, std::array<int, 4> edges,
                  bool subface = false) {
  PtexFaceInfo f;
  f.ulog2 = static_cast<std::int8_t>(ulog2);
  f.vlog2 = static_cast<std::int8_t>(vlog2);
  for (int e = 0; e < 4; ++e) {
    f.adjfaces[std::size_t(e)] = adj[std::size_t(e)];
    f.adjedges[std::size_t(e)] = static_cast<std::uint8_t>(edges[std::size_t(e)]);
  }
  f.subface = subface;
  return f;
}

// Writes a file: `fill` sets the faces and meta data.
std::vector<std::uint8_t> Write(const TempDir& dir, PtexWriterOptions options, int nfaces,
                                const std::function<void(PtexWriter&)>& fill) {
  const std::string path = (dir / "out.ptx").string();
  StatusOr<PtexWriter> w = PtexWriter::Create(path, options, nfaces);
  EXPECT_TRUE(w.ok()) << w.status().message();
  fill(*w);
  Status s = w->Finish();
  EXPECT_TRUE(s.ok()) << s.message();
  return ReadBytes(path);
}

void Check(const Status& s) {
  ASSERT_TRUE(s.ok()) << s.message();
}

// ---- The fixtures' content, from tests/data/ptex/README.md ----

struct FixtureCase {
  std::string file;
  PtexWriterOptions options;
  int nfaces;
  std::function<void(PtexWriter&)> fill;
};
void PrintTo(const FixtureCase& c, std::ostream* os) {
  *os << c.file;
}

std::vector<float> HalfFace(int f, int ures, int vres) {
  std::vector<float> t;
  for (int v = 0; v < vres; ++v)
    for (int u = 0; u < ures; ++u)
      t.push_back(static_cast<float>(f - 1) + static_cast<float>(u) / 16.0f -
                  static_cast<float>(v) / 256.0f);
  return t;
}

std::vector<FixtureCase> Fixtures() {
  std::vector<FixtureCase> cases;
  {
    FixtureCase c{"example_2faces.ptx", {}, 2, nullptr};
    c.fill = [](PtexWriter& w) {
      Check(w.SetFace(PtexFaceId(0), Face(2, 2, {-1, 1, -1, -1}, {0, 3, 0, 0}),
                      ptex_test::FixtureFace(0, 4, 4)));
      Check(w.SetFace(PtexFaceId(1), Face(2, 2, {-1, -1, -1, 0}, {0, 0, 0, 1}),
                      std::vector<float>(16, 2.5f)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_float1.ptx", {}, 4, nullptr};
    c.fill = [](PtexWriter& w) {
      Check(w.SetFace(PtexFaceId(3), Face(5, 4, {1, -1, -1, 2}, {2, 0, 0, 1}),
                      ptex_test::FixtureFace(3, 32, 16)));
      Check(w.SetFace(PtexFaceId(0), Face(3, 3, {-1, 1, 2, -1}, {0, 3, 0, 0}),
                      ptex_test::FixtureFace(0, 8, 8)));
      Check(w.SetConstantFace(PtexFaceId(2), Face(2, 1, {0, 3, -1, -1}, {2, 3, 0, 0}),
                              std::vector<float>{2.5f}));
      Check(w.SetFace(PtexFaceId(1), Face(2, 4, {-1, -1, 3, 0}, {0, 0, 0, 1}),
                      ptex_test::FixtureFace(1, 4, 16)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_half1.ptx", {}, 3, nullptr};
    c.options.data_type = PtexDataType::kHalf;
    c.fill = [](PtexWriter& w) {
      Check(w.SetFace(PtexFaceId(0), Face(3, 2, {-1, 1, -1, -1}, {0, 3, 0, 0}), HalfFace(0, 8, 4)));
      Check(
          w.SetFace(PtexFaceId(1), Face(4, 4, {-1, 2, -1, 0}, {0, 3, 0, 1}), HalfFace(1, 16, 16)));
      Check(w.SetFace(PtexFaceId(2), Face(3, 3, {-1, -1, -1, 1}, {0, 0, 0, 1}),
                      std::vector<float>(64, 0.75f)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_float3.ptx", {}, 2, nullptr};
    c.options.num_channels = 3;
    c.fill = [](PtexWriter& w) {
      auto face = [](int f, int ures, int vres) {
        std::vector<float> t;
        for (int v = 0; v < vres; ++v)
          for (int u = 0; u < ures; ++u)
            for (int ch = 0; ch < 3; ++ch)
              t.push_back(static_cast<float>(f) + static_cast<float>(ch) / 4.0f +
                          static_cast<float>((ch + 1) * u) / 64.0f -
                          static_cast<float>(v) / 1024.0f);
        return t;
      };
      Check(w.SetFace(PtexFaceId(0), Face(3, 3, {-1, 1, -1, -1}, {0, 3, 0, 0}), face(0, 8, 8)));
      Check(w.SetFace(PtexFaceId(1), Face(2, 3, {-1, -1, -1, 0}, {0, 0, 0, 1}), face(1, 4, 8)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"tri_float1.ptx", {}, 4, nullptr};
    c.options.mesh_type = PtexMeshType::kTriangle;
    c.fill = [](PtexWriter& w) {
      Check(w.SetFace(PtexFaceId(0), Face(3, 3, {2, 3, 1, -1}, {2, 0, 0, 0}),
                      ptex_test::FixtureFace(0, 8, 8)));
      Check(w.SetFace(PtexFaceId(1), Face(2, 2, {0, 3, 2, -1}, {2, 2, 0, 0}),
                      ptex_test::FixtureFace(1, 4, 4)));
      Check(w.SetConstantFace(PtexFaceId(2), Face(2, 2, {1, 3, 0, -1}, {2, 1, 0, 0}),
                              std::vector<float>{-1.5f}));
      Check(w.SetFace(PtexFaceId(3), Face(4, 4, {0, 2, 1, -1}, {1, 1, 1, 0}),
                      ptex_test::FixtureFace(3, 16, 16)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_meta.ptx", {}, 2, nullptr};
    c.options.u_border = PtexBorderMode::kBlack;
    c.options.v_border = PtexBorderMode::kPeriodic;
    c.options.edge_filter = PtexEdgeFilterMode::kTangentVector;
    c.fill = [](PtexWriter& w) {
      Check(w.SetFace(PtexFaceId(0), Face(2, 2, {-1, 1, -1, -1}, {0, 3, 0, 0}),
                      ptex_test::FixtureFace(0, 4, 4)));
      Check(w.SetFace(PtexFaceId(1), Face(1, 2, {-1, -1, -1, 0}, {0, 0, 0, 1}),
                      ptex_test::FixtureFace(1, 2, 4)));
      Check(w.AddMetaData("author", "ptexcheck fixture"));
      Check(w.AddMetaData("empty", ""));
      const std::vector<std::int8_t> i8 = {-128, -1, 0, 1, 127};
      const std::vector<std::int16_t> i16 = {-32768, -2, 0, 2, 32767};
      const std::vector<std::int32_t> i32 = {-2147483647 - 1, -3, 0, 3, 2147483647};
      const std::vector<float> f = {0.5f, -1.25f, 1024.0f, 0.1f};
      const std::vector<double> d = {3.141592653589793, -2.5, 1e100};
      Check(w.AddMetaData("int8s", std::span<const std::int8_t>(i8)));
      Check(w.AddMetaData("int16s", std::span<const std::int16_t>(i16)));
      Check(w.AddMetaData("int32s", std::span<const std::int32_t>(i32)));
      Check(w.AddMetaData("floats", std::span<const float>(f)));
      Check(w.AddMetaData("doubles", std::span<const double>(d)));
      Mesh mesh;
      mesh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
      mesh.face_offsets = {0, 4, 8};
      mesh.face_indices = {0, 1, 4, 3, 1, 2, 5, 4};
      Check(AddMeshMetaData(w, mesh));
      std::vector<float> big;
      for (int k = 0; k < 300; ++k) big.push_back(static_cast<float>(k) * 0.5f);
      Check(w.AddMetaData("big_floats", std::span<const float>(big)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"cc_pentagon_triangle.ptx", {}, 10, nullptr};
    c.fill = [](PtexWriter& w) {
      Mesh mesh;
      mesh.positions = {{0, 0, 0}, {1, 0, 0},    {2, 0, 0},    {0, 1, 0},      {1, 1, 0},
                        {2, 1, 0}, {0.5f, 2, 0}, {1.5f, 2, 0}, {2.5f, 1.5f, 0}};
      mesh.face_offsets = {0, 4, 9, 13, 16};
      mesh.face_indices = {0, 1, 4, 3, 1, 2, 5, 7, 4, 3, 4, 7, 6, 5, 8, 7};
      StatusOr<SubdivPtexFaces> layout = ComputeSubdivPtexFaces(mesh);
      ASSERT_TRUE(layout.ok()) << layout.status().message();
      ASSERT_EQ(layout->num_faces(), 10);
      const int res[10][2] = {{3, 3}, {2, 2}, {2, 2}, {2, 2}, {1, 2},
                              {2, 2}, {4, 3}, {2, 2}, {2, 1}, {1, 2}};
      for (int f = 0; f < 10; ++f) {
        PtexFaceInfo info = layout->faces[std::size_t(f)];
        info.ulog2 = static_cast<std::int8_t>(res[f][0]);
        info.vlog2 = static_cast<std::int8_t>(res[f][1]);
        if (f == 3) {
          Check(w.SetConstantFace(PtexFaceId(f), info, std::vector<float>{3.5f}));
        } else {
          Check(
              w.SetFace(PtexFaceId(f), info, ptex_test::FixtureFace(f, info.ures(), info.vres())));
        }
      }
      Check(AddMeshMetaData(w, mesh));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_float1_tiled.ptx", {}, 2, nullptr};
    c.fill = [](PtexWriter& w) {
      std::vector<float> t;
      for (int v = 0; v < 128; ++v)
        for (int u = 0; u < 256; ++u)
          t.push_back(u < 128
                          ? 1.0f
                          : static_cast<float>(u / 16) / 8.0f + static_cast<float>(v / 16) / 64.0f);
      Check(w.SetFace(PtexFaceId(0), Face(8, 7, {-1, 1, -1, -1}, {0, 3, 0, 0}), t));
      Check(w.SetFace(PtexFaceId(1), Face(2, 2, {-1, -1, -1, 0}, {0, 0, 0, 1}),
                      ptex_test::FixtureFace(1, 4, 4)));
    };
    cases.push_back(c);
  }
  {
    FixtureCase c{"quad_uint8_rgba.ptx", {}, 2, nullptr};
    c.options.data_type = PtexDataType::kUint8;
    c.options.num_channels = 4;
    c.options.alpha_channel = 3;
    c.fill = [](PtexWriter& w) {
      std::vector<std::uint8_t> t;
      for (int v = 0; v < 8; ++v)
        for (int u = 0; u < 8; ++u) {
          t.push_back(static_cast<std::uint8_t>(32 * u));
          t.push_back(static_cast<std::uint8_t>(32 * v));
          t.push_back(static_cast<std::uint8_t>(255 - 16 * (u + v)));
          t.push_back(u < 4 ? 255 : 128);
        }
      Check(w.SetFaceRaw(PtexFaceId(0), Face(3, 3, {-1, 1, -1, -1}, {0, 3, 0, 0}), t));
      std::vector<std::uint8_t> c1;
      for (int i = 0; i < 16; ++i) c1.insert(c1.end(), {10, 20, 30, 255});
      Check(w.SetFaceRaw(PtexFaceId(1), Face(2, 2, {-1, -1, -1, 0}, {0, 0, 0, 1}), c1));
    };
    cases.push_back(c);
  }
  return cases;
}

class PtexFixtureWrite : public ::testing::TestWithParam<FixtureCase> {};

bool HasMetaData(const std::vector<std::uint8_t>& b) {
  return LoadLE<std::uint32_t>(&b[56]) != 0 || LoadLE<std::uint32_t>(&b[64 + 8]) != 0;
}

TEST_P(PtexFixtureWrite, ZlibLevel6IsByteIdenticalToTheReference) {
  const FixtureCase& c = GetParam();
  TempDir dir;
  PtexWriterOptions options = c.options;
  options.compressor = PtexCompressor::kZlib;
  options.compression_level = 6;
  const std::vector<std::uint8_t> ours = Write(dir, options, c.nfaces, c.fill);
  const std::vector<std::uint8_t> ref = ReadBytes(FixturePath(c.file));
  ASSERT_GE(ref.size(), 104u);
  if (HasMetaData(ref)) {
    EXPECT_EQ(ours, ref);
    return;
  }
  // The reference omits the barrier without meta data; everything else is identical.
  ASSERT_EQ(ours.size(), ref.size() + 8);
  EXPECT_TRUE(std::equal(ref.begin(), ref.begin() + 96, ours.begin())) << "header";
  EXPECT_EQ(LoadLE<std::uint64_t>(&ref[96]), ref.size());
  EXPECT_EQ(LoadLE<std::uint64_t>(&ours[96]), ours.size());
  EXPECT_TRUE(std::equal(ref.begin() + 104, ref.end(), ours.begin() + 104)) << "sections";
  EXPECT_EQ(std::vector<std::uint8_t>(ours.end() - 8, ours.end()), std::vector<std::uint8_t>(8, 0));
}

// Decoded pieces of a face block: constant texels raw, zipped blocks inflated by zlib, tiles
// recursively; encodings included.
std::vector<std::vector<std::uint8_t>> BlockPieces(const std::vector<std::uint8_t>& block,
                                                   std::uint32_t fdh, std::size_t expected) {
  std::vector<std::vector<std::uint8_t>> pieces;
  const std::uint32_t enc = fdh >> 30;
  pieces.push_back({static_cast<std::uint8_t>(enc)});
  if (enc == 0) {
    pieces.push_back(block);
  } else if (enc == 1 || enc == 2) {
    pieces.push_back(ptex_test::ZlibInflate(block.data(), block.size(), expected));
    // The library's own decoder (libdeflate) must agree with zlib.
    std::vector<std::uint8_t> mine(expected);
    EXPECT_EQ(ptex::Inflate(block, mine), "");
    EXPECT_EQ(mine, pieces.back());
  } else {
    const int tu = block[0], tv = block[1];
    const std::uint32_t ths = LoadLE<std::uint32_t>(&block[2]);
    pieces.push_back({block[0], block[1]});
    // The number of tiles follows from the sizes: the header inflates to 4 bytes per tile.
    std::size_t ntiles = 0;
    for (std::size_t n = 1; n <= 1u << 16; n *= 2) {
      z_stream zs{};
      std::vector<std::uint8_t> tmp(4 * n + 1);
      inflateInit(&zs);
      zs.next_in = const_cast<Bytef*>(&block[6]);
      zs.avail_in = ths;
      zs.next_out = tmp.data();
      zs.avail_out = static_cast<uInt>(tmp.size());
      const int rc = inflate(&zs, Z_FINISH);
      inflateEnd(&zs);
      if (rc == Z_STREAM_END) {
        ntiles = zs.total_out / 4;
        break;
      }
    }
    std::vector<std::uint8_t> th = ptex_test::ZlibInflate(&block[6], ths, 4 * ntiles);
    std::size_t pos = 6 + ths;
    const std::size_t tile_bytes = expected / ntiles;
    (void)tu;
    (void)tv;
    for (std::size_t t = 0; t < ntiles; ++t) {
      const std::uint32_t tfdh = LoadLE<std::uint32_t>(&th[4 * t]);
      const std::uint32_t size = tfdh & 0x3fffffff;
      std::vector<std::uint8_t> tb(block.begin() + static_cast<std::ptrdiff_t>(pos),
                                   block.begin() + static_cast<std::ptrdiff_t>(pos + size));
      for (auto& p : BlockPieces(tb, tfdh, tile_bytes)) pieces.push_back(p);
      pos += size;
    }
    EXPECT_EQ(pos, block.size());
  }
  return pieces;
}

TEST_P(PtexFixtureWrite, LibdeflateGivesTheSameContent) {
  const FixtureCase& c = GetParam();
  TempDir dir;
  const std::vector<std::uint8_t> ours = Write(dir, c.options, c.nfaces, c.fill);
  const std::vector<std::uint8_t> ref = ReadBytes(FixturePath(c.file));
  // Header: every field but the compressed sizes (32..40, 48..60) and, in the extended
  // header, the large meta data zip sizes and editdatapos.
  auto fields = [](const std::vector<std::uint8_t>& b) {
    std::vector<std::uint8_t> f(b.begin(), b.begin() + 104);
    std::fill(f.begin() + 32, f.begin() + 40, 0);
    std::fill(f.begin() + 48, f.begin() + 60, 0);
    std::fill(f.begin() + 64 + 8, f.begin() + 64 + 12, 0);
    std::fill(f.begin() + 64 + 16, f.begin() + 64 + 24, 0);
    std::fill(f.begin() + 96, f.begin() + 104, 0);
    return f;
  };
  EXPECT_EQ(fields(ours), fields(ref));
  EXPECT_EQ(LoadLE<std::uint64_t>(&ours[96]), ours.size());
  const ptex_test::Sections a = ptex_test::ReadSections(ours);
  const ptex_test::Sections b = ptex_test::ReadSections(ref);
  EXPECT_EQ(a.face_info, b.face_info);
  EXPECT_EQ(a.const_data, b.const_data);
  ASSERT_EQ(a.levels.size(), b.levels.size());
  const std::size_t pixel = std::size_t(ptex_test::DataSizeOf(a.datatype)) * a.nchannels;
  // Entry order of each level is checked through the inflated blocks: same content in the
  // same order. Expected sizes come from the face records.
  std::vector<std::int32_t> order;
  {
    std::vector<std::pair<int, int>> keyed;
    for (std::uint32_t f = 0; f < a.nfaces; ++f) {
      const std::uint8_t* r = &a.face_info[20 * f];
      const int key = (r[3] & 1) ? 1
                                 : std::min<int>(static_cast<std::int8_t>(r[0]),
                                                 static_cast<std::int8_t>(r[1]));
      keyed.push_back({key, static_cast<int>(f)});
    }
    std::stable_sort(keyed.begin(), keyed.end(), [](auto x, auto y) { return x.first > y.first; });
    for (auto& k : keyed) order.push_back(k.second);
  }
  for (std::size_t l = 0; l < a.levels.size(); ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    ASSERT_EQ(a.levels[l].entries.size(), b.levels[l].entries.size());
    for (std::size_t r = 0; r < a.levels[l].entries.size(); ++r) {
      const int f = l == 0 ? static_cast<int>(r) : order[r];
      const std::uint8_t* rec = &a.face_info[20 * std::size_t(f)];
      if (rec[3] & 1) {
        EXPECT_EQ(a.levels[l].entries[r], 0u);
        EXPECT_EQ(b.levels[l].entries[r], 0u);
        continue;
      }
      const std::size_t texels = std::size_t{1} << (rec[0] + rec[1] - 2 * l);
      EXPECT_EQ(BlockPieces(a.levels[l].blocks[r], a.levels[l].entries[r], texels * pixel),
                BlockPieces(b.levels[l].blocks[r], b.levels[l].entries[r], texels * pixel))
          << "entry " << r << " (face " << f << ")";
    }
  }
  EXPECT_EQ(a.meta, b.meta);
  EXPECT_EQ(a.lmd_values, b.lmd_values);
  // The large meta data header differs only in the value's zip size (its last 4 bytes).
  ASSERT_EQ(a.lmd_header.size(), b.lmd_header.size());
  if (!a.lmd_header.empty()) {
    EXPECT_TRUE(std::equal(a.lmd_header.begin(), a.lmd_header.end() - 4, b.lmd_header.begin()));
  }
  EXPECT_EQ(a.barrier, std::vector<std::uint8_t>(8, 0));
  EXPECT_EQ(a.end, ours.size());
}

INSTANTIATE_TEST_SUITE_P(Fixtures, PtexFixtureWrite, ::testing::ValuesIn(Fixtures()),
                         [](const ::testing::TestParamInfo<FixtureCase>& p) {
                           return p.param.file.substr(0, p.param.file.size() - 4);
                         });

// At libdeflate's level 1 a block under ptex::kStoredBelow bytes is stored (a deflate block of
// type 0, RFC 1951), one at or above it deflated; both inflate back to the data. Other levels
// and zlib deflate short blocks too.
TEST(PtexZlibBlock, ShortBlocksAreStoredAtTheFastestLevel) {
  auto block_type = [](const std::vector<std::uint8_t>& stream) { return (stream[2] >> 1) & 3; };
  for (const std::size_t size : {std::size_t{64}, ptex::kStoredBelow - 1, ptex::kStoredBelow}) {
    const std::vector<std::uint8_t> zeros(size, 0);  // deflates to a few bytes
    for (const auto& [compressor, level] :
         {std::pair{PtexCompressor::kLibdeflate, 1}, std::pair{PtexCompressor::kLibdeflate, -1},
          std::pair{PtexCompressor::kLibdeflate, 6}, std::pair{PtexCompressor::kZlib, 1}}) {
      SCOPED_TRACE(::testing::Message() << size << " bytes, level " << level
                                        << (compressor == PtexCompressor::kZlib ? ", zlib" : ""));
      std::vector<std::uint8_t> stream;
      const std::size_t made = ptex::CompressAppend(zeros, compressor, level, stream);
      ASSERT_EQ(made, stream.size());
      const bool stored =
          compressor == PtexCompressor::kLibdeflate && level <= 1 && size < ptex::kStoredBelow;
      EXPECT_EQ(block_type(stream) == 0, stored);
      EXPECT_EQ(stream.size() > size, stored);
      std::vector<std::uint8_t> back(size, 1);
      EXPECT_EQ(ptex::Inflate(stream, back), "");
      EXPECT_EQ(back, zeros);
    }
  }
}

// A face given as texels that are all bit-identical is stored exactly like SetConstantFace.
TEST(PtexWriterConstant, BitIdenticalTexelsAreAConstantFace) {
  TempDir dir;
  PtexFaceInfo info = Face(3, 2, {-1, -1, -1, -1}, {0, 0, 0, 0});
  const auto a = Write(dir, {}, 1, [&](PtexWriter& w) {
    Check(w.SetFace(PtexFaceId(0), info, std::vector<float>(32, -0.25f)));
  });
  const auto b = Write(dir, {}, 1, [&](PtexWriter& w) {
    Check(w.SetConstantFace(PtexFaceId(0), info, std::vector<float>{-0.25f}));
  });
  EXPECT_EQ(a, b);
  // +0 and -0 differ bitwise: not constant.
  std::vector<float> t(32, 0.0f);
  t[5] = -0.0f;
  const auto c =
      Write(dir, {}, 1, [&](PtexWriter& w) { Check(w.SetFace(PtexFaceId(0), info, t)); });
  StatusOr<PtexFile> f =
      ParsePtex(std::string_view(reinterpret_cast<const char*>(c.data()), c.size()), "c");
  ASSERT_TRUE(f.ok());
  EXPECT_FALSE(f->face_info(PtexFaceId(0)).constant);
}

// Faces never set become constant zero 1x1 faces without neighbours.
TEST(PtexWriterConstant, UnsetFacesAreConstantZero) {
  TempDir dir;
  const auto bytes = Write(dir, {}, 3, [&](PtexWriter& w) {
    Check(w.SetFace(PtexFaceId(1), Face(2, 2, {0, 2, -1, -1}, {2, 0, 0, 0}),
                    ptex_test::FixtureFace(1, 4, 4)));
  });
  StatusOr<PtexFile> f =
      ParsePtex(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "x");
  ASSERT_TRUE(f.ok()) << f.status().message();
  for (int id : {0, 2}) {
    const PtexFaceInfo& info = f->face_info(PtexFaceId(id));
    EXPECT_TRUE(info.constant);
    EXPECT_EQ(info.ulog2, 0);
    EXPECT_EQ(info.vlog2, 0);
    EXPECT_EQ(info.adjfaces, (std::array<std::int32_t, 4>{-1, -1, -1, -1}));
    float v = 1;
    f->ConstantValue(PtexFaceId(id), &v);
    EXPECT_EQ(v, 0.0f);
  }
}

}  // namespace
}  // namespace dispex
