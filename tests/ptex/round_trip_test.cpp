// Files written by dispex, read back by dispex: random meshes, resolutions (non-square,
// 1xN), data types, channel counts, alpha; texels, reductions, averages, adjacency and meta
// data compared with values computed here. Also determinism (submission order, threads),
// atomic output, sampling, and the writer's input errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

#include "dispex/ptex.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

using ptex_test::ReadBytes;
using ptex_test::TempDir;

// A random Ptex texture: face records with random adjacency and resolutions, and smooth
// texels in [0, 1] (integers) or [-2, 2] (floats).
struct RandomTexture {
  PtexWriterOptions options;
  std::vector<PtexFaceInfo> faces;
  std::vector<std::vector<float>> texels;  // empty: constant face with value `constant`
  std::vector<std::vector<float>> constant;
};

RandomTexture MakeRandom(std::uint32_t seed, PtexDataType type, int nch, int alpha,
                         PtexMeshType mesh = PtexMeshType::kQuad, int nfaces = 24) {
  std::mt19937 rng(seed);
  RandomTexture t;
  t.options.data_type = type;
  t.options.num_channels = nch;
  t.options.alpha_channel = alpha;
  t.options.mesh_type = mesh;
  const bool integer = type == PtexDataType::kUint8 || type == PtexDataType::kUint16;
  std::uniform_real_distribution<float> phase(0, 6.28f);
  for (int f = 0; f < nfaces; ++f) {
    PtexFaceInfo info;
    info.ulog2 = static_cast<std::int8_t>(rng() % 8);
    info.vlog2 = mesh == PtexMeshType::kTriangle ? info.ulog2 : static_cast<std::int8_t>(rng() % 8);
    if (f % 7 == 3) info.vlog2 = 0;  // 1-texel-high faces
    if (mesh == PtexMeshType::kTriangle) info.vlog2 = info.ulog2;
    const int edges = mesh == PtexMeshType::kTriangle ? 3 : 4;
    for (int e = 0; e < edges; ++e) {
      if (rng() % 4 == 0) continue;
      info.adjfaces[std::size_t(e)] = static_cast<std::int32_t>(rng() % std::uint32_t(nfaces));
      info.adjedges[std::size_t(e)] = static_cast<std::uint8_t>(rng() % std::uint32_t(edges));
    }
    info.subface = mesh == PtexMeshType::kQuad && rng() % 3 == 0;
    t.faces.push_back(info);
    std::vector<float> values;
    if (f % 5 == 4) {  // constant face
      std::vector<float> c;
      for (int ch = 0; ch < nch; ++ch) c.push_back(integer ? 0.25f * float(ch % 4) : 1.5f - ch);
      t.constant.push_back(c);
      t.texels.emplace_back();
      continue;
    }
    t.constant.emplace_back();
    const float a = phase(rng), b = phase(rng);
    for (int v = 0; v < info.vres(); ++v)
      for (int u = 0; u < info.ures(); ++u)
        for (int ch = 0; ch < nch; ++ch) {
          const float s = std::sin(a + 0.7f * u + 0.3f * ch) * std::cos(b + 0.45f * v);
          values.push_back(integer ? 0.5f + 0.5f * s : 2.0f * s);
        }
    t.texels.push_back(values);
  }
  return t;
}

// Writes the texture, submitting faces in `order` from `threads` threads.
Status WriteTexture(const RandomTexture& t, const std::string& path, std::vector<int> order,
                    int threads, PtexWriterOptions options) {
  StatusOr<PtexWriter> w = PtexWriter::Create(path, options, static_cast<int>(t.faces.size()));
  if (!w.ok()) return w.status();
  std::vector<std::thread> pool;
  std::vector<Status> results(static_cast<std::size_t>(threads), Status::Ok());
  for (int k = 0; k < threads; ++k) {
    pool.emplace_back([&, k] {
      for (std::size_t i = std::size_t(k); i < order.size(); i += std::size_t(threads)) {
        const int f = order[i];
        Status s =
            t.texels[std::size_t(f)].empty()
                ? w->SetConstantFace(PtexFaceId(f), t.faces[std::size_t(f)],
                                     t.constant[std::size_t(f)])
                : w->SetFace(PtexFaceId(f), t.faces[std::size_t(f)], t.texels[std::size_t(f)]);
        if (!s.ok()) results[std::size_t(k)] = s;
      }
    });
  }
  for (auto& th : pool) th.join();
  for (const Status& s : results) DISPEX_RETURN_IF_ERROR(s);
  DISPEX_RETURN_IF_ERROR(w->AddMetaData("name", "round trip"));
  const std::vector<double> d = {1.0, -2.5};
  DISPEX_RETURN_IF_ERROR(w->AddMetaData("d", std::span<const double>(d)));
  std::vector<std::int16_t> big(700);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<std::int16_t>(i * 37 - 9000);
  DISPEX_RETURN_IF_ERROR(w->AddMetaData("big", std::span<const std::int16_t>(big)));
  return w->Finish();
}

