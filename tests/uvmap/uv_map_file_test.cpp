// UDIM OpenEXR tiles: round trip (float exact, half rounded), header attributes, the same bytes
// for the same tile, rows ordered as images are (scanline 0 at v = 1), tile sets by pattern,
// bilinear reads, and bad files refused naming the file.
#include <ImfFrameBuffer.h>
#include <ImfInputFile.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/uv_map.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;

class TileFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("dispex_uv_map_file_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

UvMapTile Ramp(int udim, int n, int channels) {
  UvMapTile tile;
  tile.udim = udim;
  tile.resolution = n;
  tile.channels = channels;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < channels; ++c) {
        tile.values.push_back(0.001f * static_cast<float>(i) - 0.01f * static_cast<float>(j) +
                              0.37f * static_cast<float>(c) + 1e-5f * static_cast<float>(udim));
      }
    }
  }
  tile.attributes = {{"dispex:space", "normal"}, {"dispex:units", "object units"}};
  return tile;
}

TEST_F(TileFiles, FloatRoundTripIsExact) {
  for (int channels : {1, 3}) {
    const UvMapTile tile = Ramp(1012, 17, channels);
    const std::string path = Path("m.1012.exr");
    ASSERT_TRUE(WriteUvMapTile(path, tile, false).ok());
    auto back = ReadUvMapTile(path);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(back->udim, 1012);
    EXPECT_EQ(back->resolution, 17);
    EXPECT_EQ(back->channels, channels);
    EXPECT_EQ(back->values, tile.values);
    bool space = false;
    for (const auto& [k, v] : back->attributes) space |= k == "dispex:space" && v == "normal";
    EXPECT_TRUE(space);
    EXPECT_TRUE(IsUvMapPath(path));
  }
}

TEST_F(TileFiles, HalfRoundTripRoundsToHalf) {
  const UvMapTile tile = Ramp(1001, 8, 1);
  const std::string path = Path("m.1001.exr");
  ASSERT_TRUE(WriteUvMapTile(path, tile, true).ok());
  auto back = ReadUvMapTile(path);
  ASSERT_TRUE(back.ok());
  double worst = 0;
  for (std::size_t i = 0; i < tile.values.size(); ++i) {
    worst = std::max(worst, std::abs(double(back->values[i]) - tile.values[i]) /
                                std::max(1e-3, std::abs(double(tile.values[i]))));
  }
  EXPECT_GT(worst, 0);     // rounded ...
  EXPECT_LT(worst, 1e-3);  // ... to 11 significant bits
}

TEST_F(TileFiles, SameTileSameBytes) {
  const UvMapTile tile = Ramp(1001, 33, 3);
  ASSERT_TRUE(WriteUvMapTile(Path("a.1001.exr"), tile, false).ok());
  ASSERT_TRUE(WriteUvMapTile(Path("b.1001.exr"), tile, false).ok());
  EXPECT_EQ(Slurp(Path("a.1001.exr")), Slurp(Path("b.1001.exr")));
}

TEST_F(TileFiles, TileSetByPatternAndBilinearReads) {
  UvMapTile a = Ramp(1001, 4, 1), b = Ramp(1013, 4, 1);
  std::fill(b.values.begin(), b.values.end(), 7.0f);
  ASSERT_TRUE(WriteUvMapTile(Path("shape.1001.exr"), a, false).ok());
  ASSERT_TRUE(WriteUvMapTile(Path("shape.1013.exr"), b, false).ok());
  ASSERT_TRUE(WriteUvMapTile(Path("other.1002.exr"), a, false).ok());  // another shape's
  auto map = UvMap::Open(Path("shape.<UDIM>.exr"));
  ASSERT_TRUE(map.ok()) << map.status().message();
  ASSERT_EQ(map->tiles().size(), 2u);
  EXPECT_EQ(map->tiles()[0].udim, 1001);
  EXPECT_EQ(map->tiles()[1].udim, 1013);
  float out[1];
  // Texel (1, 2) of 1001 at its centre; between texels (1, 2) and (2, 2).
  ASSERT_TRUE(map->Sample(1.5 / 4, 2.5 / 4, out));
  EXPECT_FLOAT_EQ(out[0], a.values[2 * 4 + 1]);
  ASSERT_TRUE(map->Sample(2.0 / 4, 2.5 / 4, out));
  EXPECT_FLOAT_EQ(out[0], 0.5f * (a.values[2 * 4 + 1] + a.values[2 * 4 + 2]));
  // Clamped at the tile's border, not wrapped.
  ASSERT_TRUE(map->Sample(0.01, 0.01, out));
  EXPECT_FLOAT_EQ(out[0], a.values[0]);
  ASSERT_TRUE(map->Sample(2.5, 1.5, out));  // tile 1013
  EXPECT_FLOAT_EQ(out[0], 7.0f);
  EXPECT_FALSE(map->Sample(1.5, 0.5, out));  // no tile 1002 of this shape
  EXPECT_EQ(out[0], 0.0f);
  // One tile's name opens the whole set.
  auto same = UvMap::Open(Path("shape.1013.exr"));
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->tiles().size(), 2u);
}

