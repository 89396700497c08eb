// The map atlas: known maps give known pixels (tile colours, sign colours, grey extremes,
// texel orientation, reductions), tile sizes and face order, the legend, labels, errors and
// determinism.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "dispex/render.h"
#include "render_test_util.h"

namespace dispex {
namespace {

using render_test::TempDir;
using Rgb = std::array<std::uint8_t, 3>;

constexpr Rgb kMagenta = {255, 0, 255};

// Writes one face per entry of `faces`: {ulog2, vlog2, texels (v-major)}; a single texel
// value for a face of more texels means a constant face.
struct FaceSpec {
  int ulog2 = 0, vlog2 = 0;
  std::vector<float> texels;
};

PtexFile WriteAndOpen(const std::string& path, const std::vector<FaceSpec>& faces,
                      PtexDataType type = PtexDataType::kFloat) {
  PtexWriterOptions options;
  options.data_type = type;
  auto writer = PtexWriter::Create(path, options, static_cast<int>(faces.size()));
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  for (std::size_t f = 0; f < faces.size(); ++f) {
    PtexFaceInfo info;
    info.ulog2 = static_cast<std::int8_t>(faces[f].ulog2);
    info.vlog2 = static_cast<std::int8_t>(faces[f].vlog2);
    std::vector<float> texels = faces[f].texels;
    if (texels.size() == 1) texels.assign(info.num_texels(), texels[0]);
    Status st = writer->SetFace(PtexFaceId(static_cast<int>(f)), info, texels);
    EXPECT_TRUE(st.ok()) << st.message();
  }
  EXPECT_TRUE(writer->Finish().ok());
  auto file = PtexFile::Open(path);
  EXPECT_TRUE(file.ok()) << file.status().message();
  return std::move(*file);
}

// Every pixel of the tile equals `colour`.
void ExpectUniformTile(const Image& image, const AtlasRect& r, Rgb colour, const char* what) {
  int wrong = 0;
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) wrong += image.at(x, y) != colour;
  }
  EXPECT_EQ(wrong, 0) << what << ": tile at " << r.x << "," << r.y << " of " << r.width << "x"
                      << r.height << " has pixels other than (" << int(colour[0]) << ","
                      << int(colour[1]) << "," << int(colour[2]) << ")";
}

TEST(AtlasColour, MatchesTheDocumentedFormulas) {
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, -2, 3, -2), (Rgb{0, 0, 0}));
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, -2, 3, 3), (Rgb{255, 255, 255}));
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, -2, 3, 0), (Rgb{102, 102, 102}));  // 0.4 * 255
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, -2, 3, 10), (Rgb{255, 255, 255}));
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, 1, 1, 1), (Rgb{128, 128, 128}));
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, -4, 4, 4), (Rgb{0, 255, 0}));
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, -4, 4, -1), (Rgb{64, 0, 0}));  // 63.75
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, -4, 4, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, -4, 4, -9), (Rgb{255, 0, 0}));
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, 0, 0, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(AtlasColour(AtlasMode::kSigned, -1, 1, NAN), kMagenta);
  EXPECT_EQ(AtlasColour(AtlasMode::kGrey, -1, 1, INFINITY), kMagenta);
}

TEST(Atlas, ConstantFacesGiveUniformTilesOfTheSignColour) {
  TempDir dir;
  const PtexFile map = WriteAndOpen(
      dir / "c.ptx",
      {{0, 0, {-1.0f}}, {2, 2, {-0.5f}}, {3, 1, {0.5f}}, {1, 1, {1.0f}}, {0, 0, {0.0f}}});
  AtlasLayout layout;
  auto image = RenderAtlas(map, AtlasOptions{}, &layout);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(layout.range_min, -1);
  EXPECT_EQ(layout.range_max, 1);
  ASSERT_EQ(layout.tiles.size(), 5u);
  ExpectUniformTile(*image, layout.tiles[0].rect, {255, 0, 0}, "-1");
  ExpectUniformTile(*image, layout.tiles[1].rect, {128, 0, 0}, "-0.5");
  ExpectUniformTile(*image, layout.tiles[2].rect, {0, 128, 0}, "+0.5");
  ExpectUniformTile(*image, layout.tiles[3].rect, {0, 255, 0}, "+1");
  ExpectUniformTile(*image, layout.tiles[4].rect, {0, 0, 0}, "0");
}

