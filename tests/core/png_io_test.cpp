#include "core/png_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace dispex {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> Ramp(std::size_t n) {
  std::vector<std::uint8_t> data(n);
  for (std::size_t i = 0; i < n; ++i) data[i] = static_cast<std::uint8_t>(i * 37 + 11);
  return data;
}

TEST(CorePng, GreyAndRgbRoundTrip) {
  for (int channels : {1, 3}) {
    const int width = 7, height = 5;
    const std::vector<std::uint8_t> data = Ramp(std::size_t(width * height * channels));
    auto bytes = EncodePngPixels(data.data(), data.size(), width, height, channels);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    auto back = DecodePngPixels(bytes->data(), bytes->size(), "t.png", PngConversion::kNative);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(back->width, width);
    EXPECT_EQ(back->height, height);
    EXPECT_EQ(back->channels, channels);
    EXPECT_EQ(back->bit_depth, 8);
    EXPECT_EQ(back->data, data);
  }
}

TEST(CorePng, BadShapesAreErrors) {
  const std::vector<std::uint8_t> data = Ramp(12);
  EXPECT_FALSE(EncodePngPixels(data.data(), data.size(), 0, 4, 3).ok());
  EXPECT_FALSE(EncodePngPixels(data.data(), data.size(), 2, 2, 2).ok());
  EXPECT_FALSE(EncodePngPixels(data.data(), data.size(), 2, 2, 1).ok());
  EXPECT_TRUE(EncodePngPixels(data.data(), data.size(), 2, 2, 3).ok());
}

TEST(CorePng, WriteIsAtomicAndNamesThePath) {
  const fs::path dir =
      fs::temp_directory_path() / ("dispex_core_png_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::uint8_t> data = Ramp(6);
  const std::string path = (dir / "g.png").string();
  ASSERT_TRUE(WritePngPixels(path, data.data(), data.size(), 3, 2, 1).ok());
  auto back = ReadPngPixels(path, PngConversion::kNative);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->data, data);
  const Status bad = WritePngPixels((dir / "x.png").string(), data.data(), 5, 3, 2, 1);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("x.png"), std::string::npos) << bad.message();
  fs::remove(path);
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dispex