// What the file must hold for a float texel, after conversion to the data type and back.
float Stored(float x, PtexDataType type) {
  switch (type) {
    case PtexDataType::kFloat:
      return x;
    case PtexDataType::kHalf:
      return HalfToFloat(FloatToHalf(x));
    case PtexDataType::kUint8:
      return static_cast<float>(std::floor(std::clamp(x, 0.f, 1.f) * 255.0 + 0.5) / 255.0);
    case PtexDataType::kUint16:
      return static_cast<float>(std::floor(std::clamp(x, 0.f, 1.f) * 65535.0 + 0.5) / 65535.0);
  }
  return 0;
}

void ExpectRoundTrip(const RandomTexture& t, const PtexFile& file) {
  const PtexDataType type = t.options.data_type;
  const int nch = t.options.num_channels;
  ASSERT_EQ(file.num_faces(), static_cast<int>(t.faces.size()));
  EXPECT_EQ(file.header().data_type, type);
  EXPECT_EQ(file.header().num_channels, nch);
  EXPECT_EQ(file.header().alpha_channel, t.options.alpha_channel);
  EXPECT_EQ(file.header().mesh_type, t.options.mesh_type);
  const bool triangle = t.options.mesh_type == PtexMeshType::kTriangle;
  for (std::size_t f = 0; f < t.faces.size(); ++f) {
    SCOPED_TRACE("face " + std::to_string(f));
    const PtexFaceInfo& in = t.faces[f];
    const PtexFaceInfo& out = file.face_info(PtexFaceId(static_cast<int>(f)));
    EXPECT_EQ(out.ulog2, in.ulog2);
    EXPECT_EQ(out.vlog2, in.vlog2);
    EXPECT_EQ(out.subface, triangle ? false : in.subface);
    for (int e = 0; e < (triangle ? 3 : 4); ++e) {
      EXPECT_EQ(out.adjfaces[std::size_t(e)], in.adjfaces[std::size_t(e)]);
      if (in.adjfaces[std::size_t(e)] >= 0) {
        EXPECT_EQ(out.adjedges[std::size_t(e)], in.adjedges[std::size_t(e)]);
      }
    }
    std::vector<float> got;
    ASSERT_TRUE(file.ReadFace(PtexFaceId(static_cast<int>(f)), 0, got).ok());
    std::vector<float> expect;
    if (t.texels[f].empty()) {
      for (std::size_t i = 0; i < in.num_texels(); ++i)
        for (int c = 0; c < nch; ++c) expect.push_back(Stored(t.constant[f][std::size_t(c)], type));
    } else {
      for (float x : t.texels[f]) expect.push_back(Stored(x, type));
    }
    ASSERT_EQ(got, expect);
    // Constant: declared so, or because every converted texel is identical (e.g. 1x1).
    bool all_same = true;
    for (std::size_t i = std::size_t(nch); i < expect.size(); ++i) {
      all_same &= std::bit_cast<std::uint32_t>(expect[i]) ==
                  std::bit_cast<std::uint32_t>(expect[i % std::size_t(nch)]);
    }
    EXPECT_EQ(out.constant, all_same);
    // Stored reductions: levels 1 .. min(ulog2, vlog2) - 2 of non-constant faces.
    const int expected_levels =
        out.constant ? 1 : 1 + std::max(0, std::min<int>(in.ulog2, in.vlog2) - 2);
    EXPECT_EQ(file.NumStoredLevels(PtexFaceId(static_cast<int>(f))), expected_levels);
    if (t.options.alpha_channel < 0 && !triangle && !out.constant) {
      // Each stored level is the 2x2 reduction of the previous one, in the data type's own
      // arithmetic, recomputed here from the stored previous level.
      std::vector<float> prev = got;
      for (int l = 1; l < expected_levels; ++l) {
        const int w = in.ures() >> (l - 1), h = in.vres() >> (l - 1);
        std::vector<float> mine;
        for (int j = 0; j < h / 2; ++j)
          for (int i = 0; i < w / 2; ++i)
            for (int c = 0; c < nch; ++c) {
              auto s = [&](int x, int y) { return prev[std::size_t((y * w + x) * nch + c)]; };
              const float a = s(2 * i, 2 * j), b = s(2 * i + 1, 2 * j), cc = s(2 * i, 2 * j + 1),
                          d = s(2 * i + 1, 2 * j + 1);
              if (type == PtexDataType::kFloat) {
                mine.push_back((a + b + cc + d) * 0.25f);
              } else if (type == PtexDataType::kHalf) {
                mine.push_back(HalfToFloat(FloatToHalf((a + b + cc + d) * 0.25f)));
              } else {
                const double one = type == PtexDataType::kUint8 ? 255.0 : 65535.0;
                const long sum = std::lround(a * one) + std::lround(b * one) +
                                 std::lround(cc * one) + std::lround(d * one);
                mine.push_back(static_cast<float>(static_cast<double>(sum / 4) / one));
              }
            }
        std::vector<float> level;
        ASSERT_TRUE(file.ReadFace(PtexFaceId(static_cast<int>(f)), l, level).ok());
        ASSERT_EQ(level, mine) << "level " << l;
        prev = level;
      }
      // The constant data holds the exact mean of the stored level-0 texels.
      std::vector<float> avg(std::size_t(nch), 0.f);
      file.ConstantValue(PtexFaceId(static_cast<int>(f)), avg.data());
      for (int c = 0; c < nch; ++c) {
        float expect_avg = 0;
        if (type == PtexDataType::kFloat || type == PtexDataType::kHalf) {
          double sum = 0;
          for (std::size_t i = std::size_t(c); i < got.size(); i += std::size_t(nch)) sum += got[i];
          const double mean = sum / static_cast<double>(in.num_texels());
          expect_avg = type == PtexDataType::kFloat ? static_cast<float>(mean)
                                                    : HalfToFloat(DoubleToHalf(mean));
        } else {  // integer mean, truncated (as the reference)
          const double one = type == PtexDataType::kUint8 ? 255.0 : 65535.0;
          long long sum = 0;
          for (std::size_t i = std::size_t(c); i < got.size(); i += std::size_t(nch)) {
            sum += std::llround(got[i] * one);
          }
          const long long mean = sum / static_cast<long long>(in.num_texels());
          expect_avg = static_cast<float>(static_cast<double>(mean) / one);
        }
        EXPECT_EQ(avg[std::size_t(c)], expect_avg) << "channel " << c;
      }
    }
  }
  ASSERT_EQ(file.meta_data().size(), 3u);
  EXPECT_EQ(file.FindMetaData("name")->AsString(), "round trip");
  EXPECT_EQ(file.FindMetaData("d")->AsDouble(), (std::vector<double>{1.0, -2.5}));
  const PtexMetaItem* big = file.FindMetaData("big");
  ASSERT_NE(big, nullptr);
  EXPECT_TRUE(big->large);
  ASSERT_EQ(big->count(), 700u);
  EXPECT_EQ(big->AsInt16()[699], static_cast<std::int16_t>(699 * 37 - 9000));
  EXPECT_TRUE(file.Validate().ok());
}