TEST(Atlas, GreyModeSpansBlackToWhite) {
  TempDir dir;
  const PtexFile map =
      WriteAndOpen(dir / "g.ptx", {{1, 1, {-2.0f}}, {1, 1, {0.0f}}, {1, 1, {3.0f}}});
  AtlasOptions options;
  options.mode = AtlasMode::kGrey;
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(layout.range_min, -2);
  EXPECT_EQ(layout.range_max, 3);
  ExpectUniformTile(*image, layout.tiles[0].rect, {0, 0, 0}, "min");
  ExpectUniformTile(*image, layout.tiles[1].rect, {102, 102, 102}, "0");
  ExpectUniformTile(*image, layout.tiles[2].rect, {255, 255, 255}, "max");
}

TEST(Atlas, GivenRangeIsSymmetricAndClamps) {
  TempDir dir;
  const PtexFile map = WriteAndOpen(dir / "r.ptx", {{0, 0, {0.5f}}, {0, 0, {-0.125f}}});
  AtlasOptions options;
  options.range = 0.25;
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(layout.range_min, -0.25);
  EXPECT_EQ(layout.range_max, 0.25);
  ExpectUniformTile(*image, layout.tiles[0].rect, {0, 255, 0}, "clamped");
  ExpectUniformTile(*image, layout.tiles[1].rect, {128, 0, 0}, "half");
  options.mode = AtlasMode::kGrey;
  image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  ExpectUniformTile(*image, layout.tiles[0].rect, {255, 255, 255}, "grey clamped");
  ExpectUniformTile(*image, layout.tiles[1].rect, {64, 64, 64}, "grey -0.125");  // 0.25 * 255
}

TEST(Atlas, TileSizesAndTexelOrientation) {
  TempDir dir;
  // Face 0: 2x2 texels, v-major: (0,0)=1 (1,0)=2 (0,1)=3 (1,1)=4. Face 1: 4x2. Face 2: 64x64.
  std::vector<float> big(64 * 64);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = float(i % 7) - 3.0f;
  const PtexFile map = WriteAndOpen(
      dir / "t.ptx", {{1, 1, {1, 2, 3, 4}}, {2, 1, {1, 1, 1, 1, -1, -1, -1, -1}}, {6, 6, big}});
  AtlasOptions options;
  options.mode = AtlasMode::kGrey;  // range [-3, 4]
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  const auto& t0 = layout.tiles[0];
  EXPECT_EQ(t0.scale_x, 8);
  EXPECT_EQ(t0.scale_y, 8);
  EXPECT_EQ(t0.rect.width, 16);
  EXPECT_EQ(t0.rect.height, 16);
  EXPECT_EQ(layout.tiles[1].scale_x, 4);  // 4 texels -> 16 pixels
  EXPECT_EQ(layout.tiles[1].scale_y, 8);  // 2 texels -> 16 pixels
  EXPECT_EQ(layout.tiles[1].rect.width, 16);
  EXPECT_EQ(layout.tiles[1].rect.height, 16);
  EXPECT_EQ(layout.tiles[2].scale_x, 1);
  EXPECT_EQ(layout.tiles[2].rect.width, 64);
  auto grey = [&](float v) { return AtlasColour(AtlasMode::kGrey, -3, 4, v); };
  // v = 0 is the bottom row of the tile: texel (0,0) at the bottom left.
  ExpectUniformTile(*image, {t0.rect.x, t0.rect.y + 8, 8, 8}, grey(1), "texel (0,0)");
  ExpectUniformTile(*image, {t0.rect.x + 8, t0.rect.y + 8, 8, 8}, grey(2), "texel (1,0)");
  ExpectUniformTile(*image, {t0.rect.x, t0.rect.y, 8, 8}, grey(3), "texel (0,1)");
  ExpectUniformTile(*image, {t0.rect.x + 8, t0.rect.y, 8, 8}, grey(4), "texel (1,1)");
  const auto& t1 = layout.tiles[1];
  ExpectUniformTile(*image, {t1.rect.x, t1.rect.y, 16, 8}, grey(-1), "face 1 top row");
  ExpectUniformTile(*image, {t1.rect.x, t1.rect.y + 8, 16, 8}, grey(1), "face 1 bottom row");
  const auto& t2 = layout.tiles[2];
  for (int j = 0; j < 64; j += 9) {
    for (int i = 0; i < 64; i += 5) {
      EXPECT_EQ(image->at(t2.rect.x + i, t2.rect.y + 63 - j), grey(big[j * 64 + i]));
    }
  }
}

