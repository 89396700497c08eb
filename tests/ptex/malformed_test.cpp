// Malformed and truncated Ptex files: every prefix of valid files, corrupt zlib streams,
// sizes past the end, absurd resolutions and counts, random byte flips (fixed seed). Each
// must give a Status that names the file, never a crash, a hang or an out-of-bounds read
// (this suite runs under AddressSanitizer and UBSan in CI). Where a mutated file still
// parses, every face and level is read, sampled and dumped.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "dispex/ptex_describe.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

using ptex_test::FloatBytes;
using ptex_test::Put;
using ptex_test::RawPtex;
using ptex_test::ZippedFloats;

constexpr char kName[] = "bad.ptx";

StatusOr<PtexFile> Parse(const std::vector<std::uint8_t>& bytes) {
  PtexReadOptions options;
  options.max_values_per_read = std::size_t{1} << 22;
  return ParsePtex(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                   kName, options);
}

// Uses everything a parsed file offers; errors are fine, crashes are not.
void Exercise(const PtexFile& file) {
  (void)file.Validate();
  std::vector<float> texels;
  for (int f = 0; f < file.num_faces(); ++f) {
    const PtexFaceId id(f);
    for (int l = 0; l < file.NumStoredLevels(id); ++l) {
      (void)file.BlockInfo(id, l);
      Status s = file.ReadFace(id, l, texels);
      if (!s.ok()) {
        EXPECT_EQ(s.message().rfind(std::string(kName) + ": ", 0), 0u) << s.message();
      }
    }
    for (int c = 0; c < file.header().num_channels && c < 4; ++c) {
      (void)file.Sample(id, 0.3f, 0.7f, c);
    }
  }
  std::string text;
  (void)FormatPtexStructure(file, text);
  (void)FormatPtexSummary(file);
}

void ExpectError(const std::vector<std::uint8_t>& bytes, const std::string& needle) {
  StatusOr<PtexFile> f = Parse(bytes);
  ASSERT_FALSE(f.ok()) << "expected an error containing: " << needle;
  EXPECT_EQ(f.status().message().rfind(std::string(kName) + ": ", 0), 0u) << f.status().message();
  EXPECT_NE(f.status().message().find(needle), std::string::npos) << f.status().message();
  EXPECT_EQ(f.status().message().find('\n'), std::string::npos);
}

// A file written by dispex with meta data, a large meta data item and a tiled face.
std::vector<std::uint8_t> DispexFile() {
  ptex_test::TempDir dir;
  const std::string path = (dir / "w.ptx").string();
  StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 3);
  EXPECT_TRUE(w.ok());
  PtexFaceInfo a;
  a.ulog2 = 8;
  a.vlog2 = 7;
  a.adjfaces = {-1, 1, -1, -1};
  a.adjedges = {0, 3, 0, 0};
  std::vector<float> t(256 * 128);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = (i % 256) < 128 ? 1.0f : float(i % 7);
  EXPECT_TRUE(w->SetFace(PtexFaceId(0), a, t).ok());
  PtexFaceInfo b;
  b.ulog2 = 3;
  b.vlog2 = 1;
  EXPECT_TRUE(w->SetFace(PtexFaceId(1), b, ptex_test::FixtureFace(1, 8, 2)).ok());
  EXPECT_TRUE(w->AddMetaData("k", "value").ok());
  std::vector<double> big(200, 0.5);
  EXPECT_TRUE(w->AddMetaData("big", std::span<const double>(big)).ok());
  EXPECT_TRUE(w->Finish().ok());
  return ptex_test::ReadBytes(path);
}

std::vector<std::vector<std::uint8_t>> ValidFiles() {
  std::vector<std::vector<std::uint8_t>> files;
  for (const char* name :
       {"example_2faces.ptx", "quad_float1.ptx", "quad_half1.ptx", "quad_float3.ptx",
        "tri_float1.ptx", "quad_meta.ptx", "cc_pentagon_triangle.ptx", "quad_float1_tiled.ptx",
        "quad_uint8_rgba.ptx"}) {
    files.push_back(ptex_test::ReadBytes(ptex_test::FixturePath(name)));
  }
  files.push_back(DispexFile());
  return files;
}