struct Config {
  PtexDataType type;
  int channels;
  int alpha;
  PtexMeshType mesh;
};
void PrintTo(const Config& c, std::ostream* os) {
  *os << PtexDataTypeName(c.type) << " x" << c.channels << " alpha " << c.alpha << " "
      << PtexMeshTypeName(c.mesh);
}

class PtexRoundTrip : public ::testing::TestWithParam<Config> {};

TEST_P(PtexRoundTrip, TexelsAdjacencyMetaDataAndReductions) {
  const Config c = GetParam();
  TempDir dir;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    RandomTexture t = MakeRandom(seed * 77 + static_cast<std::uint32_t>(c.channels), c.type,
                                 c.channels, c.alpha, c.mesh);
    std::vector<int> order(t.faces.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::shuffle(order.begin(), order.end(), std::mt19937(seed));
    const std::string path = (dir / "rt.ptx").string();
    Status s = WriteTexture(t, path, order, 2, t.options);
    ASSERT_TRUE(s.ok()) << s.message();
    StatusOr<PtexFile> file = PtexFile::Open(path);
    ASSERT_TRUE(file.ok()) << file.status().message();
    ExpectRoundTrip(t, *file);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Types, PtexRoundTrip,
    ::testing::Values(Config{PtexDataType::kFloat, 1, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kFloat, 3, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kHalf, 1, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kHalf, 2, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kUint8, 1, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kUint8, 4, 3, PtexMeshType::kQuad},
                      Config{PtexDataType::kUint16, 5, -1, PtexMeshType::kQuad},
                      Config{PtexDataType::kUint16, 2, 0, PtexMeshType::kQuad},
                      Config{PtexDataType::kFloat, 2, 1, PtexMeshType::kQuad},
                      Config{PtexDataType::kFloat, 1, -1, PtexMeshType::kTriangle},
                      Config{PtexDataType::kHalf, 3, -1, PtexMeshType::kTriangle}),
    [](const ::testing::TestParamInfo<Config>& p) {
      std::ostringstream name;
      name << PtexDataTypeName(p.param.type) << "_" << p.param.channels << "ch";
      if (p.param.alpha >= 0) name << "_alpha" << p.param.alpha;
      name << (p.param.mesh == PtexMeshType::kTriangle ? "_triangle" : "_quad");
      return name.str();
    });

// The same faces submitted in different orders, from 1 to 4 threads, give the same bytes;
// so does each compressor.
TEST(PtexWriterDeterminism, SameBytesWhateverTheOrderAndThreads) {
  TempDir dir;
  RandomTexture t = MakeRandom(99, PtexDataType::kFloat, 2, -1, PtexMeshType::kQuad, 60);
  // A face large enough to be tiled.
  t.faces[5].ulog2 = 9;
  t.faces[5].vlog2 = 7;
  t.texels[5].clear();
  for (int i = 0; i < (512 << 7) * 2; ++i) t.texels[5].push_back(std::sin(0.001f * float(i)));
  t.constant[5].clear();
  for (PtexCompressor comp : {PtexCompressor::kLibdeflate, PtexCompressor::kZlib}) {
    PtexWriterOptions options = t.options;
    options.compressor = comp;
    std::vector<int> order(t.faces.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    const std::string first = (dir / "a.ptx").string();
    ASSERT_TRUE(WriteTexture(t, first, order, 1, options).ok());
    const std::vector<std::uint8_t> reference = ReadBytes(first);
    std::reverse(order.begin(), order.end());
    for (int threads : {1, 2, 4}) {
      std::shuffle(order.begin(), order.end(), std::mt19937(threads));
      std::string name = std::to_string(threads);
      name += "threads.ptx";
      const std::string path = (dir / name).string();
      ASSERT_TRUE(WriteTexture(t, path, order, threads, options).ok());
      EXPECT_EQ(ReadBytes(path), reference) << threads << " threads";
    }
    StatusOr<PtexFile> file = PtexFile::Open(first);
    ASSERT_TRUE(file.ok());
    EXPECT_EQ(file->BlockInfo(PtexFaceId(5), 0).encoding, PtexBlockInfo::Encoding::kTiled);
    ExpectRoundTrip(t, *file);
  }
}

// Every face copied still encoded (ReadEncodedFace into SetEncodedFace, in another order) makes
// the same file, byte for byte, as writing its texels: tiled, constant, 1-texel-high and
// alpha faces, half and integer types, triangles, both compressors.
TEST(PtexEncodedFaces, CopiedFacesMakeTheSameFile) {
  TempDir dir;
  struct Case {
    PtexDataType type;
    int channels, alpha;
    PtexMeshType mesh;
    PtexCompressor compressor;
  };
  for (const Case& c :
       {Case{PtexDataType::kFloat, 2, -1, PtexMeshType::kQuad, PtexCompressor::kLibdeflate},
        Case{PtexDataType::kHalf, 1, -1, PtexMeshType::kQuad, PtexCompressor::kLibdeflate},
        Case{PtexDataType::kUint8, 4, 3, PtexMeshType::kQuad, PtexCompressor::kZlib},
        Case{PtexDataType::kUint16, 3, -1, PtexMeshType::kTriangle, PtexCompressor::kLibdeflate}}) {
    RandomTexture t = MakeRandom(7, c.type, c.channels, c.alpha, c.mesh, 30);
    t.faces[2].ulog2 = t.faces[2].vlog2 = 9;  // tiled at level 0 and 1
    t.constant[2].clear();
    t.texels[2].clear();
    for (int i = 0; i < (1 << 18) * c.channels; ++i) {
      t.texels[2].push_back(0.5f + 0.4f * std::sin(0.001f * float(i)));
    }
    PtexWriterOptions options = t.options;
    options.compressor = c.compressor;
    std::vector<int> order(t.faces.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    const std::string original = (dir / "original.ptx").string();
    ASSERT_TRUE(WriteTexture(t, original, order, 1, options).ok());
    StatusOr<PtexFile> file = PtexFile::Open(original);
    ASSERT_TRUE(file.ok()) << file.status().message();
    ASSERT_EQ(file->BlockInfo(PtexFaceId(2), 0).encoding, PtexBlockInfo::Encoding::kTiled);

    const std::string copy = (dir / "copy.ptx").string();
    StatusOr<PtexWriter> w = PtexWriter::Create(copy, options, file->num_faces());
    ASSERT_TRUE(w.ok());
    PtexEncodedFace encoded;
    for (int f = file->num_faces() - 1; f >= 0; --f) {
      ASSERT_TRUE(file->ReadEncodedFace(PtexFaceId(f), encoded).ok());
      EXPECT_EQ(encoded.constant, file->face_info(PtexFaceId(f)).constant);
      const Status set = w->SetEncodedFace(PtexFaceId(f), t.faces[std::size_t(f)], encoded);
      ASSERT_TRUE(set.ok()) << set.message();
    }
    ASSERT_TRUE(w->AddMetaData("name", "round trip").ok());
    const std::vector<double> d = {1.0, -2.5};
    ASSERT_TRUE(w->AddMetaData("d", std::span<const double>(d)).ok());
    std::vector<std::int16_t> big(700);
    for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<std::int16_t>(i * 37 - 9000);
    ASSERT_TRUE(w->AddMetaData("big", std::span<const std::int16_t>(big)).ok());
    ASSERT_TRUE(w->Finish().ok());
    EXPECT_EQ(ReadBytes(copy), ReadBytes(original)) << PtexEncodingName(options);
  }
}

// The level data hash the writer records is the reader's hash of the file's level data, and a
// changed byte of a face block changes it.
TEST(PtexLevelDataHash, RecordedAsTheReaderComputesIt) {
  TempDir dir;
  RandomTexture t = MakeRandom(9, PtexDataType::kHalf, 1, -1);
  PtexWriterOptions options = t.options;
  options.level_data_hash_key = "test:level_data_hash";
  std::vector<int> order(t.faces.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const std::string path = (dir / "a.ptx").string();
  ASSERT_TRUE(WriteTexture(t, path, order, 2, options).ok());
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok());
  const PtexMetaItem* recorded = file->FindMetaData("test:level_data_hash");
  ASSERT_NE(recorded, nullptr);
  EXPECT_EQ(recorded->AsString().size(), 32u);
  EXPECT_EQ(recorded->AsString(), file->LevelDataHash());

  // The last byte of the last level's last block (the level data ends where the meta data
  // begins), changed.
  std::vector<std::uint8_t> bytes = ReadBytes(path);
  bytes[ptex_test::ReadSections(bytes).level_data_end - 1] ^= 0x5a;
  StatusOr<PtexFile> changed = ParsePtex(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), "changed.ptx");
  ASSERT_TRUE(changed.ok()) << changed.status().message();
  EXPECT_NE(changed->LevelDataHash(), recorded->AsString());

  options.level_data_hash_key = std::string(255, 'k');
  EXPECT_FALSE(PtexWriter::Create((dir / "b.ptx").string(), options, 1).ok());
}

// An encoded face that this writer would not have made is refused, naming what differs.
TEST(PtexEncodedFaces, AFaceOfAnotherEncodingIsRefused) {
  TempDir dir;
  RandomTexture t = MakeRandom(8, PtexDataType::kFloat, 1, -1);
  t.faces[0].ulog2 = t.faces[0].vlog2 = 4;  // reductions stored at levels 1 and 2
  t.constant[0].clear();
  t.texels[0].assign(256, 0);
  for (std::size_t i = 0; i < 256; ++i) t.texels[0][i] = float(i);
  std::vector<int> order(t.faces.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  const std::string path = (dir / "a.ptx").string();
  ASSERT_TRUE(WriteTexture(t, path, order, 1, t.options).ok());
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok());
  PtexEncodedFace encoded;
  ASSERT_TRUE(file->ReadEncodedFace(PtexFaceId(0), encoded).ok());
  ASSERT_EQ(encoded.headers.size(), 3u);

  const auto refused = [&](PtexWriterOptions options, PtexFaceInfo info, const PtexEncodedFace& e) {
    StatusOr<PtexWriter> w =
        PtexWriter::Create((dir / "b.ptx").string(), options, static_cast<int>(t.faces.size()));
    EXPECT_TRUE(w.ok());
    const Status s = w->SetEncodedFace(PtexFaceId(0), info, e);
    EXPECT_EQ(w->faces_set(), s.ok() ? 1 : 0);  // nothing stored when refused
    return s.ok() ? std::string() : s.message();
  };
  PtexWriterOptions no_reductions = t.options;
  no_reductions.write_reductions = false;
  EXPECT_NE(refused(no_reductions, t.faces[0], encoded).find("stores 3 levels, this file 1"),
            std::string::npos);
  PtexWriterOptions half = t.options;
  half.data_type = PtexDataType::kHalf;
  EXPECT_NE(refused(half, t.faces[0], encoded).find("texels of 4 bytes, the file's have 2"),
            std::string::npos);
  PtexFaceInfo smaller = t.faces[0];
  smaller.ulog2 = 3;
  EXPECT_NE(
      refused(t.options, smaller, encoded).find("resolution log2 (4, 4), not the face's (3, 4)"),
      std::string::npos);
  PtexEncodedFace cut = encoded;
  cut.blocks.pop_back();
  EXPECT_NE(refused(t.options, t.faces[0], cut).find("bytes of blocks, its headers say"),
            std::string::npos);
  EXPECT_EQ(refused(t.options, t.faces[0], encoded), "");
  EXPECT_NE(PtexEncodingName(t.options), PtexEncodingName(no_reductions));
  EXPECT_NE(PtexEncodingName(t.options), PtexEncodingName(half));
}

// Large faces are tiled by the reference rule; constant tiles are stored raw; reading back
// reassembles them.
TEST(PtexWriterTiling, TilesByTheReferenceRule) {
  TempDir dir;
  const std::string path = (dir / "t.ptx").string();
  PtexFaceInfo info;
  info.ulog2 = 9;
  info.vlog2 = 9;  // 512x512 float = 1 MiB: 16 tiles of 128x128
  std::vector<float> t(512 * 512);
  for (int v = 0; v < 512; ++v)
    for (int u = 0; u < 512; ++u) t[std::size_t(v * 512 + u)] = v < 128 ? 7.0f : float(u + v);
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 1);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, t).ok());
    ASSERT_TRUE(w->Finish().ok());
  }
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  PtexBlockInfo b = file->BlockInfo(PtexFaceId(0), 0);
  EXPECT_EQ(b.encoding, PtexBlockInfo::Encoding::kTiled);
  EXPECT_EQ(b.num_tiles, 16);
  EXPECT_EQ(b.tile_ulog2, 7);
  EXPECT_EQ(b.tile_vlog2, 7);
  // Level 1 (256x256 = 256 KiB) is tiled too: 4 tiles; level 2 (64 KiB) is not.
  EXPECT_EQ(file->BlockInfo(PtexFaceId(0), 1).num_tiles, 4);
  EXPECT_EQ(file->BlockInfo(PtexFaceId(0), 2).encoding, PtexBlockInfo::Encoding::kZipped);
  std::vector<float> got;
  ASSERT_TRUE(file->ReadFace(PtexFaceId(0), 0, got).ok());
  EXPECT_EQ(got, t);
  // Constant tiles (the first 4, v < 128) are stored as one raw texel each.
  const auto s = ptex_test::ReadSections(ReadBytes(path));
  const auto& blk = s.levels[0].blocks[0];
  const std::uint32_t ths = ptex_test::LoadLE<std::uint32_t>(&blk[2]);
  std::vector<std::uint8_t> th = ptex_test::ZlibInflate(&blk[6], ths, 64);
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&th[std::size_t(4 * k)]), 4u);
  EXPECT_EQ(ptex_test::LoadLE<std::uint32_t>(&th[16]) >> 30, 1u);
}

