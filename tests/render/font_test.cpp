// The built-in bitmap font: metrics, glyph placement, scaling, clipping, distinct glyphs.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "dispex/render.h"
#include "render/bitmap_font.h"

namespace dispex::render {
namespace {

constexpr std::array<std::uint8_t, 3> kInk = {255, 255, 0};

std::string GlyphBits(char c, FontSize size) {
  std::string bits;
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 5; ++x) bits += GlyphPixel(c, size, x, y) ? '#' : '.';
  }
  return bits;
}

TEST(BitmapFont, Metrics) {
  EXPECT_EQ(TextWidth("", FontSize::kSmall), 0);
  EXPECT_EQ(TextWidth("7", FontSize::kSmall), 5);
  EXPECT_EQ(TextWidth("123", FontSize::kSmall), 17);
  EXPECT_EQ(TextWidth("123", FontSize::kSmall, 2), 34);
  EXPECT_EQ(TextWidth("123", FontSize::kTiny), 11);
  EXPECT_EQ(TextHeight(FontSize::kSmall), 8);
  EXPECT_EQ(TextHeight(FontSize::kTiny, 3), 15);
}

TEST(BitmapFont, DrawsEachGlyphPixelAsAScaledBlock) {
  for (FontSize size : {FontSize::kSmall, FontSize::kTiny}) {
    for (int scale : {1, 2, 3}) {
      const std::string text = size == FontSize::kSmall ? "a-9.e+" : "4096";
      Image image(80, 40);
      const int x0 = 3, y0 = 2;
      DrawText(image, x0, y0, text, size, scale, kInk);
      for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) {
          bool expected = false;
          const int cx = (x - x0), cy = (y - y0);
          if (cx >= 0 && cy >= 0) {
            const int advance = FontAdvance(size) * scale;
            const int k = cx / advance;
            if (k < static_cast<int>(text.size())) {
              expected = GlyphPixel(text[static_cast<std::size_t>(k)], size, (cx % advance) / scale,
                                    cy / scale);
            }
          }
          EXPECT_EQ(image.at(x, y) == kInk, expected)
              << text << " scale " << scale << " at " << x << "," << y;
        }
      }
    }
  }
}

TEST(BitmapFont, GlyphsAreDistinctAndUpperCaseIsLowerCase) {
  std::set<std::string> seen;
  const std::string chars = "0123456789abcdefghijklmnopqrstuvwxyz+-.,:;=()[]/%_|<>'?";
  for (char c : chars) {
    const std::string bits = GlyphBits(c, FontSize::kSmall);
    EXPECT_NE(bits.find('#'), std::string::npos) << c;
    EXPECT_TRUE(seen.insert(bits).second) << "glyph '" << c << "' repeats another";
  }
  EXPECT_EQ(GlyphBits('Q', FontSize::kSmall), GlyphBits('q', FontSize::kSmall));
  EXPECT_EQ(GlyphBits('\x01', FontSize::kSmall), GlyphBits('?', FontSize::kSmall));
  EXPECT_EQ(GlyphBits(' ', FontSize::kSmall).find('#'), std::string::npos);
  std::set<std::string> tiny;
  for (char c = '0'; c <= '9'; ++c) EXPECT_TRUE(tiny.insert(GlyphBits(c, FontSize::kTiny)).second);
}

TEST(BitmapFont, ClipsAtTheImageBorder) {
  Image image(10, 6);
  DrawText(image, -7, -3, "88", FontSize::kSmall, 2, kInk);
  DrawText(image, 6, 3, "88", FontSize::kSmall, 2, kInk);
  int inked = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) inked += image.at(x, y) == kInk;
  }
  EXPECT_GT(inked, 0);
}

}  // namespace
}  // namespace dispex::render
