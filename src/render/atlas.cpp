// dispex preview: a displacement map as a picture. Each Ptex face's texels become a tile (see
// atlas_layout.cpp), coloured by value in grey, in signed green/red, or a vector's three
// components as red, green and blue, with a legend strip
// that gives the value range. Faces are read and drawn in parallel; each tile is written by
// one task only, so the pixels do not depend on the thread count.
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "core/parallel.h"
#include "dispex/render.h"
#include "dispex/vector_space.h"
#include "render/atlas_layout.h"
#include "render/bitmap_font.h"
#include "render/image_ops.h"

namespace dispex {

namespace {

using render::FontSize;
using render::Rgb;

constexpr Rgb kBackground = {48, 56, 72};
constexpr Rgb kText = {235, 235, 235};
constexpr Rgb kBarFrame = {150, 150, 160};

Status CheckMapForAtlas(const PtexFile& map, const AtlasOptions& o) {
  if (map.header().mesh_type != PtexMeshType::kQuad) {
    return Status::Error(map.name() + ": triangle-mesh Ptex files are not supported");
  }
  const int last = o.channel + (o.mode == AtlasMode::kVector ? 2 : 0);
  if (last >= map.header().num_channels) {
    return Status::Error(fmt::format("{}: channel {} out of range (the file has {})", map.name(),
                                     last, map.header().num_channels));
  }
  return Status::Ok();
}

// The face's texels of channels [first, first + count) at the tile's reduction, v-major and
// interleaved: stored reductions when the file has the level, else the mean of each block of
// level-0 texels.
Status ShownTexels(const PtexFile& map, PtexFaceId face, int first, int count, int reduction,
                   std::vector<float>& scratch, std::vector<float>& out) {
  const PtexFaceInfo& info = map.face_info(face);
  const int nc = map.header().num_channels;
  const int su = render::Reduced(info.ures(), reduction);
  const int sv = render::Reduced(info.vres(), reduction);
  const auto shown = static_cast<std::size_t>(su) * static_cast<std::size_t>(sv);
  out.assign(shown * static_cast<std::size_t>(count), 0.0f);
  if (info.constant) {
    std::vector<float> value(static_cast<std::size_t>(nc));
    map.ConstantValue(face, value.data());
    for (std::size_t k = 0; k < out.size(); ++k) {
      out[k] = value[static_cast<std::size_t>(first) + k % static_cast<std::size_t>(count)];
    }
    return Status::Ok();
  }
  const bool stored = reduction > 0 && reduction < map.NumStoredLevels(face) &&
                      info.ulog2 >= reduction && info.vlog2 >= reduction;
  const int level = stored ? reduction : 0;
  DISPEX_RETURN_IF_ERROR(map.ReadFace(face, level, scratch));
  const int lu = info.ures() >> level, lv = info.vres() >> level;
  const int bu = lu / su, bv = lv / sv;  // block of texels per shown texel (1 when stored)
  const double inverse = 1.0 / (double(bu) * double(bv));
  for (int j = 0; j < sv; ++j) {
    for (int i = 0; i < su; ++i) {
      for (int c = 0; c < count; ++c) {
        double sum = 0;
        for (int y = j * bv; y < (j + 1) * bv; ++y) {
          for (int x = i * bu; x < (i + 1) * bu; ++x) {
            sum += scratch[(static_cast<std::size_t>(y) * lu + x) * nc + first + c];
          }
        }
        out[(static_cast<std::size_t>(j) * su + i) * count + c] = static_cast<float>(sum * inverse);
      }
    }
  }
  return Status::Ok();
}

std::string FormatValue(double v) {
  if (v == 0) return "0";
  return fmt::format("{:.3g}", v);
}

void DrawLegend(Image& image, const AtlasLayout& layout, AtlasMode mode) {
  render::FillRect(image, layout.legend.x, layout.legend.y, layout.legend.width,
                   layout.legend.height, kBackground);
  const AtlasRect& bar = layout.legend_bar;
  render::FillRect(image, bar.x - 1, bar.y - 1, bar.width + 2, bar.height + 2, kBarFrame);
  for (int i = 0; i < bar.width; ++i) {
    const double t = (i + 0.5) / bar.width;
    const double value = layout.range_min + t * (layout.range_max - layout.range_min);
    const Rgb c = AtlasColour(mode, layout.range_min, layout.range_max, static_cast<float>(value));
    render::FillRect(image, bar.x + i, bar.y, 1, bar.height, c);
  }
  const int scale = layout.width >= 480 ? 2 : 1;
  const int y = bar.y + bar.height + 5;
  const std::string lo = FormatValue(layout.range_min);
  const std::string mid = FormatValue(0.5 * (layout.range_min + layout.range_max));
  const std::string hi = FormatValue(layout.range_max);
  render::DrawText(image, bar.x, y, lo, FontSize::kSmall, scale, kText);
  render::DrawText(image, bar.x + (bar.width - render::TextWidth(mid, FontSize::kSmall, scale)) / 2,
                   y, mid, FontSize::kSmall, scale, kText);
  render::DrawText(image, bar.x + bar.width - render::TextWidth(hi, FontSize::kSmall, scale), y, hi,
                   FontSize::kSmall, scale, kText);
}

}  // namespace

Status ValidateAtlasOptions(const AtlasOptions& o) {
  if (!(o.range >= 0) || !std::isfinite(o.range)) {
    return Status::Error(
        fmt::format("range = {}: expected 0 (automatic) or a number > 0", o.range));
  }
  if (o.channel < 0) return Status::Error(fmt::format("channel = {}: must be >= 0", o.channel));
  if (o.min_tile < 2 || o.min_tile > 256) {
    return Status::Error(fmt::format("min_tile = {}: must be 2..256", o.min_tile));
  }
  if (o.max_tile < 16 || o.max_tile > 4096) {
    return Status::Error(fmt::format("max_tile = {}: must be 16..4096", o.max_tile));
  }
  if (o.width < 0 || o.width > 16384) {
    return Status::Error(fmt::format("width = {}: must be 0 (automatic) or up to 16384", o.width));
  }
  if (o.threads < 0) return Status::Error(fmt::format("threads = {}: must be >= 0", o.threads));
  return Status::Ok();
}

std::array<std::uint8_t, 3> AtlasColour(AtlasMode mode, double lo, double hi, float value) {
  if (!std::isfinite(value)) return {255, 0, 255};
  if (mode == AtlasMode::kGrey || mode == AtlasMode::kVector) {
    double t = hi > lo ? (double(value) - lo) / (hi - lo) : 0.5;
    t = std::clamp(t, 0.0, 1.0);
    const auto g = static_cast<std::uint8_t>(std::lround(255.0 * t));
    return {g, g, g};
  }
  const double m = std::max(std::fabs(lo), std::fabs(hi));
  if (!(m > 0) || value == 0) return {0, 0, 0};
  const auto c =
      static_cast<std::uint8_t>(std::lround(255.0 * std::min(1.0, std::fabs(double(value)) / m)));
  return value > 0 ? Rgb{0, c, 0} : Rgb{c, 0, 0};
}

AtlasMode DefaultAtlasMode(const PtexFile& map) {
  const bool vector =
      map.FindMetaData(kVectorSpaceMetaKey) != nullptr && map.header().num_channels >= 3;
  return vector ? AtlasMode::kVector : AtlasMode::kSigned;
}

std::array<std::uint8_t, 3> AtlasVectorColour(double lo, double hi, const float* components) {
  Rgb out;
  for (int c = 0; c < 3; ++c) {
    if (!std::isfinite(components[c])) return {255, 0, 255};
    out[static_cast<std::size_t>(c)] = AtlasColour(AtlasMode::kGrey, lo, hi, components[c])[0];
  }
  return out;
}

StatusOr<Image> RenderAtlas(const PtexFile& map, const AtlasOptions& options,
                            AtlasLayout* layout_out) {
  DISPEX_RETURN_IF_ERROR(ValidateAtlasOptions(options));
  DISPEX_RETURN_IF_ERROR(CheckMapForAtlas(map, options));
  DISPEX_ASSIGN_OR_RETURN(AtlasLayout layout, render::LayOutAtlas(map, options));
  const int n = map.num_faces();
  const bool vector = options.mode == AtlasMode::kVector;
  const int count = vector ? 3 : 1;

  // Texels shown per face (at most one per pixel of its tile, so bounded by the image).
  std::vector<std::vector<float>> shown(static_cast<std::size_t>(n));
  tbb::enumerable_thread_specific<std::vector<float>> scratches;
  std::mutex mutex;
  Status error;
  int error_face = std::numeric_limits<int>::max();
  RunWithThreads(options.threads, [&] {
    tbb::parallel_for(0, n, [&](int f) {
      std::vector<float>& scratch = scratches.local();
      const auto& tile = layout.tiles[static_cast<std::size_t>(f)];
      Status st = ShownTexels(map, PtexFaceId(f), options.channel, count, tile.reduction, scratch,
                              shown[static_cast<std::size_t>(f)]);
      if (!st.ok()) {
        std::lock_guard lock(mutex);
        if (f < error_face) {  // report the lowest failing face, whatever the thread count
          error_face = f;
          error = st;
        }
      }
    });
  });
  DISPEX_RETURN_IF_ERROR(error);

  // The range.
  if (options.range > 0) {
    layout.range_min = -options.range;
    layout.range_max = options.range;
  } else {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& texels : shown) {
      for (float v : texels) {
        if (!std::isfinite(v)) continue;
        lo = std::min(lo, double(v));
        hi = std::max(hi, double(v));
      }
    }
    if (lo > hi) lo = hi = 0;  // nothing finite
    if (options.mode != AtlasMode::kGrey) {
      const double m = std::max(std::fabs(lo), std::fabs(hi));
      layout.range_min = -m;
      layout.range_max = m;
    } else {
      layout.range_min = lo;
      layout.range_max = hi;
    }
  }

