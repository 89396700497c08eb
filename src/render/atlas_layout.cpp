// Atlas layout: every face a tile of its own resolution, each side scaled by an integer factor
// so that small faces stay visible and reduced by powers of two so that huge ones stay bounded;
// tiles placed left to right in face-id order on shelves (rows as tall as their tallest tile), one
// pixel of separator around each; the legend strip below.
#include "render/atlas_layout.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "render/bitmap_font.h"

namespace dispex::render {

namespace {

constexpr std::int64_t kMaxPixels = std::int64_t{1} << 27;
constexpr int kMinAutoWidth = 320;
constexpr int kLegendPad = 8, kLegendBarHeight = 14, kLegendGap = 5;

LegendMetrics Legend(int width) {
  LegendMetrics m;
  m.text_scale = width >= 480 ? 2 : 1;
  m.height = kLegendPad + kLegendBarHeight + kLegendGap +
             TextHeight(FontSize::kSmall, m.text_scale) + kLegendPad;
  // Room for three numbers such as "-1.23e-05" under the bar.
  m.min_width = 2 * kLegendPad + 3 * TextWidth("-1.23e-05", FontSize::kSmall, m.text_scale) +
                4 * FontAdvance(FontSize::kSmall) * m.text_scale;
  return m;
}

}  // namespace

StatusOr<AtlasLayout> LayOutAtlas(const PtexFile& map, const AtlasOptions& options) {
  const int n = map.num_faces();
  AtlasLayout layout;
  layout.tiles.resize(static_cast<std::size_t>(n));

  int min_tile = options.min_tile;
  if (options.labels) {
    const std::string largest = std::to_string(std::max(n - 1, 0));
    min_tile = std::max(
        {min_tile, TextWidth(largest, FontSize::kTiny) + 2, TextHeight(FontSize::kTiny) + 2});
  }

  std::int64_t area = 0;
  int widest = 0;
  for (int f = 0; f < n; ++f) {
    const PtexFaceInfo& info = map.face_info(PtexFaceId(f));
    AtlasLayout::Tile& tile = layout.tiles[static_cast<std::size_t>(f)];
    int reduction = 0;
    while (std::max(Reduced(info.ures(), reduction), Reduced(info.vres(), reduction)) >
           options.max_tile) {
      ++reduction;
    }
    const int u = Reduced(info.ures(), reduction), v = Reduced(info.vres(), reduction);
    auto scale = [&](int texels) {
      return std::max(1, std::min((min_tile + texels - 1) / texels, options.max_tile / texels));
    };
    tile.reduction = reduction;
    tile.scale_x = scale(u);
    tile.scale_y = scale(v);
    tile.rect.width = u * tile.scale_x;
    tile.rect.height = v * tile.scale_y;
    area += std::int64_t(tile.rect.width + 1) * (tile.rect.height + 1);
    widest = std::max(widest, tile.rect.width);
  }

  int width = options.width;
  if (width == 0) {
    width = std::max(kMinAutoWidth,
                     static_cast<int>(std::ceil(std::sqrt(static_cast<double>(area)))) + 1);
  }
  width = std::max(width, widest + 2);

  // Shelves.
  int x = 1, y = 1, row_height = 0;
  for (AtlasLayout::Tile& tile : layout.tiles) {
    if (x > 1 && x + tile.rect.width + 1 > width) {
      y += row_height + 1;
      x = 1;
      row_height = 0;
    }
    tile.rect.x = x;
    tile.rect.y = y;
    x += tile.rect.width + 1;
    row_height = std::max(row_height, tile.rect.height);
    if (std::int64_t(y) + row_height > kMaxPixels / width) break;  // reported below
  }
  const int tiles_height = n > 0 ? y + row_height + 1 : 1;

  LegendMetrics legend = Legend(width);
  layout.width = std::max(width, legend.min_width);
  layout.height = tiles_height + legend.height;
  if (std::int64_t(layout.width) * layout.height > kMaxPixels ||
      std::int64_t(tiles_height) * width > kMaxPixels) {
    return Status::Error(
        fmt::format("{}: the atlas of {} faces would exceed {} pixels; lower min_tile or max_tile",
                    map.name(), n, kMaxPixels));
  }
  layout.legend = {0, tiles_height, layout.width, legend.height};
  layout.legend_bar = {kLegendPad, tiles_height + kLegendPad, layout.width - 2 * kLegendPad,
                       kLegendBarHeight};
  return layout;
}

}  // namespace dispex::render