TEST(PtexMalformed, EveryPrefixOfValidFiles) {
  for (const auto& file : ValidFiles()) {
    ASSERT_TRUE(Parse(file).ok());
    int parsed = 0;
    for (std::size_t n = 0; n < file.size(); ++n) {
      std::vector<std::uint8_t> prefix(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(n));
      StatusOr<PtexFile> f = Parse(prefix);
      if (f.ok()) {
        ++parsed;  // only the trailing barrier (or edit area) may be cut without harm
        Exercise(*f);
      } else {
        EXPECT_EQ(f.status().message().rfind(std::string(kName) + ": ", 0), 0u)
            << f.status().message();
      }
    }
    EXPECT_LE(parsed, 8) << "prefixes that parsed";
  }
}

TEST(PtexMalformed, RandomByteFlips) {
  std::mt19937 rng(20240601);
  int parsed = 0, total = 0;
  for (const auto& file : ValidFiles()) {
    for (int iter = 0; iter < 600; ++iter) {
      std::vector<std::uint8_t> m = file;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) {
        const std::size_t at = rng() % m.size();
        switch (rng() % 3) {
          case 0:
            m[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
            break;
          case 1:
            m[at] = static_cast<std::uint8_t>(rng());
            break;
          default:
            m[at] = (rng() & 1) ? 0xff : 0x00;
            break;
        }
      }
      ++total;
      StatusOr<PtexFile> f = Parse(m);
      if (!f.ok()) {
        EXPECT_EQ(f.status().message().rfind(std::string(kName) + ": ", 0), 0u)
            << f.status().message();
        continue;
      }
      ++parsed;
      Exercise(*f);
    }
  }
  // Most flips land in compressed face data, which only fails when read.
  EXPECT_GT(parsed, 0);
  EXPECT_LT(parsed, total);
}

// A small valid file assembled by hand, to corrupt field by field.
RawPtex Small() {
  RawPtex p;
  RawPtex::AddFace(p.face_info, 2, 2, 0);
  RawPtex::AddFace(p.face_info, 2, 2, 1);
  p.const_data = FloatBytes({1.5f, 2.5f});
  const auto b = ZippedFloats(ptex_test::FixtureFace(0, 4, 4));
  p.levels.push_back({{0x40000000u | std::uint32_t(b.size()), 0}, {b, {}}});
  return p;
}

template <class T>
std::vector<std::uint8_t> Patch(std::vector<std::uint8_t> bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
  return bytes;
}

TEST(PtexMalformed, HeaderFields) {
  const std::vector<std::uint8_t> ok = Small().Build();
  ASSERT_TRUE(Parse(ok).ok());
  ExpectError({}, "shorter than the 64-byte Ptex header");
  ExpectError(std::vector<std::uint8_t>(ok.begin(), ok.begin() + 63), "shorter than the 64-byte");
  ExpectError(Patch<std::uint32_t>(ok, 0, 0x12345678), "not a Ptex file");
  ExpectError(Patch<std::uint32_t>(ok, 4, 2), "major version 2");
  ExpectError(Patch<std::uint32_t>(ok, 8, 2), "mesh type 2");
  ExpectError(Patch<std::uint32_t>(ok, 12, 4), "data type 4");
  ExpectError(Patch<std::int32_t>(ok, 16, 1), "alpha channel 1");
  ExpectError(Patch<std::int32_t>(ok, 16, -2), "alpha channel -2");
  ExpectError(Patch<std::uint16_t>(ok, 20, 0), "0 channels");
  ExpectError(Patch<std::uint16_t>(ok, 22, 0), "level count 0");
  ExpectError(Patch<std::uint32_t>(ok, 24, 0), "no faces");
  ExpectError(Patch<std::uint32_t>(ok, 40, 32), "level info size 32");
  ExpectError(Patch<std::uint32_t>(ok, 28, 0x7fffffff), "extended header size");
  ExpectError(Patch<std::uint16_t>(ok, 64, 3), "border modes");
  ExpectError(Patch<std::uint16_t>(ok, 70, 2), "edge filter mode 2");
}

TEST(PtexMalformed, CountsTheFileCannotHold) {
  const std::vector<std::uint8_t> ok = Small().Build();
  // 2^32 - 1 faces in a 200-byte file: rejected at once, before any allocation.
  ExpectError(Patch<std::uint32_t>(ok, 24, 0xffffffffu), "faces exceed the limit");
  // 2^28 faces: within the limit, but 20 x 2^28 bytes cannot come out of the face info block.
  ExpectError(Patch<std::uint32_t>(ok, 24, 1u << 28), "cannot hold");
  ExpectError(Patch<std::uint16_t>(ok, 20, 0xffff), "constant data");
  ExpectError(Patch<std::uint32_t>(ok, 32, 0xfffffff0u), "run past the end of the file");
  ExpectError(Patch<std::uint32_t>(ok, 36, 0xfffffff0u), "run past the end of the file");
  ExpectError(Patch<std::uint64_t>(ok, 48, 0xffffffffffffff00ull), "level data of");
  ExpectError(Patch<std::uint64_t>(ok, 48, 1), "level 0");
  ExpectError(Patch<std::uint32_t>(ok, 56, 1000), "meta data sizes");
  ExpectError(Patch<std::uint32_t>(Patch<std::uint32_t>(ok, 56, 1000), 60, 1), "meta data");
  ExpectError(Patch<std::uint32_t>(ok, 64 + 8, 5), "large meta data header sizes disagree");
  ExpectError(Patch<std::uint64_t>(ok, 64 + 16, 5), "large meta data of 5 bytes");
  ExpectError(Patch<std::uint64_t>(ok, 64 + 24, 1u << 30), "edit data");
}