TEST(Atlas, LargeFacesAreShownReducedByTheMeanOfTexelBlocks) {
  TempDir dir;
  std::vector<float> texels(64 * 32);
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 64; ++i) texels[j * 64 + i] = float(i + 100 * j);
  }
  const PtexFile map = WriteAndOpen(dir / "big.ptx", {{6, 5, texels}});
  AtlasOptions options;
  options.mode = AtlasMode::kGrey;
  options.max_tile = 16;
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  const auto& t = layout.tiles[0];
  EXPECT_EQ(t.reduction, 2);  // 64x32 -> 16x8
  EXPECT_EQ(t.scale_x, 1);
  EXPECT_EQ(t.scale_y, 2);  // 8 texels stretched to the 16-pixel minimum
  EXPECT_EQ(t.rect.width, 16);
  EXPECT_EQ(t.rect.height, 16);
  for (int j = 0; j < 8; ++j) {
    for (int i = 0; i < 16; ++i) {
      double sum = 0;
      for (int y = 4 * j; y < 4 * j + 4; ++y) {
        for (int x = 4 * i; x < 4 * i + 4; ++x) sum += texels[y * 64 + x];
      }
      // The shown range is that of the block means.
      const double lo = (0 + 1 + 2 + 3) / 4.0 + 100 * 1.5, hi = 61.5 + 100 * 29.5;
      const Rgb want = AtlasColour(AtlasMode::kGrey, lo, hi, float(sum / 16));
      EXPECT_EQ(image->at(t.rect.x + i, t.rect.y + 2 * (7 - j)), want) << i << "," << j;
      EXPECT_EQ(image->at(t.rect.x + i, t.rect.y + 2 * (7 - j) + 1), want) << i << "," << j;
    }
  }
}

TEST(Atlas, TilesAreInFaceOrderLeftToRightThenDown) {
  TempDir dir;
  std::vector<FaceSpec> faces;
  for (int f = 0; f < 40; ++f) faces.push_back({0, 0, {float(f + 1)}});
  const PtexFile map = WriteAndOpen(dir / "o.ptx", faces);
  AtlasOptions options;
  options.mode = AtlasMode::kGrey;
  options.width = 100;  // 5 tiles of 16 + 1 per row (the legend may widen the image)
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  for (int f = 1; f < 40; ++f) {
    const auto& a = layout.tiles[f - 1].rect;
    const auto& b = layout.tiles[f].rect;
    EXPECT_TRUE(b.y > a.y || (b.y == a.y && b.x > a.x)) << f;
    EXPECT_TRUE(a.x + a.width < b.x || b.y >= a.y + a.height) << "tiles overlap at " << f;
    EXPECT_LE(b.x + b.width, 100) << f;
  }
  EXPECT_EQ(layout.tiles[5].rect.x, 1);  // the sixth tile starts the second row
  EXPECT_EQ(layout.tiles[5].rect.y, 18);
  // Brightness grows with the face id.
  for (int f = 1; f < 40; ++f) {
    const auto& r = layout.tiles[f].rect;
    const auto& q = layout.tiles[f - 1].rect;
    EXPECT_GT(image->at(r.x + 8, r.y + 8)[0], image->at(q.x + 8, q.y + 8)[0]) << f;
  }
  // Separators between tiles keep the background colour.
  const auto& t0 = layout.tiles[0].rect;
  EXPECT_EQ(image->at(t0.x + t0.width, t0.y), image->at(0, 0));
}