// Without reductions the file has one level; without tiling a large face is one block.
TEST(PtexWriterOptionsTest, NoReductionsNoTiles) {
  TempDir dir;
  const std::string path = (dir / "plain.ptx").string();
  PtexWriterOptions options;
  options.write_reductions = false;
  options.tile_large_faces = false;
  PtexFaceInfo info;
  info.ulog2 = 9;
  info.vlog2 = 8;
  std::vector<float> t(512 * 256);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = std::sin(0.01f * float(i));
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, options, 1);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, t).ok());
    ASSERT_TRUE(w->Finish().ok());
  }
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->header().num_levels, 1);
  EXPECT_EQ(file->NumStoredLevels(PtexFaceId(0)), 1);
  EXPECT_EQ(file->BlockInfo(PtexFaceId(0), 0).encoding, PtexBlockInfo::Encoding::kZipped);
  std::vector<float> got;
  ASSERT_TRUE(file->ReadFace(PtexFaceId(0), 0, got).ok());
  EXPECT_EQ(got, t);
}

// Adding a key again replaces its value in place; small and large items keep their order
// within their sections.
TEST(PtexWriterMetaData, ReplaceKeepsPosition) {
  TempDir dir;
  const std::string path = (dir / "meta.ptx").string();
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 1);
    ASSERT_TRUE(w.ok());
    const std::vector<std::int32_t> one = {1}, two = {2, 3};
    ASSERT_TRUE(w->AddMetaData("first", std::span<const std::int32_t>(one)).ok());
    ASSERT_TRUE(w->AddMetaData("second", "s").ok());
    ASSERT_TRUE(w->AddMetaData("first", std::span<const std::int32_t>(two)).ok());
    const std::vector<double> big(200, 1.5);  // 1600 bytes: a large item
    ASSERT_TRUE(w->AddMetaData("big", std::span<const double>(big)).ok());
    ASSERT_TRUE(w->AddMetaData("last", "x").ok());
    ASSERT_TRUE(w->Finish().ok());
  }
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok());
  auto meta = file->meta_data();
  ASSERT_EQ(meta.size(), 4u);
  EXPECT_EQ(meta[0].key, "first");
  EXPECT_EQ(meta[0].AsInt32(), (std::vector<std::int32_t>{2, 3}));
  EXPECT_EQ(meta[1].key, "second");
  EXPECT_EQ(meta[2].key, "last");
  EXPECT_EQ(meta[3].key, "big");
  EXPECT_TRUE(meta[3].large);
  EXPECT_EQ(meta[3].AsDouble(), std::vector<double>(200, 1.5));
}