  Image image(layout.width, layout.height, kBackground);
  RunWithThreads(options.threads, [&] {
    tbb::parallel_for(0, n, [&](int f) {
      const auto& tile = layout.tiles[static_cast<std::size_t>(f)];
      const PtexFaceInfo& info = map.face_info(PtexFaceId(f));
      const int su = render::Reduced(info.ures(), tile.reduction);
      const int sv = render::Reduced(info.vres(), tile.reduction);
      const auto& texels = shown[static_cast<std::size_t>(f)];
      for (int y = 0; y < tile.rect.height; ++y) {
        const int j = sv - 1 - y / tile.scale_y;
        for (int x = 0; x < tile.rect.width; ++x) {
          const std::size_t k = static_cast<std::size_t>(j) * su + x / tile.scale_x;
          image.set(tile.rect.x + x, tile.rect.y + y,
                    vector
                        ? AtlasVectorColour(layout.range_min, layout.range_max, &texels[3 * k])
                        : AtlasColour(options.mode, layout.range_min, layout.range_max, texels[k]));
        }
      }
      const std::string id = options.labels ? std::to_string(f) : std::string();
      const int box_w = render::TextWidth(id, FontSize::kTiny) + 2;
      const int box_h = render::TextHeight(FontSize::kTiny) + 2;
      // Only inside the tile: neighbouring tiles are drawn by other tasks.
      if (options.labels && box_w <= tile.rect.width && box_h <= tile.rect.height) {
        render::FillRect(image, tile.rect.x, tile.rect.y, box_w, box_h, kBackground);
        render::DrawText(image, tile.rect.x + 1, tile.rect.y + 1, id, FontSize::kTiny, 1, kText);
      }
    });
  });
  DrawLegend(image, layout, options.mode);
  if (layout_out) *layout_out = layout;
  return image;
}

}  // namespace dispex