TEST(Atlas, LegendShowsTheGradientAndNumbers) {
  TempDir dir;
  const PtexFile map = WriteAndOpen(dir / "l.ptx", {{2, 2, {-0.25f}}, {2, 2, {0.75f}}});
  for (AtlasMode mode : {AtlasMode::kSigned, AtlasMode::kGrey}) {
    AtlasOptions options;
    options.mode = mode;
    AtlasLayout layout;
    auto image = RenderAtlas(map, options, &layout);
    ASSERT_TRUE(image.ok());
    const AtlasRect& bar = layout.legend_bar;
    ASSERT_GT(bar.width, 100);
    EXPECT_GE(bar.y, layout.legend.y);
    EXPECT_LE(bar.y + bar.height, layout.legend.y + layout.legend.height);
    const int row = bar.y + bar.height / 2;
    for (int i = 0; i < bar.width; ++i) {
      const double value =
          layout.range_min + (i + 0.5) / bar.width * (layout.range_max - layout.range_min);
      EXPECT_EQ(image->at(bar.x + i, row),
                AtlasColour(mode, layout.range_min, layout.range_max, static_cast<float>(value)))
          << i;
    }
    if (mode == AtlasMode::kSigned) {
      EXPECT_GT(image->at(bar.x, row)[0], 240);                  // strong red at the left end
      EXPECT_GT(image->at(bar.x + bar.width - 1, row)[1], 240);  // strong green at the right
      EXPECT_LT(image->at(bar.x + bar.width / 2, row)[0], 8);    // black in the middle
    } else {
      EXPECT_LT(image->at(bar.x, row)[0], 3);
      EXPECT_GT(image->at(bar.x + bar.width - 1, row)[0], 252);
    }
    // Numbers: light text pixels below the bar, at its left end, middle and right end.
    int left = 0, middle = 0, right = 0;
    for (int y = bar.y + bar.height + 1; y < layout.legend.y + layout.legend.height; ++y) {
      for (int x = 0; x < layout.width; ++x) {
        if (image->at(x, y) != Rgb{235, 235, 235}) continue;
        if (x < bar.x + bar.width / 4)
          ++left;
        else if (x > bar.x + 3 * bar.width / 4)
          ++right;
        else
          ++middle;
      }
    }
    EXPECT_GT(left, 10);
    EXPECT_GT(middle, 3);
    EXPECT_GT(right, 10);
  }
}

TEST(Atlas, NonFiniteTexelsAreMagentaAndOutOfTheRange) {
  TempDir dir;
  const std::string path = dir / "nan.ptx";
  PtexWriterOptions options;
  options.data_type = PtexDataType::kHalf;
  auto writer = PtexWriter::Create(path, options, 1);
  ASSERT_TRUE(writer.ok());
  PtexFaceInfo info;
  info.ulog2 = info.vlog2 = 1;
  // Half texels, v-major: 0.5, NaN, -0.25, +inf.
  const std::uint16_t raw[] = {FloatToHalf(0.5f), 0x7e00, FloatToHalf(-0.25f), 0x7c00};
  ASSERT_TRUE(writer
                  ->SetFaceRaw(PtexFaceId(0), info,
                               {reinterpret_cast<const std::uint8_t*>(raw), sizeof raw})
                  .ok());
  ASSERT_TRUE(writer->Finish().ok());
  auto map = PtexFile::Open(path);
  ASSERT_TRUE(map.ok());
  AtlasLayout layout;
  auto image = RenderAtlas(*map, AtlasOptions{}, &layout);
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(layout.range_max, 0.5);
  const auto& r = layout.tiles[0].rect;                       // 16x16, texels of 8x8 pixels
  EXPECT_EQ(image->at(r.x + 1, r.y + 15), (Rgb{0, 255, 0}));  // (0,0) = 0.5
  EXPECT_EQ(image->at(r.x + 9, r.y + 15), kMagenta);          // (1,0) = NaN
  EXPECT_EQ(image->at(r.x + 1, r.y + 1), (Rgb{128, 0, 0}));   // (0,1) = -0.25
  EXPECT_EQ(image->at(r.x + 9, r.y + 1), kMagenta);           // (1,1) = inf
}

