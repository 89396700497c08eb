// Names of the render options and their parsers (the command line's words).
#include <fmt/format.h>

#include <charconv>

#include "dispex/render.h"

namespace dispex {

std::string_view AtlasModeName(AtlasMode mode) {
  switch (mode) {
    case AtlasMode::kGrey:
      return "grey";
    case AtlasMode::kSigned:
      return "signed";
    case AtlasMode::kVector:
      return "vector";
  }
  return "?";
}

StatusOr<AtlasMode> ParseAtlasMode(std::string_view name) {
  if (name == "grey" || name == "gray") return AtlasMode::kGrey;
  if (name == "signed") return AtlasMode::kSigned;
  if (name == "vector") return AtlasMode::kVector;
  return Status::Error(fmt::format("unknown mode '{}' (expected grey, signed or vector)", name));
}

std::string_view ViewName(ViewPreset view) {
  switch (view) {
    case ViewPreset::kFront:
      return "front";
    case ViewPreset::kBack:
      return "back";
    case ViewPreset::kLeft:
      return "left";
    case ViewPreset::kRight:
      return "right";
    case ViewPreset::kTop:
      return "top";
    case ViewPreset::kIso:
      return "iso";
  }
  return "iso";
}

StatusOr<ViewPreset> ParseView(std::string_view name) {
  for (ViewPreset v : {ViewPreset::kFront, ViewPreset::kBack, ViewPreset::kLeft, ViewPreset::kRight,
                       ViewPreset::kTop, ViewPreset::kIso}) {
    if (name == ViewName(v)) return v;
  }
  return Status::Error(
      fmt::format("unknown view '{}' (expected front, back, left, right, top or iso)", name));
}

std::string_view ProjectionName(Projection projection) {
  return projection == Projection::kPerspective ? "perspective" : "ortho";
}

StatusOr<Projection> ParseProjection(std::string_view name) {
  if (name == "perspective") return Projection::kPerspective;
  if (name == "ortho" || name == "orthographic") return Projection::kOrthographic;
  return Status::Error(
      fmt::format("unknown projection '{}' (expected perspective or ortho)", name));
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