// Bilinear sampling: texel centres give texel values; in between, bilinear weights; outside
// the centres, clamped to the border texels.
TEST(PtexFileSample, BilinearWithTexelCentresAndClamping) {
  TempDir dir;
  const std::string path = (dir / "s.ptx").string();
  PtexFaceInfo info;
  info.ulog2 = 2;
  info.vlog2 = 1;  // 4x2
  const std::vector<float> t = {0, 1, 2, 3, 10, 11, 12, 13};
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 2);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, t).ok());
    ASSERT_TRUE(w->SetConstantFace(PtexFaceId(1), info, std::vector<float>{4.5f}).ok());
    ASSERT_TRUE(w->Finish().ok());
  }
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok());
  const PtexFaceId f(0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i)
      EXPECT_FLOAT_EQ(file->Sample(f, (i + 0.5f) / 4, (j + 0.5f) / 2), t[std::size_t(j * 4 + i)]);
  // Between texel centres (u = 0.25 is between texels 0 and 1; v = 0.5 between rows).
  EXPECT_FLOAT_EQ(file->Sample(f, 0.25f, 0.25f), 0.5f);
  EXPECT_FLOAT_EQ(file->Sample(f, 0.25f, 0.5f), 0.5f * (0.5f + 10.5f));
  // Clamped at the border: the outer half texel is flat.
  EXPECT_FLOAT_EQ(file->Sample(f, 0.0f, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(file->Sample(f, 1.0f, 1.0f), 13.0f);
  EXPECT_FLOAT_EQ(file->Sample(f, 0.05f, 0.9f), 10.0f);
  EXPECT_FLOAT_EQ(file->Sample(PtexFaceId(1), 0.3f, 0.7f), 4.5f);
  file->ReleaseSampleCache();
  EXPECT_FLOAT_EQ(file->Sample(f, 0.25f, 0.25f), 0.5f);
}

TEST(PtexFileSample, TriangleTexels) {
  TempDir dir;
  const std::string path = (dir / "tri.ptx").string();
  PtexWriterOptions options;
  options.mesh_type = PtexMeshType::kTriangle;
  PtexFaceInfo info;
  info.ulog2 = info.vlog2 = 2;  // N = 4
  std::vector<float> t(16);
  for (int i = 0; i < 16; ++i) t[std::size_t(i)] = float(i);
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, options, 1);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, t).ok());
    ASSERT_TRUE(w->Finish().ok());
  }
  StatusOr<PtexFile> file = PtexFile::Open(path);
  ASSERT_TRUE(file.ok());
  // Upright texel (i, j) has its centroid at ((i + 1/3)/N, (j + 1/3)/N), stored at (i, j).
  EXPECT_EQ(file->Sample(PtexFaceId(0), (1 + 1 / 3.f) / 4, (2 + 1 / 3.f) / 4), t[2 * 4 + 1]);
  // Inverted texel of row j, column i: centroid ((i + 2/3)/N, (j + 2/3)/N), stored at
  // (N-1-j, N-1-i).
  EXPECT_EQ(file->Sample(PtexFaceId(0), (1 + 2 / 3.f) / 4, (0 + 2 / 3.f) / 4), t[(3 - 1) * 4 + 3]);
}