TEST(Atlas, LabelsWriteFaceIdsInTheirTiles) {
  TempDir dir;
  std::vector<FaceSpec> faces(12, FaceSpec{0, 0, {1.0f}});
  const PtexFile map = WriteAndOpen(dir / "labels.ptx", faces);
  AtlasOptions options;
  options.labels = true;
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  auto plain = RenderAtlas(map, AtlasOptions{});
  ASSERT_TRUE(plain.ok());
  for (int f : {0, 7, 11}) {
    const auto& r = layout.tiles[f].rect;
    int text = 0;
    for (int y = r.y; y < r.y + 7; ++y) {
      for (int x = r.x; x < r.x + 10; ++x) text += image->at(x, y) == Rgb{235, 235, 235};
    }
    EXPECT_GT(text, 5) << "face " << f;
    EXPECT_EQ(image->at(r.x + r.width - 1, r.y + r.height - 1), (Rgb{0, 255, 0}));
  }
  // Face 11's label is "11": two copies of the tiny "1" glyph, 4 pixels apart.
  const auto& r = layout.tiles[11].rect;
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 3; ++x) {
      EXPECT_EQ(image->at(r.x + 1 + x, r.y + 1 + y), image->at(r.x + 5 + x, r.y + 1 + y));
    }
  }
}

TEST(Atlas, ManyFacesGetLabelsThatFit) {
  TempDir dir;
  std::vector<FaceSpec> faces(1200, FaceSpec{0, 0, {0.5f}});
  const PtexFile map = WriteAndOpen(dir / "many.ptx", faces);
  AtlasOptions options;
  options.labels = true;
  AtlasLayout layout;
  auto image = RenderAtlas(map, options, &layout);
  ASSERT_TRUE(image.ok());
  // "1199" is 15 pixels wide: tiles grow to 17.
  EXPECT_EQ(layout.tiles[0].rect.width, 17);
  EXPECT_EQ(layout.tiles[1199].rect.height, 17);
}

TEST(Atlas, SameImageWithOneOrTwoThreads) {
  TempDir dir;
  std::vector<FaceSpec> faces;
  for (int f = 0; f < 50; ++f) {
    std::vector<float> t(16 * 8);
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = std::sin(0.1f * float(f * 131 + int(i)));
    faces.push_back({4, 3, t});
  }
  const PtexFile map = WriteAndOpen(dir / "d.ptx", faces);
  AtlasOptions one, two;
  one.threads = 1;
  two.threads = 2;
  one.labels = two.labels = true;
  auto a = RenderAtlas(map, one);
  auto b = RenderAtlas(map, two);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->rgb, b->rgb);
}

TEST(Atlas, BadOptionsAreErrors) {
  TempDir dir;
  const PtexFile map = WriteAndOpen(dir / "e.ptx", {{0, 0, {1.0f}}});
  AtlasOptions o;
  o.channel = 1;
  auto r = RenderAtlas(map, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("channel 1"), std::string::npos) << r.status().message();
  o = {};
  o.min_tile = 1;
  EXPECT_FALSE(RenderAtlas(map, o).ok());
  o = {};
  o.max_tile = 5000;
  EXPECT_FALSE(RenderAtlas(map, o).ok());
  o = {};
  o.range = -1;
  EXPECT_FALSE(RenderAtlas(map, o).ok());
  o = {};
  o.range = NAN;
  EXPECT_FALSE(RenderAtlas(map, o).ok());
}

