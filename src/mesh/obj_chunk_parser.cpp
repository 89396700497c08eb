// Parsing pass of the OBJ reader (see obj_chunk_parser.h and obj_syntax.h).
#include "mesh/obj_chunk_parser.h"

#include <fmt/format.h>

#include <string_view>

#include "core/check.h"
#include "mesh/obj_syntax.h"
#include "mesh/obj_tags.h"
#include "mesh/text_scan.h"

namespace dispex::mesh {
namespace {

class ChunkParser {
 public:
  ChunkParser(const ChunkInput& in, ChunkOutput& out)
      : in_(in),
        out_(out),
        p_(in.begin),
        end_(in.end),
        line_(in.first_line),
        keep_uvs_(out.uv_indices.capacity() > 0) {}

  void Run() {
    while (p_ < end_) {
      SkipBlanks(p_, end_, line_);
      const LineKind kind = ReadKeyword(p_, end_);
      bool ok = true;
      switch (kind) {
        case LineKind::kVertex:
          ok = ParseVertex();
          break;
        case LineKind::kTexCoord:
          ok = ParseTexCoord();
          break;
        case LineKind::kFace:
          ok = ParseFace();
          break;
        case LineKind::kGroup:
          ok = ParseGroup();
          break;
        case LineKind::kTag:
          ok = ParseTagLine();
          break;
        case LineKind::kEmpty:
        case LineKind::kIgnored:
          break;
        case LineKind::kNotKeyword:
          ok = Fail(IsDanglingContinuation(p_, end_)
                        ? std::string("line continued with '\\' at the end of the file")
                        : fmt::format("line does not start with an OBJ keyword ('{}')",
                                      TokenForMessage(p_, end_)));
          break;
      }
      if (!ok) return;
      // Parsers stop at the statement's end ('\n', '#', buffer end) or, for lines that are
      // skipped, anywhere in the line: finish the logical line the way the counting pass does.
      if (p_ < end_ && *p_ == '\n') {
        ++p_;
        ++line_;
      } else {
        SkipLogicalLine(in_.file_begin, p_, end_, line_);
      }
    }
  }

 private:
  bool Fail(std::string message) {
    out_.error = ChunkError{line_, std::move(message)};
    return false;
  }

  bool AtStatementEnd() const { return p_ == end_ || *p_ == '\n' || *p_ == '#'; }

  // A byte where an argument should end or start that is neither: name it.
  bool FailUnexpected(const char* what) {
    if (IsDanglingContinuation(p_, end_)) {
      return Fail("line continued with '\\' at the end of the file");
    }
    return Fail(fmt::format("unexpected '{}' {}", TokenForMessage(p_, end_), what));
  }

  // The numbers of a `v` or `vt` line: `needed` floats, then up to `stored` - `needed`
  // optional ones (`out` keeps its value where one is missing), then any further numbers,
  // which are checked and ignored. The one place that parses floats, so that the compiler
  // keeps fast_float inlined in it (a second call site made it an out-of-line call for every
  // coordinate, 5% slower on vertex-heavy files); kept out of line for the same reason.
  // `what` names the line in messages: "vertex" -> "vertex has 2 coordinates (3 needed)",
  // "bad vertex coordinate 'x'", "vertex coordinate 'nan' is not a finite number".
  [[gnu::noinline]] bool ParseNumbers(float* out, int needed, int stored, const char* what) {
    for (int k = 0; k < stored; ++k) {
      SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) {
        if (k >= needed) return true;
        return Fail(
            fmt::format("{} has {} coordinate{} ({} needed)", what, k, k == 1 ? "" : "s", needed));
      }
      const char* token = p_;
      const NumberResult r = ParseReal(p_, end_, out[k]);
      if (r == NumberResult::kOk && EndsToken(p_, end_)) continue;
      p_ = token;
      if (r == NumberResult::kNotFinite) {
        return Fail(fmt::format("{} coordinate '{}' is not a finite number", what,
                                TokenForMessage(p_, end_)));
      }
      if (IsDanglingContinuation(p_, end_)) {
        return Fail("line continued with '\\' at the end of the file");
      }
      return Fail(fmt::format("bad {} coordinate '{}'", what, TokenForMessage(p_, end_)));
    }
    // Optional w or per-vertex colour values: must be numbers, otherwise ignored.
    for (;;) {
      SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) return true;
      const char* token = p_;
      double extra = 0;
      if (ParseReal(p_, end_, extra) != NumberResult::kOk || !EndsToken(p_, end_)) {
        p_ = token;
        return FailUnexpected(fmt::format("after the {} coordinates", what).c_str());
      }
    }
  }

