// dispex::Image and the drawing helpers of image_ops.h.
#include <algorithm>
#include <cstring>

#include "core/check.h"
#include "dispex/render.h"
#include "render/image_ops.h"

namespace dispex {

Image::Image(int w, int h, std::array<std::uint8_t, 3> fill) : width(w), height(h) {
  DISPEX_CHECK_GE(w, 0);
  DISPEX_CHECK_GE(h, 0);
  rgb.resize(3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (std::size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = fill[0];
    rgb[i + 1] = fill[1];
    rgb[i + 2] = fill[2];
  }
}

std::array<std::uint8_t, 3> Image::at(int x, int y) const {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                             static_cast<std::size_t>(x));
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

void Image::set(int x, int y, std::array<std::uint8_t, 3> colour) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                             static_cast<std::size_t>(x));
  rgb[i] = colour[0];
  rgb[i + 1] = colour[1];
  rgb[i + 2] = colour[2];
}

}  // namespace dispex

namespace dispex::render {

void FillRect(Image& image, int x, int y, int w, int h, Rgb colour) {
  const int x0 = std::max(x, 0), x1 = std::min(x + w, image.width);
  const int y0 = std::max(y, 0), y1 = std::min(y + h, image.height);
  for (int py = y0; py < y1; ++py) {
    for (int px = x0; px < x1; ++px) image.set(px, py, colour);
  }
}

void Blit(Image& target, const Image& source, int x, int y) {
  const int x0 = std::max(x, 0), x1 = std::min(x + source.width, target.width);
  if (x1 <= x0) return;
  for (int py = std::max(y, 0); py < std::min(y + source.height, target.height); ++py) {
    const std::size_t from =
        3 * (static_cast<std::size_t>(py - y) * source.width + static_cast<std::size_t>(x0 - x));
    const std::size_t to =
        3 * (static_cast<std::size_t>(py) * target.width + static_cast<std::size_t>(x0));
    std::memcpy(target.rgb.data() + to, source.rgb.data() + from,
                3 * static_cast<std::size_t>(x1 - x0));
  }
}

}  // namespace dispex::render