TEST(Atlas, TooLargeAnAtlasIsAnErrorBeforeAnyTexelIsRead) {
  TempDir dir;
  const std::string path = dir / "huge.ptx";
  auto writer = PtexWriter::Create(path, PtexWriterOptions{}, 9);
  ASSERT_TRUE(writer.ok());
  for (int f = 0; f < 9; ++f) {
    PtexFaceInfo info;
    info.ulog2 = info.vlog2 = 12;  // constant faces of 4096 x 4096 texels
    const float value = 1.0f;
    ASSERT_TRUE(writer->SetConstantFace(PtexFaceId(f), info, {&value, 1}).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
  auto map = PtexFile::Open(path);
  ASSERT_TRUE(map.ok());
  AtlasOptions options;
  options.max_tile = 4096;
  auto image = RenderAtlas(*map, options);
  ASSERT_FALSE(image.ok());
  EXPECT_NE(image.status().message().find("huge.ptx"), std::string::npos);
  EXPECT_NE(image.status().message().find("max_tile"), std::string::npos);
  // At the default largest tile the same map is fine.
  AtlasLayout layout;
  image = RenderAtlas(*map, AtlasOptions{}, &layout);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(layout.tiles[0].rect.width, 256);
  EXPECT_EQ(layout.tiles[0].reduction, 4);
}

// A 3-channel map: each texel's channels as red, green, blue over [-m, m], m the largest
// |component| (rejects drawing channel 0 only, channels out of order, or a range taken from
// one channel). Texel (1, 0) of face 0 is (0, 0, 0): 128 grey. The default mode of a map
// marked as a vector map is kVector, of a plain 3-channel map kSigned.
TEST(Atlas, VectorModeDrawsThreeChannelsAsRgb) {
  TempDir dir;
  PtexWriterOptions options;
  options.num_channels = 3;
  auto writer = PtexWriter::Create(dir / "v.ptx", options, 2);
  ASSERT_TRUE(writer.ok());
  PtexFaceInfo info;
  info.ulog2 = 1;
  info.vlog2 = 0;
  const std::vector<float> face0 = {-2, 1, 0, 0, 0, 0};  // texels (0, 0) and (1, 0)
  ASSERT_TRUE(writer->SetFace(PtexFaceId(0), info, face0).ok());
  const float constant[3] = {0.5f, -0.5f, 2.0f};
  ASSERT_TRUE(writer->SetConstantFace(PtexFaceId(1), PtexFaceInfo{}, constant).ok());
  ASSERT_TRUE(writer->AddMetaData("dispex:vector_space", "object").ok());
  ASSERT_TRUE(writer->Finish().ok());
  auto map = PtexFile::Open(dir / "v.ptx");
  ASSERT_TRUE(map.ok()) << map.status().message();
  EXPECT_EQ(DefaultAtlasMode(*map), AtlasMode::kVector);
  AtlasOptions o;
  o.mode = AtlasMode::kVector;
  o.min_tile = 4;
  AtlasLayout layout;
  auto image = RenderAtlas(*map, o, &layout);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(layout.range_min, -2);
  EXPECT_EQ(layout.range_max, 2);
  const AtlasLayout::Tile& t0 = layout.tiles[0];
  // (x + 2) / 4 * 255: -2 -> 0, 1 -> 191, 0 -> 128 (127.5 rounds up).
  EXPECT_EQ(image->at(t0.rect.x, t0.rect.y), (Rgb{0, 191, 128}));
  EXPECT_EQ(image->at(t0.rect.x + t0.scale_x, t0.rect.y), (Rgb{128, 128, 128}));
  ExpectUniformTile(*image, layout.tiles[1].rect, {159, 96, 255}, "constant (0.5, -0.5, 2)");
  EXPECT_EQ(AtlasVectorColour(-1, 1, std::array<float, 3>{0, NAN, 0}.data()), kMagenta);
  o.channel = 1;
  EXPECT_FALSE(RenderAtlas(*map, o).ok()) << "channels 1..3 of a 3-channel map";

  auto plain_writer = PtexWriter::Create(dir / "p.ptx", options, 1);
  ASSERT_TRUE(plain_writer.ok());
  ASSERT_TRUE(plain_writer->SetConstantFace(PtexFaceId(0), PtexFaceInfo{}, constant).ok());
  ASSERT_TRUE(plain_writer->Finish().ok());
  auto plain = PtexFile::Open(dir / "p.ptx");
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(DefaultAtlasMode(*plain), AtlasMode::kSigned);
}

TEST(Atlas, ParseAtlasMode) {
  EXPECT_EQ(*ParseAtlasMode("grey"), AtlasMode::kGrey);
  EXPECT_EQ(*ParseAtlasMode("signed"), AtlasMode::kSigned);
  EXPECT_EQ(*ParseAtlasMode("vector"), AtlasMode::kVector);
  EXPECT_EQ(AtlasModeName(AtlasMode::kVector), "vector");
  EXPECT_FALSE(ParseAtlasMode("colour").ok());
  EXPECT_EQ(AtlasModeName(AtlasMode::kSigned), "signed");
}

}  // namespace
}  // namespace dispex