  bool ParseVertex() {
    float xyz[3];
    if (!ParseNumbers(xyz, 3, 3, "vertex")) return false;
    in_.positions[in_.vertex_base + out_.vertices] = Float3{xyz[0], xyz[1], xyz[2]};
    ++out_.vertices;
    return true;
  }

  // `vt u [v [w]]`: v defaults to 0; w and any further numbers must be numbers and are ignored.
  bool ParseTexCoord() {
    float uv[2] = {0, 0};
    if (!ParseNumbers(uv, 1, 2, "texture")) return false;
    float* out = in_.uvs + 2 * (in_.texcoord_base + out_.texcoords);
    out[0] = uv[0];
    out[1] = uv[1];
    ++out_.texcoords;
    return true;
  }

  // The 0-based texture coordinate of a corner's 1-based or relative index, checked as
  // vertex indices are.
  bool ResolveTexture(std::int64_t index, const char* token, std::int64_t& texcoord) {
    if (index > 0) {
      texcoord = index - 1;
      if (texcoord < in_.num_texcoords) return true;
      p_ = token;
      return Fail(fmt::format("face texture index {} out of range ({} texture coordinates)", index,
                              in_.num_texcoords));
    }
    if (index < 0) {
      const std::int64_t before = in_.texcoord_base + out_.texcoords;
      texcoord = before + index;
      if (texcoord >= 0) return true;
      p_ = token;
      return Fail(fmt::format(
          "relative face texture index {} out of range ({} texture coordinates before it)", index,
          before));
    }
    p_ = token;
    return Fail("face texture index 0 (OBJ indices start at 1)");
  }

  void AddCorner(std::int32_t vertex) {
    if (in_.indices == nullptr) {
      DISPEX_CHECK(!out_.indices.full());
      out_.indices.push_back(vertex);
      return;
    }
    // The count is checked against the counting pass's after the parse (obj_reader.cpp).
    if (out_.corners < in_.corners) in_.indices[out_.corners] = vertex;
    ++out_.corners;
  }