TEST(PtexMalformed, FaceRecords) {
  for (int bad : {16, -1, 127}) {
    RawPtex p = Small();
    p.face_info[0] = static_cast<std::uint8_t>(bad);
    ExpectError(p.Build(), "face info: face 0: resolution log2");
  }
  RawPtex p = Small();
  p.face_info[20 + 1] = 3;  // face 1 of a triangle mesh: 4x8
  p.mesh_type = 0;
  ExpectError(p.Build(), "face 1: triangle face with non-square resolution");
  p = Small();
  std::memcpy(&p.face_info[4 + 4], "\x02\x00\x00\x00", 4);  // neighbour 2 of 2 faces
  ExpectError(p.Build(), "face 0: neighbour across edge 1 is face 2");
  p = Small();
  std::memcpy(&p.face_info[4], "\xfe\xff\xff\xff", 4);  // neighbour -2
  ExpectError(p.Build(), "neighbour across edge 0 is face -2");
}

TEST(PtexMalformed, LevelsAndBlocks) {
  RawPtex p = Small();
  p.levels[0].headers.push_back(0);  // 3 entries for 2 faces
  p.levels[0].blocks.emplace_back();
  ExpectError(p.Build(), "level 0: 3 entries, the file has 2 faces");

  p = Small();
  p.levels[0].headers[0] += 5;  // block size says 5 more bytes than there are
  ExpectError(p.Build(), "runs past the end of the level");

  p = Small();
  p.levels[0].blocks[1] = {1, 2, 3};  // bytes after the blocks
  ExpectError(p.Build(), "level 0: blocks total");

  p = Small();
  p.levels[0].headers[0] = 0x40000000u;  // a non-constant face with an empty block
  p.levels[0].blocks[0].clear();
  ExpectError(p.Build(), "face 0 level 0: empty data block");

  p = Small();
  p.levels[0].headers[0] = 3;  // constant encoding, 3 bytes for a 4-byte texel
  p.levels[0].blocks[0] = {1, 2, 3};
  ExpectError(p.Build(), "constant block of 3 bytes");

  // A reduction level entry whose face is too small for the level.
  p = Small();
  const auto r = ZippedFloats(std::vector<float>(4, 0));
  p.levels.push_back({{0x40000000u | std::uint32_t(r.size())}, {r}});
  p.levels.push_back({{0x40000000u | std::uint32_t(r.size())}, {r}});
  p.levels.push_back({{0x40000000u | std::uint32_t(r.size())}, {r}});
  ExpectError(p.Build(), "level 3: entry 0 is face 0 level 3, too small");
}

