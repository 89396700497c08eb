// What an OBJ line is, decided the same way by the counting pass and the parsing pass of the
// parallel reader (obj_reader.cpp), so that both agree on vertex and face numbering.
//
// Wavefront OBJ (the "Object Files (.obj)" appendix of the Advanced Visualizer manual): one
// statement per logical line, a keyword then its arguments; `#` starts a comment; a trailing
// `\` joins the next line. OpenSubdiv's regression shapes add `t` (subdivision tag) lines.
#pragma once

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "mesh/text_scan.h"

namespace dispex::mesh {

enum class LineKind : std::uint8_t {
  kEmpty,       // blank line or comment
  kVertex,      // v
  kTexCoord,    // vt
  kFace,        // f
  kGroup,       // o or g: starts a named group of faces
  kTag,         // t: OpenSubdiv subdivision tag
  kIgnored,     // any other keyword: vn, vp, usemtl, mtllib, s, l, p, cstype, ...
  kNotKeyword,  // the line does not start with a keyword (binary garbage, a stray number)
};

inline bool IsKeywordStart(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
inline bool IsKeywordChar(char c) {
  return IsKeywordStart(c) || (c >= '0' && c <= '9');
}

// Classifies the logical line whose first non-blank byte is at `p` (after SkipBlanks)
// and moves `p` past the keyword. On kEmpty and kNotKeyword `p` does not move.
inline LineKind ReadKeyword(const char*& p, const char* end) {
  if (p == end || *p == '\n' || *p == '#') return LineKind::kEmpty;
  // The hot cases first: "v " and "f ".
  if (p + 1 < end && (p[1] == ' ' || p[1] == '\t')) {
    if (*p == 'v') {
      ++p;
      return LineKind::kVertex;
    }
    if (*p == 'f') {
      ++p;
      return LineKind::kFace;
    }
  }
  if (!IsKeywordStart(*p)) return LineKind::kNotKeyword;
  const char* q = p + 1;
  while (q < end && IsKeywordChar(*q)) ++q;
  if (!EndsToken(q, end)) return LineKind::kNotKeyword;
  const auto length = q - p;
  LineKind kind = LineKind::kIgnored;
  if (length == 1) {
    switch (*p) {
      case 'v':
        kind = LineKind::kVertex;
        break;
      case 'f':
        kind = LineKind::kFace;
        break;
      case 'o':
      case 'g':
        kind = LineKind::kGroup;
        break;
      case 't':
        kind = LineKind::kTag;
        break;
      default:
        break;
    }
  } else if (length == 2 && p[0] == 'v' && p[1] == 't') {
    kind = LineKind::kTexCoord;
  }
  p = q;
  return kind;
}

// The set bits of a 16-bit mask. __builtin_popcount is a call into libgcc where the baseline ISA
// has no POPCNT (x86-64's), once per 16 bytes of every face line.
inline unsigned CountBits16(unsigned x) {
  x = x - ((x >> 1) & 0x5555u);
  x = (x & 0x3333u) + ((x >> 2) & 0x3333u);
  x = (x + (x >> 4)) & 0x0f0fu;
  return (x + (x >> 8)) & 0x1fu;
}

// The corners of a face line whose arguments (after the keyword) span [p, end), `end` its
// '\n' or the buffer's end: the runs of bytes that are not blanks. They are the corners
// ParseFace reads whenever it accepts the line and the span holds no '#' (a comment) and no
// '\' (a continuation), where `plain` becomes false (the count then says nothing).
inline std::int64_t CountFaceCorners(const char* p, const char* end, bool& plain) {
  std::int64_t corners = 0;
  bool after_blank = true;  // the keyword ends at a blank, or the line has no argument
#if defined(__SSE2__)
  const __m128i space = _mm_set1_epi8(' '), tab = _mm_set1_epi8('\t'), cr = _mm_set1_epi8('\r');
  const __m128i hash = _mm_set1_epi8('#'), backslash = _mm_set1_epi8('\\');
  // Per byte of the 16 at q: blank, and '#' or '\\'.
  auto classify = [&](const char* q, unsigned& blank, unsigned& special) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
    blank = static_cast<unsigned>(_mm_movemask_epi8(
        _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(bytes, space), _mm_cmpeq_epi8(bytes, tab)),
                     _mm_cmpeq_epi8(bytes, cr))));
    special = static_cast<unsigned>(_mm_movemask_epi8(
        _mm_or_si128(_mm_cmpeq_epi8(bytes, hash), _mm_cmpeq_epi8(bytes, backslash))));
  };
  const bool long_line = end - p >= 16;
  unsigned blank = 0, special = 0;
  for (; end - p >= 16; p += 16) {
    classify(p, blank, special);
    plain = plain && special == 0;
    // A run starts at a byte that is not blank after one that is.
    corners += CountBits16(~blank & ((blank << 1) | (after_blank ? 1u : 0u)) & 0xffffu);
    after_blank = (blank & 0x8000u) != 0;
  }
  if (long_line && p < end) {
    // The last 16 bytes, of which the first `seen` were counted above.
    const auto seen = static_cast<unsigned>(16 - (end - p));
    classify(end - 16, blank, special);
    const unsigned fresh = (0xffffu << seen) & 0xffffu;
    plain = plain && (special & fresh) == 0;
    corners += CountBits16(~blank & (blank << 1) & fresh);
    p = end;
  }
#endif
  for (; p < end; ++p) {
    plain = plain && *p != '#' && *p != '\\';
    const bool blank_byte = IsBlank(*p);
    corners += !blank_byte && after_blank;
    after_blank = blank_byte;
  }
  return corners;
}

// The start of the logical line after the one containing `p` (or `end`). `begin` is the start
// of the whole buffer, for looking back at a continuation before a newline.
inline const char* NextLineStart(const char* begin, const char* p, const char* end) {
  std::int64_t unused_lines = 0;
  SkipLogicalLine(begin, p, end, unused_lines);
  return p;
}

}  // namespace dispex::mesh
