// A tiny built-in bitmap font, so pictures can carry numbers and labels without a font file.
// Two sizes: kSmall, 5x7 glyphs (one more row for descenders) on a 6x9 advance (digits, a-z, upper
// case drawn as lower case, and " +-.,:;=()[]/%_|<>'"), and kTiny, 3x5 digits on a 4x6 advance
// (face ids on small tiles; other characters advance but draw nothing). Any other character draws
// as '?'.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "dispex/render.h"

namespace dispex::render {

enum class FontSize : std::uint8_t { kTiny, kSmall };

// Pixels from the start of one character to the next, and the height of a line, at scale 1
// (they include one blank column / row of spacing).
int FontAdvance(FontSize size);
int FontLineHeight(FontSize size);

// Width of `text` at `scale` without the trailing spacing column (0 for empty text).
int TextWidth(std::string_view text, FontSize size, int scale = 1);
// Height of the glyph box at `scale`: 8 rows (7 and a descender row) for kSmall, 5 for kTiny.
int TextHeight(FontSize size, int scale = 1);

// Draws `text` with its top-left corner at (x, y), each glyph pixel a scale x scale block.
// Pixels outside the image are clipped.
void DrawText(Image& image, int x, int y, std::string_view text, FontSize size, int scale,
              std::array<std::uint8_t, 3> colour);

// True when glyph pixel (gx, gy) of character `c` is set (gx < 5, gy < 8 for kSmall; gx < 3,
// gy < 5 for kTiny). For tests.
bool GlyphPixel(char c, FontSize size, int gx, int gy);

}  // namespace dispex::render