TEST(PtexMalformed, CorruptZlibStreams) {
  // Corrupt face data is found when the face is read, not at open.
  RawPtex p = Small();
  p.levels[0].blocks[0][5] ^= 0xff;
  p.levels[0].blocks[0][6] ^= 0x55;
  StatusOr<PtexFile> f = Parse(p.Build());
  ASSERT_TRUE(f.ok()) << f.status().message();
  std::vector<float> t;
  Status s = f->ReadFace(PtexFaceId(0), 0, t);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.message().rfind("bad.ptx: face 0 level 0: ", 0), 0u) << s.message();
  EXPECT_FALSE(f->Validate().ok());
  EXPECT_TRUE(std::isnan(f->Sample(PtexFaceId(0), 0.5f, 0.5f)));

  // A stream that inflates to fewer bytes than the face needs.
  p = Small();
  p.levels[0].blocks[0] = ZippedFloats(std::vector<float>(15, 1.0f));
  p.levels[0].headers[0] = 0x40000000u | std::uint32_t(p.levels[0].blocks[0].size());
  f = Parse(p.Build());
  ASSERT_TRUE(f.ok());
  s = f->ReadFace(PtexFaceId(0), 0, t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("inflates to 60 bytes, expected 64"), std::string::npos)
      << s.message();

  // ... or to more.
  p.levels[0].blocks[0] = ZippedFloats(std::vector<float>(17, 1.0f));
  p.levels[0].headers[0] = 0x40000000u | std::uint32_t(p.levels[0].blocks[0].size());
  f = Parse(p.Build());
  ASSERT_TRUE(f.ok());
  s = f->ReadFace(PtexFaceId(0), 0, t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("more than the expected 64 bytes"), std::string::npos) << s.message();

  // A face info block that is not zlib at all.
  std::vector<std::uint8_t> bytes = Small().Build();
  bytes[104] = 0x12;
  bytes[105] = 0x34;
  ExpectError(bytes, "face info: corrupt zlib stream");

  // A block claiming a resolution far beyond what it can inflate to.
  p = Small();
  p.face_info[0] = 15;
  p.face_info[1] = 15;
  f = Parse(p.Build());
  ASSERT_TRUE(f.ok());
  s = f->ReadFace(PtexFaceId(0), 0, t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("read limit"), std::string::npos) << s.message();
}

TEST(PtexMalformed, TiledBlocks) {
  // Face 0 of 4x4 as 4 tiles of 2x2.
  auto tiled = [](std::int8_t tu, std::int8_t tv, std::uint32_t ntiles_in_header, bool nested) {
    std::vector<std::uint8_t> tiles, header;
    for (std::uint32_t t = 0; t < ntiles_in_header; ++t) {
      const auto z = ZippedFloats({1, 2, 3, 4});
      Put<std::uint32_t>(header,
                         (nested && t == 2 ? 0xc0000000u : 0x40000000u) | std::uint32_t(z.size()));
      tiles.insert(tiles.end(), z.begin(), z.end());
    }
    const auto hz = ptex_test::ZlibCompress(header);
    std::vector<std::uint8_t> block;
    block.push_back(static_cast<std::uint8_t>(tu));
    block.push_back(static_cast<std::uint8_t>(tv));
    Put<std::uint32_t>(block, static_cast<std::uint32_t>(hz.size()));
    block.insert(block.end(), hz.begin(), hz.end());
    block.insert(block.end(), tiles.begin(), tiles.end());
    RawPtex p = Small();
    p.levels[0].blocks[0] = block;
    p.levels[0].headers[0] = 0xc0000000u | std::uint32_t(block.size());
    return p.Build();
  };
  StatusOr<PtexFile> f = Parse(tiled(1, 1, 4, false));
  ASSERT_TRUE(f.ok()) << f.status().message();
  std::vector<float> t;
  ASSERT_TRUE(f->ReadFace(PtexFaceId(0), 0, t).ok());
  EXPECT_EQ(t, (std::vector<float>{1, 2, 1, 2, 3, 4, 3, 4, 1, 2, 1, 2, 3, 4, 3, 4}));
  ExpectError(tiled(3, 1, 4, false), "tile resolution log2 (3, 1) does not fit");
  ExpectError(tiled(-1, 1, 4, false), "tile resolution log2 (-1, 1)");
  ExpectError(tiled(1, 1, 3, false), "tile header");
  ExpectError(tiled(1, 1, 4, true), "tile 2 is itself tiled");
}

TEST(PtexMalformed, MetaData) {
  auto with_meta = [](std::vector<std::uint8_t> meta) {
    RawPtex p = Small();
    p.meta = std::move(meta);
    return p.Build();
  };
  ExpectError(with_meta({0}), "meta data: item 0 at byte 0: key size 0");
  ExpectError(with_meta({3, 'a', 'b'}), "record runs past the end");
  ExpectError(with_meta({2, 'a', 'b', 0, 1, 0, 0, 0, 7}), "key is not NUL-terminated");
  ExpectError(with_meta({2, 'a', 0, 9, 1, 0, 0, 0, 7}), "unknown data type 9");
  ExpectError(with_meta({2, 'a', 0, 3, 3, 0, 0, 0, 7, 7, 7}), "not a multiple of the int32 size");
  ExpectError(with_meta({2, 'a', 0, 1, 9, 0, 0, 0, 7}), "value of 9 bytes runs past");
  StatusOr<PtexFile> f = Parse(with_meta({2, 'a', 0, 1, 2, 0, 0, 0, 7, 0xff}));
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_EQ(f->FindMetaData("a")->AsInt8(), (std::vector<std::int8_t>{7, -1}));
}

}  // namespace
}  // namespace dispex
