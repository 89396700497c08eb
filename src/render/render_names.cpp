// Names of the render options and their parsers (the command line's words).
#include <fmt/format.h>

#include <charconv>

#include "core/enum_names.h"
#include "dispex/render.h"

namespace dispex {

namespace {

constexpr auto kAtlasModeNames = EnumTable<AtlasMode>({
    {AtlasMode::kGrey, "grey"},
    {AtlasMode::kSigned, "signed"},
    {AtlasMode::kVector, "vector"},
    {AtlasMode::kGrey, "gray", kEnumAlias},
});

constexpr auto kViewNames = EnumTable<ViewPreset>({
    {ViewPreset::kFront, "front"},
    {ViewPreset::kBack, "back"},
    {ViewPreset::kLeft, "left"},
    {ViewPreset::kRight, "right"},
    {ViewPreset::kTop, "top"},
    {ViewPreset::kIso, "iso"},
});

constexpr auto kProjectionNames = EnumTable<Projection>({
    {Projection::kPerspective, "perspective"},
    {Projection::kOrthographic, "ortho"},
    {Projection::kOrthographic, "orthographic", kEnumAlias},
});

}  // namespace

std::string_view AtlasModeName(AtlasMode mode) {
  return EnumName(kAtlasModeNames, mode);
}

StatusOr<AtlasMode> ParseAtlasMode(std::string_view name) {
  return ParseEnum(kAtlasModeNames, "mode", name);
}

std::string_view ViewName(ViewPreset view) {
  return EnumName(kViewNames, view);
}

StatusOr<ViewPreset> ParseView(std::string_view name) {
  return ParseEnum(kViewNames, "view", name);
}

std::string_view ProjectionName(Projection projection) {
  return EnumName(kProjectionNames, projection);
}

StatusOr<Projection> ParseProjection(std::string_view name) {
  return ParseEnum(kProjectionNames, "projection", name);
}

StatusOr<std::array<int, 2>> ParseImageSize(std::string_view text) {
  const auto bad = [&] {
    return Status::Error(
        fmt::format("image size '{}': expected WxH with W and H in 1..16384, e.g. 960x360", text));
  };
  const std::size_t x = text.find('x');
  if (x == std::string_view::npos || x == 0 || x + 1 >= text.size()) return bad();
  std::array<int, 2> size{0, 0};
  for (int i = 0; i < 2; ++i) {
    std::string_view part = i == 0 ? text.substr(0, x) : text.substr(x + 1);
    auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), size[i]);
    if (ec != std::errc() || end != part.data() + part.size() || size[i] < 1 || size[i] > 16384) {
      return bad();
    }
  }
  return size;
}

}  // namespace dispex
