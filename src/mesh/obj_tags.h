// OpenSubdiv subdivision tags in OBJ files: `t <name> <nint>/<nfloat>/<nstring> ints floats
// strings` (regression/common/shape_utils.cpp parses them, far_utils.h applies them).
#pragma once

#include <cstdint>
#include <string>

#include "dispex/mesh.h"

namespace dispex::mesh {

// Sizes the tag's indices are checked against (vertex and face counts of the whole file).
struct TagLimits {
  std::int64_t num_vertices = 0;
  std::int64_t num_faces = 0;
};

// Parses the rest of a `t` line; `p` points just after the `t` keyword and `line` is the
// physical line number there (advanced across continuations). Appends to `tags`. On success
// `p` is at the end of the statement: a '\n', a '#' comment or the buffer end. On failure returns
// false with a one-line message (no file or line prefix) in `error`, `line` at the offending token.
//
// Semantics follow OpenSubdiv's far_utils.h:
//   crease  2k/1/0 or 2k/k/0: k edges (v0 v1 pairs); one sharpness for all or one per edge
//   corner  k/1/0 or k/k/0:   k vertices; one sharpness for all or one per vertex
//   hole    k/0/0:            k face ids
//   interpolateboundary 1/0/0 N: 0 none, 1 edge and corner, 2 edge only
//   creasemethod 0/0/1 S:        normal (uniform) or chaikin
//   smoothtriangles 0/0/1 S:     catmark or smooth; also OpenSubdiv 2 (Hbr)'s 1/0/0 N:
//                                0 catmark, 2 smooth, 1 an error (Hbr's other rule, not in Far)
// The last setting tag of a kind wins. Sharpness is clamped at 0 from below as OpenSubdiv
// does. Vertex and face ids are 0-based and must be in range. Other tag names
// (facevaryinginterpolateboundary, ...) are checked for well-formed counts and their names
// kept in tags.ignored_tag_names.
bool ParseTag(const char*& p, const char* end, std::int64_t& line, const TagLimits& limits,
              SubdivTags& tags, std::string& error);

}  // namespace dispex::mesh