// An unfinished writer leaves no file and no temporary; an existing target is untouched.
TEST(PtexWriterAtomic, NoFileWithoutFinish) {
  TempDir dir;
  const std::string path = (dir / "map.ptx").string();
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 2);
    ASSERT_TRUE(w.ok());
    PtexFaceInfo info;
    info.ulog2 = info.vlog2 = 3;
    ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, std::vector<float>(64, 0.5f)).ok());
  }
  EXPECT_EQ(dir.FileCount(), 0u);
  ptex_test::WriteBytes(path, {1, 2, 3});
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 2);
    ASSERT_TRUE(w.ok());
  }
  EXPECT_EQ(ReadBytes(path), (std::vector<std::uint8_t>{1, 2, 3}));
  EXPECT_EQ(dir.FileCount(), 1u);
  {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 2);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->Finish().ok());
    EXPECT_FALSE(w->Finish().ok());
  }
  EXPECT_EQ(dir.FileCount(), 1u);
  EXPECT_TRUE(PtexFile::Open(path).ok());
}

// Every invalid input is a Status naming the file and face, and stores nothing.
TEST(PtexWriterErrors, InvalidInput) {
  TempDir dir;
  const std::string path = (dir / "bad.ptx").string();
  auto create_fails = [&](PtexWriterOptions o, int n, const std::string& what) {
    StatusOr<PtexWriter> w = PtexWriter::Create(path, o, n);
    ASSERT_FALSE(w.ok()) << what;
    EXPECT_NE(w.status().message().find("bad.ptx"), std::string::npos) << w.status().message();
  };
  PtexWriterOptions o;
  create_fails(o, 0, "no faces");
  o.num_channels = 0;
  create_fails(o, 1, "no channels");
  o.num_channels = 2;
  o.alpha_channel = 2;
  create_fails(o, 1, "alpha out of range");
  o.alpha_channel = -1;
  o.compression_level = 13;
  create_fails(o, 1, "libdeflate level");
  o.compressor = PtexCompressor::kZlib;
  o.compression_level = 10;
  create_fails(o, 1, "zlib level");
  std::ofstream(dir / "file.txt") << "x";  // a file where a folder would be made
  EXPECT_FALSE(PtexWriter::Create((dir / "file.txt" / "x.ptx").string(), {}, 1).ok());
  std::filesystem::remove(dir / "file.txt");

  StatusOr<PtexWriter> w = PtexWriter::Create(path, {}, 3);
  ASSERT_TRUE(w.ok());
  PtexFaceInfo info;
  info.ulog2 = 2;
  info.vlog2 = 1;
  const std::vector<float> good(8, 0.25f);
  auto fails = [&](const Status& s, const std::string& needle) {
    ASSERT_FALSE(s.ok()) << needle;
    EXPECT_NE(s.message().find(needle), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(".ptx: "), std::string::npos) << s.message();
  };
  fails(w->SetFace(PtexFaceId(3), info, good), "face id 3");
  fails(w->SetFace(PtexFaceId(-1), info, good), "face id -1");
  fails(w->SetFace(PtexFaceId(0), info, std::vector<float>(7)), "7 values");
  std::vector<float> nan = good;
  nan[5] = std::nanf("");
  fails(w->SetFace(PtexFaceId(0), info, nan), "texel 5 channel 0 is not finite");
  PtexFaceInfo bad = info;
  bad.ulog2 = 16;
  fails(w->SetFace(PtexFaceId(0), bad, good), "resolution");
  bad = info;
  bad.vlog2 = -1;
  fails(w->SetFace(PtexFaceId(0), bad, good), "resolution");
  bad = info;
  bad.adjfaces[2] = 3;
  fails(w->SetFace(PtexFaceId(0), bad, good), "edge 2");
  bad = info;
  bad.adjfaces[1] = 1;
  bad.adjedges[1] = 4;
  fails(w->SetFace(PtexFaceId(0), bad, good), "edge id 4");
  fails(w->SetFaceRaw(PtexFaceId(0), info, std::vector<std::uint8_t>(31)), "31 bytes");
  fails(w->SetConstantFace(PtexFaceId(0), info, std::vector<float>{1, 2}), "2 channels");
  ASSERT_TRUE(w->SetFace(PtexFaceId(0), info, good).ok());
  fails(w->SetFace(PtexFaceId(0), info, good), "set twice");
  fails(w->AddMetaData("", "x"), "key");
  fails(w->AddMetaData(std::string(255, 'k'), "x"), "255 bytes");
  fails(w->AddMetaData("empty", std::span<const float>()), "no values");
  EXPECT_TRUE(w->AddMetaData(std::string(254, 'k'), "x").ok());
  EXPECT_EQ(w->faces_set(), 1);
  ASSERT_TRUE(w->Finish().ok());
  fails(w->SetFace(PtexFaceId(1), info, good), "after Finish");

  PtexWriterOptions tri;
  tri.mesh_type = PtexMeshType::kTriangle;
  StatusOr<PtexWriter> t = PtexWriter::Create((dir / "tri.ptx").string(), tri, 1);
  ASSERT_TRUE(t.ok());
  fails(t->SetFace(PtexFaceId(0), info, good), "square");
}

// The writer holds compressed data only: a smooth 2^20-texel float face takes far less.
TEST(PtexWriterStreaming, HoldsOnlyCompressedBlocks) {
  TempDir dir;
  StatusOr<PtexWriter> w = PtexWriter::Create((dir / "m.ptx").string(), {}, 16);
  ASSERT_TRUE(w.ok());
  PtexFaceInfo info;
  info.ulog2 = info.vlog2 = 8;
  std::vector<float> t(256 * 256);
  for (int f = 0; f < 16; ++f) {
    for (std::size_t i = 0; i < t.size(); ++i)
      t[i] = std::floor(std::sin(0.01f * float(i % 256) + f) * 64) / 64;
    ASSERT_TRUE(w->SetFace(PtexFaceId(f), info, t).ok());
  }
  EXPECT_GT(w->compressed_bytes(), 0u);
  EXPECT_LT(w->compressed_bytes(), 16 * t.size() * sizeof(float) / 4);
  ASSERT_TRUE(w->Finish().ok());
}

}  // namespace
}  // namespace dispex
