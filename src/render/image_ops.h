// Small drawing helpers on dispex::Image used by the atlas and the surface renders.
#pragma once

#include <array>
#include <cstdint>

#include "dispex/render.h"

namespace dispex::render {

using Rgb = std::array<std::uint8_t, 3>;

// Fills the rectangle [x, x + w) x [y, y + h), clipped to the image.
void FillRect(Image& image, int x, int y, int w, int h, Rgb colour);

// Copies `source` into `target` with its top-left corner at (x, y), clipped.
void Blit(Image& target, const Image& source, int x, int y);

}  // namespace dispex::render
