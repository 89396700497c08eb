// PNG output and input: round trips, libpng's own writer as the oracle for reading other
// colour types, and clear errors for bad files and paths.
#include <gtest/gtest.h>
#include <png.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "dispex/render.h"
#include "render_test_util.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;
using render_test::TempDir;

Image Pattern(int w, int h) {
  Image image(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      image.set(x, y,
                {static_cast<std::uint8_t>(x * 37 + y), static_cast<std::uint8_t>(y * 11),
                 static_cast<std::uint8_t>((x ^ y) * 5)});
    }
  }
  return image;
}

TEST(Png, RoundTripKeepsEveryPixel) {
  TempDir dir;
  const Image image = Pattern(67, 41);
  ASSERT_TRUE(WritePng(dir / "a.png", image).ok());
  auto back = ReadPng(dir / "a.png");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->width, 67);
  EXPECT_EQ(back->height, 41);
  EXPECT_EQ(back->rgb, image.rgb);
}

TEST(Png, EncodedBytesAreAPngThatLibpngReads) {
  const Image image = Pattern(9, 5);
  auto bytes = EncodePng(image);
  ASSERT_TRUE(bytes.ok());
  ASSERT_GE(bytes->size(), 8u);
  EXPECT_EQ(png_sig_cmp(bytes->data(), 0, 8), 0);
  // libpng's simplified reader as an independent decoder.
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_memory(&png, bytes->data(), bytes->size()));
  png.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(png));
  ASSERT_TRUE(png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr));
  EXPECT_EQ(png.width, 9u);
  EXPECT_EQ(png.height, 5u);
  EXPECT_EQ(pixels, image.rgb);
}

TEST(Png, ReadsGreyAndAlphaImagesWrittenByLibpng) {
  TempDir dir;
  // A grey+alpha 8-bit image written by libpng's simplified API.
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = 3;
  png.height = 2;
  png.format = PNG_FORMAT_GA;
  const std::uint8_t ga[] = {0, 255, 100, 255, 255, 255, 7, 255, 8, 255, 9, 255};
  ASSERT_TRUE(png_image_write_to_file(&png, (dir / "ga.png").c_str(), 0, ga, 0, nullptr));
  auto back = ReadPng(dir / "ga.png");
  ASSERT_TRUE(back.ok()) << back.status().message();
  ASSERT_EQ(back->width, 3);
  ASSERT_EQ(back->height, 2);
  for (int i = 0; i < 6; ++i) {
    const std::uint8_t g = ga[2 * i];
    EXPECT_EQ(back->at(i % 3, i / 3), (std::array<std::uint8_t, 3>{g, g, g})) << i;
  }
}

TEST(Png, ReadsSixteenBitRgbaAsEightBitRgb) {
  TempDir dir;
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = 2;
  png.height = 1;
  png.format = PNG_FORMAT_LINEAR_RGB_ALPHA;  // 16-bit linear channels
  const std::uint16_t rgba[] = {65535, 0, 0, 65535, 0, 65535, 65535, 65535};
  ASSERT_TRUE(png_image_write_to_file(&png, (dir / "c16.png").c_str(), 0, rgba, 0, nullptr));
  auto back = ReadPng(dir / "c16.png");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->at(0, 0), (std::array<std::uint8_t, 3>{255, 0, 0}));
  EXPECT_EQ(back->at(1, 0), (std::array<std::uint8_t, 3>{0, 255, 255}));
}

TEST(Png, MissingFileIsAnErrorNamingIt) {
  TempDir dir;
  auto back = ReadPng(dir / "missing.png");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("missing.png"), std::string::npos)
      << back.status().message();
}

TEST(Png, NotAPngIsAnError) {
  TempDir dir;
  render_test::WriteText(dir / "text.png", "hello, this is not an image");
  auto back = ReadPng(dir / "text.png");
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.status().message().find("not a PNG"), std::string::npos);
  render_test::WriteText(dir / "empty.png", "");
  EXPECT_FALSE(ReadPng(dir / "empty.png").ok());
}

TEST(Png, EveryTruncationIsAnErrorNotACrash) {
  const Image image = Pattern(31, 17);
  auto bytes = EncodePng(image);
  ASSERT_TRUE(bytes.ok());
  for (std::size_t cut = 0; cut < bytes->size(); cut += 7) {
    auto back = DecodePng(bytes->data(), cut, "cut.png");
    EXPECT_FALSE(back.ok()) << cut;
    if (!back.ok()) {
      EXPECT_EQ(back.status().message().rfind("cut.png", 0), 0u);
    }
  }
  // A flipped byte in the image data: either an error or an image of the right size.
  std::vector<std::uint8_t> corrupt = *bytes;
  corrupt[corrupt.size() / 2] ^= 0x5a;
  auto back = DecodePng(corrupt.data(), corrupt.size(), "corrupt.png");
  if (back.ok()) {
    EXPECT_EQ(back->rgb.size(), image.rgb.size());
  }
}

TEST(Png, UnwritablePathIsAnErrorAndLeavesNothing) {
  TempDir dir;
  std::ofstream(dir / "file.txt") << "x";  // a file where a folder would be made
  Status st = WritePng(dir / "file.txt/folder/a.png", Pattern(4, 4));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("a.png"), std::string::npos) << st.message();
  fs::remove(dir / "file.txt");
  EXPECT_TRUE(fs::is_empty(dir.path()));
  // Missing folders are made.
  ASSERT_TRUE(WritePng(dir / "new/folder/a.png", Pattern(4, 4)).ok());
  EXPECT_TRUE(fs::exists(dir / "new/folder/a.png"));
}

TEST(Png, EmptyImageIsAnError) {
  EXPECT_FALSE(EncodePng(Image()).ok());
  Image wrong(4, 4);
  wrong.rgb.pop_back();
  EXPECT_FALSE(EncodePng(wrong).ok());
}

}  // namespace
}  // namespace dispex
