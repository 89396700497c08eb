// The glyphs of the built-in font, drawn for this project: each row a string, '#' = ink.
#include "render/bitmap_font.h"

#include <algorithm>
#include <cctype>

namespace dispex::render {

namespace {

constexpr int kSmallW = 5, kSmallH = 8;
constexpr int kTinyW = 3, kTinyH = 5;

struct SmallGlyph {
  char c;
  const char* rows[kSmallH];
};

// clang-format off
constexpr SmallGlyph kSmallGlyphs[] = {
  {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### ", "     "}},
  {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ", "     "}},
  {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####", "     "}},
  {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### ", "     "}},
  {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # ", "     "}},
  {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### ", "     "}},
  {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### ", "     "}},
  {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   ", "     "}},
  {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### ", "     "}},
  {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  ", "     "}},
  {'a', {"     ", "     ", " ### ", "    #", " ####", "#   #", " ####", "     "}},
  {'b', {"#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#### ", "     "}},
  {'c', {"     ", "     ", " ### ", "#    ", "#    ", "#   #", " ### ", "     "}},
  {'d', {"    #", "    #", " ## #", "#  ##", "#   #", "#   #", " ####", "     "}},
  {'e', {"     ", "     ", " ### ", "#   #", "#####", "#    ", " ### ", "     "}},
  {'f', {"  ## ", " #  #", " #   ", "###  ", " #   ", " #   ", " #   ", "     "}},
  {'g', {"     ", "     ", " ####", "#   #", "#   #", " ####", "    #", " ### "}},
  {'h', {"#    ", "#    ", "# ## ", "##  #", "#   #", "#   #", "#   #", "     "}},
  {'i', {"  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### ", "     "}},
  {'j', {"   # ", "     ", "  ## ", "   # ", "   # ", "   # ", "#  # ", " ##  "}},
  {'k', {"#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "     "}},
  {'l', {" ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ", "     "}},
  {'m', {"     ", "     ", "## # ", "# # #", "# # #", "#   #", "#   #", "     "}},
  {'n', {"     ", "     ", "# ## ", "##  #", "#   #", "#   #", "#   #", "     "}},
  {'o', {"     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### ", "     "}},
  {'p', {"     ", "     ", "#### ", "#   #", "#   #", "#### ", "#    ", "#    "}},
  {'q', {"     ", "     ", " ## #", "#  ##", "#   #", " ####", "    #", "    #"}},
  {'r', {"     ", "     ", "# ## ", "##  #", "#    ", "#    ", "#    ", "     "}},
  {'s', {"     ", "     ", " ####", "#    ", " ### ", "    #", "#### ", "     "}},
  {'t', {" #   ", " #   ", "###  ", " #   ", " #   ", " #  #", "  ## ", "     "}},
  {'u', {"     ", "     ", "#   #", "#   #", "#   #", "#  ##", " ## #", "     "}},
  {'v', {"     ", "     ", "#   #", "#   #", "#   #", " # # ", "  #  ", "     "}},
  {'w', {"     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # ", "     "}},
  {'x', {"     ", "     ", "#   #", " # # ", "  #  ", " # # ", "#   #", "     "}},
  {'y', {"     ", "     ", "#   #", "#   #", "#   #", " ####", "    #", " ### "}},
  {'z', {"     ", "     ", "#####", "   # ", "  #  ", " #   ", "#####", "     "}},
  {' ', {"     ", "     ", "     ", "     ", "     ", "     ", "     ", "     "}},
  {'+', {"     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     ", "     "}},
  {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     ", "     "}},
  {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  ", "     "}},
  {',', {"     ", "     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   "}},
  {':', {"     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     ", "     "}},
  {';', {"     ", " ##  ", " ##  ", "     ", " ##  ", "  #  ", " #   ", "     "}},
  {'=', {"     ", "     ", "#####", "     ", "#####", "     ", "     ", "     "}},
  {'(', {"   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # ", "     "}},
  {')', {" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   ", "     "}},
  {'[', {" ### ", " #   ", " #   ", " #   ", " #   ", " #   ", " ### ", "     "}},
  {']', {" ### ", "   # ", "   # ", "   # ", "   # ", "   # ", " ### ", "     "}},
  {'/', {"    #", "    #", "   # ", "  #  ", " #   ", "#    ", "#    ", "     "}},
  {'%', {"##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##", "     "}},
  {'_', {"     ", "     ", "     ", "     ", "     ", "     ", "#####", "     "}},
  {'|', {"  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "     "}},
  {'<', {"   # ", "  #  ", " #   ", "#    ", " #   ", "  #  ", "   # ", "     "}},
  {'>', {" #   ", "  #  ", "   # ", "    #", "   # ", "  #  ", " #   ", "     "}},
  {'\'', {"  #  ", "  #  ", " #   ", "     ", "     ", "     ", "     ", "     "}},
  {'?', {" ### ", "#   #", "    #", "   # ", "  #  ", "     ", "  #  ", "     "}},
};

constexpr const char* kTinyDigits[10][kTinyH] = {
  {"###", "# #", "# #", "# #", "###"},
  {" # ", "## ", " # ", " # ", "###"},
  {"###", "  #", "###", "#  ", "###"},
  {"###", "  #", "###", "  #", "###"},
  {"# #", "# #", "###", "  #", "  #"},
  {"###", "#  ", "###", "  #", "###"},
  {"###", "#  ", "###", "# #", "###"},
  {"###", "  #", "  #", "  #", "  #"},
  {"###", "# #", "###", "# #", "###"},
  {"###", "# #", "###", "  #", "###"},
};
// clang-format on

// Row bit masks per character (bit gx set = ink at column gx), built once.
struct SmallTable {
  std::array<std::array<std::uint8_t, kSmallH>, 128> rows{};
  std::array<bool, 128> present{};
  SmallTable() {
    for (const SmallGlyph& g : kSmallGlyphs) {
      auto index = static_cast<unsigned char>(g.c);
      present[index] = true;
      for (int y = 0; y < kSmallH; ++y) {
        std::uint8_t bits = 0;
        for (int x = 0; x < kSmallW; ++x) {
          if (g.rows[y][x] == '#') bits = static_cast<std::uint8_t>(bits | (1u << x));
        }
        rows[index][static_cast<std::size_t>(y)] = bits;
      }
    }
  }
};

const SmallTable& Small() {
  static const SmallTable table;
  return table;
}

unsigned char SmallIndex(char c) {
  auto u = static_cast<unsigned char>(c);
  if (u < 128 && std::isupper(u)) u = static_cast<unsigned char>(std::tolower(u));
  if (u >= 128 || !Small().present[u]) return static_cast<unsigned char>('?');
  return u;
}

}  // namespace

int FontAdvance(FontSize size) {
  return size == FontSize::kSmall ? kSmallW + 1 : kTinyW + 1;
}
int FontLineHeight(FontSize size) {
  return size == FontSize::kSmall ? kSmallH + 1 : kTinyH + 1;
}

int TextHeight(FontSize size, int scale) {
  return (size == FontSize::kSmall ? kSmallH : kTinyH) * scale;
}

int TextWidth(std::string_view text, FontSize size, int scale) {
  if (text.empty()) return 0;
  return (static_cast<int>(text.size()) * FontAdvance(size) - 1) * scale;
}

bool GlyphPixel(char c, FontSize size, int gx, int gy) {
  if (size == FontSize::kTiny) {
    if (c < '0' || c > '9' || gx < 0 || gx >= kTinyW || gy < 0 || gy >= kTinyH) return false;
    return kTinyDigits[c - '0'][gy][gx] == '#';
  }
  if (gx < 0 || gx >= kSmallW || gy < 0 || gy >= kSmallH) return false;
  return (Small().rows[SmallIndex(c)][static_cast<std::size_t>(gy)] >> gx) & 1u;
}

void DrawText(Image& image, int x, int y, std::string_view text, FontSize size, int scale,
              std::array<std::uint8_t, 3> colour) {
  const int gw = size == FontSize::kSmall ? kSmallW : kTinyW;
  const int gh = size == FontSize::kSmall ? kSmallH : kTinyH;
  int pen = x;
  for (char c : text) {
    for (int gy = 0; gy < gh; ++gy) {
      for (int gx = 0; gx < gw; ++gx) {
        if (!GlyphPixel(c, size, gx, gy)) continue;
        const int x0 = pen + gx * scale, y0 = y + gy * scale;
        for (int py = std::max(y0, 0); py < std::min(y0 + scale, image.height); ++py) {
          for (int px = std::max(x0, 0); px < std::min(x0 + scale, image.width); ++px) {
            image.set(px, py, colour);
          }
        }
      }
    }
    pen += FontAdvance(size) * scale;
  }
}

}  // namespace dispex::render