  // One corner "v", "v/t", "v//n" or "v/t/n". Vertex and texture indices are resolved and
  // checked; normal indices are checked for syntax only (they may point at vn lines the file
  // does not have). Texture ids are kept while every face of the chunk has one per corner.
  bool ParseFace() {
    const std::int64_t vertices_before = in_.vertex_base + out_.vertices;
    std::uint32_t count = 0;
    std::uint32_t textured = 0;  // corners that named a texture coordinate
    for (;;) {
      SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) break;
      const char* token = p_;
      std::int64_t index = 0;
      // Fast path: a plain index of up to 8 digits that ends at a blank or the line end (within
      // a chunk's last 8 bytes, ParseInt below reads it).
      if (end_ - p_ > 8) {
        std::uint32_t digits = 0;
        const char* q = p_ + LeadingDigits8(p_, digits);
        if (digits > 0 && digits <= in_.num_vertices && (*q == ' ' || *q == '\n')) {
          p_ = q;
          AddCorner(static_cast<std::int32_t>(digits - 1));
          ++count;
          continue;
        }
      }
      NumberResult r = ParseInt(p_, end_, index);
      bool has_texture = false;
      std::int64_t texture = 0;
      if (r == NumberResult::kOk && p_ < end_ && *p_ == '/') {
        ++p_;
        if (p_ < end_ && *p_ != '/') {
          r = ParseInt(p_, end_, texture);
          has_texture = true;
        }
        if (r == NumberResult::kOk && p_ < end_ && *p_ == '/') {
          std::int64_t unused = 0;
          ++p_;
          r = ParseInt(p_, end_, unused);  // normal index
        }
      }
      if (r != NumberResult::kOk || !EndsToken(p_, end_)) {
        p_ = token;
        if (IsDanglingContinuation(p_, end_)) {
          return Fail("line continued with '\\' at the end of the file");
        }
        return Fail(fmt::format("bad face vertex '{}'", TokenForMessage(p_, end_)));
      }
      std::int64_t vertex = 0;
      if (index > 0) {
        vertex = index - 1;
        if (vertex >= in_.num_vertices) {
          p_ = token;
          return Fail(
              fmt::format("face index {} out of range ({} vertices)", index, in_.num_vertices));
        }
      } else if (index < 0) {
        vertex = vertices_before + index;
        if (vertex < 0) {
          p_ = token;
          return Fail(fmt::format("relative face index {} out of range ({} vertices before it)",
                                  index, vertices_before));
        }
      } else {
        p_ = token;
        return Fail("face index 0 (OBJ indices start at 1)");
      }
      if (has_texture) {
        const char* after = p_;
        std::int64_t texcoord = 0;
        if (!ResolveTexture(texture, token, texcoord)) return false;
        p_ = after;
        if (keep_uvs_) {
          DISPEX_CHECK(!out_.uv_indices.full());
          out_.uv_indices.push_back(static_cast<std::int32_t>(texcoord));
        }
        ++textured;
      }
      AddCorner(static_cast<std::int32_t>(vertex));
      ++count;
    }
    if (count < 3) {
      return Fail(fmt::format("face has {} {} (at least 3 needed)", count,
                              count == 1 ? "vertex" : "vertices"));
    }
    if (textured == count) {
      ++out_.faces_with_uvs;
    } else if (out_.first_face_without_uvs < 0) {
      out_.first_face_without_uvs = out_.faces;
    }
    if (textured != count && keep_uvs_) {
      out_.uv_indices.pop_back(textured);
      keep_uvs_ = false;  // the file has no UVs: stop keeping them
    }
    in_.face_sizes[in_.face_base + out_.faces] = count;
    ++out_.faces;
    return true;
  }

  // `o name` / `g name ...`: the rest of the line, blanks collapsed, is the group's name.
  bool ParseGroup() {
    std::string name;
    for (;;) {
      SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) break;
      if (IsDanglingContinuation(p_, end_)) {
        return Fail("line continued with '\\' at the end of the file");
      }
      int length = 0;
      const char* start = p_;
      while (p_ < end_ && !IsBlank(*p_) && *p_ != '\n' && !IsContinuation(p_, end_, length) &&
             !IsDanglingContinuation(p_, end_)) {
        ++p_;
      }
      if (!name.empty()) name.push_back(' ');
      name.append(start, p_);
    }
    if (name.empty()) name = "default";
    out_.groups.push_back(GroupStart{in_.face_base + out_.faces, std::move(name)});
    return true;
  }

  bool ParseTagLine() {
    std::string error;
    const TagLimits limits{in_.num_vertices, in_.num_faces};
    if (!ParseTag(p_, end_, line_, limits, out_.tags, error)) return Fail(std::move(error));
    return true;
  }

  const ChunkInput& in_;
  ChunkOutput& out_;
  const char* p_;
  const char* end_;
  std::int64_t line_;
  bool keep_uvs_;  // every face so far had UVs (and the file has vt lines)
};

}  // namespace

bool ParseChunk(const ChunkInput& in, ChunkOutput& out) {
  // Every face corner takes at least two bytes ("1 "), so this bounds the chunk's indices.
  const std::size_t bytes = static_cast<std::size_t>(in.end - in.begin);
  if (in.indices == nullptr && !out.indices.Reserve(bytes / 2 + 2)) return false;
  // Without a vt line every texture index is an error: no buffer needed.
  if (in.num_texcoords > 0 && !out.uv_indices.Reserve(bytes / 2 + 2)) return false;
  ChunkParser(in, out).Run();
  return true;
}

}  // namespace dispex::mesh
