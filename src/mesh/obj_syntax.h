// What an OBJ line is, decided the same way by the counting pass and the parsing pass of the
// parallel reader (obj_reader.cpp), so that both agree on vertex and face numbering.
//
// Wavefront OBJ (the "Object Files (.obj)" appendix of the Advanced Visualizer manual): one
// statement per logical line, a keyword then its arguments; `#` starts a comment; a trailing
// `\` joins the next line. OpenSubdiv's regression shapes add `t` (subdivision tag) lines.
#pragma once

#include <cstdint>

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

// The start of the logical line after the one containing `p` (or `end`). `begin` is the start
// of the whole buffer, for looking back at a continuation before a newline.
inline const char* NextLineStart(const char* begin, const char* p, const char* end) {
  std::int64_t unused_lines = 0;
  SkipLogicalLine(begin, p, end, unused_lines);
  return p;
}

}  // namespace dispex::mesh