TEST_F(TileFiles, RowsAreStoredTopDown) {
  // OpenEXR's scanline 0 is the image's top (v = 1): a tile whose bottom row (v = 0) is 1 and
  // the rest 0 has its last scanline 1, read here by OpenEXR itself.
  UvMapTile tile;
  tile.udim = 1001;
  tile.resolution = 4;
  tile.values.assign(16, 0.0f);
  for (int i = 0; i < 4; ++i) tile.values[i] = 1.0f;
  const std::string path = Path("r.1001.exr");
  ASSERT_TRUE(WriteUvMapTile(path, tile, false).ok());
  Imf::InputFile file(path.c_str());
  float pixels[16];
  Imf::FrameBuffer frame;
  frame.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels), sizeof(float),
                               4 * sizeof(float)));
  file.setFrameBuffer(frame);
  file.readPixels(0, 3);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(pixels[i], 0.0f);       // scanline 0: the top
    EXPECT_EQ(pixels[12 + i], 1.0f);  // scanline 3: the bottom, v = 0
  }
  auto back = ReadUvMapTile(path);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->values[0], 1.0f);
  EXPECT_EQ(back->values[12], 0.0f);
}

TEST_F(TileFiles, BadFilesNameTheFile) {
  std::ofstream(Path("junk.1001.exr")) << "not an image";
  auto junk = ReadUvMapTile(Path("junk.1001.exr"));
  ASSERT_FALSE(junk.ok());
  EXPECT_EQ(junk.status().message().rfind(Path("junk.1001.exr") + ": ", 0), 0u)
      << junk.status().message();
  EXPECT_EQ(junk.status().message().find('\n'), std::string::npos);
  auto missing = ReadUvMapTile(Path("missing.1001.exr"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("missing.1001.exr"), std::string::npos);
  auto none = UvMap::Open(Path("nothing.<UDIM>.exr"));
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("no tile"), std::string::npos);
  auto bad_pattern = UvMap::Open(Path("x.<UDIM>.png"));
  ASSERT_FALSE(bad_pattern.ok());
  // Tiles that disagree on resolution.
  ASSERT_TRUE(WriteUvMapTile(Path("mix.1001.exr"), Ramp(1001, 4, 1), false).ok());
  ASSERT_TRUE(WriteUvMapTile(Path("mix.1002.exr"), Ramp(1002, 8, 1), false).ok());
  auto mixed = UvMap::Open(Path("mix.<UDIM>.exr"));
  ASSERT_FALSE(mixed.ok());
  EXPECT_NE(mixed.status().message().find("mix.1002.exr"), std::string::npos);
  // A wrong-sized tile is refused before anything is written.
  UvMapTile wrong = Ramp(1001, 4, 1);
  wrong.values.pop_back();
  EXPECT_FALSE(WriteUvMapTile(Path("w.1001.exr"), wrong, false).ok());
  EXPECT_FALSE(fs::exists(Path("w.1001.exr")));
}

// A set of tiles is written whole or not at all: when its third tile cannot be written, the
// first two keep the previous run's bytes and no temporary file is left.
TEST_F(TileFiles, ATileSetIsCommittedTogether) {
  const std::vector<std::string> paths = {Path("set.1001.exr"), Path("set.1002.exr"),
                                          Path("set.1003.exr")};
  std::vector<UvMapTile> old_tiles = {Ramp(1001, 4, 1), Ramp(1002, 4, 1), Ramp(1003, 4, 1)};
  ASSERT_TRUE(WriteUvMapTiles(paths, old_tiles, false).ok());
  const std::string old_first = Slurp(paths[0]), old_second = Slurp(paths[1]);
  std::vector<UvMapTile> new_tiles = {Ramp(1001, 8, 3), Ramp(1002, 8, 3), Ramp(1003, 8, 3)};
  ASSERT_TRUE(WriteUvMapTiles({paths.data(), 2}, {new_tiles.data(), 2}, false).ok());
  EXPECT_NE(Slurp(paths[0]), old_first);  // the control: a set that can be written is
  ASSERT_TRUE(WriteUvMapTiles({paths.data(), 2}, {old_tiles.data(), 2}, false).ok());
  new_tiles[2].values.pop_back();
  auto failed = WriteUvMapTiles(paths, new_tiles, false);
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.message().find("set.1003.exr"), std::string::npos) << failed.message();
  EXPECT_EQ(Slurp(paths[0]), old_first);
  EXPECT_EQ(Slurp(paths[1]), old_second);
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos) << entry.path();
    ++files;
  }
  EXPECT_EQ(files, 3u);
}

}  // namespace
}  // namespace dispex
