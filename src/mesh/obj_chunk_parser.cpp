// Parsing pass of the OBJ reader (see obj_chunk_parser.h and obj_syntax.h).
#include "mesh/obj_chunk_parser.h"

#include <fmt/format.h>

#include <string_view>

#include "core/check.h"
#include "mesh/obj_syntax.h"
#include "mesh/obj_tags.h"
#include "mesh/text_scan.h"

namespace dispex::obj {
namespace {

class ChunkParser {
 public:
  ChunkParser(const ChunkInput& in, ChunkOutput& out)
      : in_(in), out_(out), p_(in.begin), end_(in.end), line_(in.first_line) {}

  void Run() {
    while (p_ < end_) {
      text::SkipBlanks(p_, end_, line_);
      const LineKind kind = ReadKeyword(p_, end_);
      bool ok = true;
      switch (kind) {
        case LineKind::kVertex:
          ok = ParseVertex();
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
          ok = Fail(text::IsDanglingContinuation(p_, end_)
                        ? std::string("line continued with '\\' at the end of the file")
                        : fmt::format("line does not start with an OBJ keyword ('{}')",
                                      text::TokenForMessage(p_, end_)));
          break;
      }
      if (!ok) return;
      // Parsers stop at the statement's end ('\n', '#', buffer end) or, for lines that are
      // skipped, anywhere in the line: finish the logical line the way the counting pass does.
      if (p_ < end_ && *p_ == '\n') {
        ++p_;
        ++line_;
      } else {
        text::SkipLogicalLine(in_.file_begin, p_, end_, line_);
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
    if (text::IsDanglingContinuation(p_, end_)) {
      return Fail("line continued with '\\' at the end of the file");
    }
    return Fail(fmt::format("unexpected '{}' {}", text::TokenForMessage(p_, end_), what));
  }

  bool ParseVertex() {
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      text::SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) {
        return Fail(fmt::format("vertex has {} coordinate{} (3 needed)", k, k == 1 ? "" : "s"));
      }
      const char* token = p_;
      const text::NumberResult r = text::ParseReal(p_, end_, xyz[k]);
      if (r == text::NumberResult::kOk && text::EndsToken(p_, end_)) continue;
      p_ = token;
      if (r == text::NumberResult::kNotFinite) {
        return Fail(fmt::format("vertex coordinate '{}' is not a finite number",
                                text::TokenForMessage(p_, end_)));
      }
      if (text::IsDanglingContinuation(p_, end_)) {
        return Fail("line continued with '\\' at the end of the file");
      }
      return Fail(fmt::format("bad vertex coordinate '{}'", text::TokenForMessage(p_, end_)));
    }
    // Optional w or per-vertex colour values: must be numbers, otherwise ignored.
    for (;;) {
      text::SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) break;
      const char* token = p_;
      double extra = 0;
      if (text::ParseReal(p_, end_, extra) != text::NumberResult::kOk ||
          !text::EndsToken(p_, end_)) {
        p_ = token;
        return FailUnexpected("after the vertex coordinates");
      }
    }
    in_.positions[in_.vertex_base + out_.vertices] = Float3{xyz[0], xyz[1], xyz[2]};
    ++out_.vertices;
    return true;
  }

  // One corner "v", "v/t", "v//n" or "v/t/n". Texture and normal indices are checked for
  // syntax only: they may point at vt/vn lines the file does not have.
  bool ParseFace() {
    const std::int64_t vertices_before = in_.vertex_base + out_.vertices;
    std::uint32_t count = 0;
    for (;;) {
      text::SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) break;
      const char* token = p_;
      std::int64_t index = 0;
      // Fast path: a plain index of up to 9 digits that ends at a blank or the line end.
      const char* q = p_;
      std::uint32_t digits = 0;
      while (q < end_ && q - p_ < 9 && static_cast<unsigned char>(*q - '0') < 10) {
        digits = digits * 10 + static_cast<std::uint32_t>(*q - '0');
        ++q;
      }
      if (q > p_ && q < end_ && (*q == ' ' || *q == '\n') && digits > 0 &&
          digits <= in_.num_vertices) {
        p_ = q;
        DISPEX_CHECK(!out_.indices.full());
        out_.indices.push_back(static_cast<std::int32_t>(digits - 1));
        ++count;
        continue;
      }
      text::NumberResult r = text::ParseInt(p_, end_, index);
      if (r == text::NumberResult::kOk && p_ < end_ && *p_ == '/') {
        std::int64_t unused = 0;
        ++p_;
        if (p_ < end_ && *p_ != '/') r = text::ParseInt(p_, end_, unused);  // texture index
        if (r == text::NumberResult::kOk && p_ < end_ && *p_ == '/') {
          ++p_;
          r = text::ParseInt(p_, end_, unused);  // normal index
        }
      }
      if (r != text::NumberResult::kOk || !text::EndsToken(p_, end_)) {
        p_ = token;
        if (text::IsDanglingContinuation(p_, end_)) {
          return Fail("line continued with '\\' at the end of the file");
        }
        return Fail(fmt::format("bad face vertex '{}'", text::TokenForMessage(p_, end_)));
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
      DISPEX_CHECK(!out_.indices.full());
      out_.indices.push_back(static_cast<std::int32_t>(vertex));
      ++count;
    }
    if (count < 3) {
      return Fail(fmt::format("face has {} {} (at least 3 needed)", count,
                              count == 1 ? "vertex" : "vertices"));
    }
    in_.face_sizes[in_.face_base + out_.faces] = count;
    ++out_.faces;
    return true;
  }

  // `o name` / `g name ...`: the rest of the line, blanks collapsed, is the group's name.
  bool ParseGroup() {
    std::string name;
    for (;;) {
      text::SkipBlanks(p_, end_, line_);
      if (AtStatementEnd()) break;
      if (text::IsDanglingContinuation(p_, end_)) {
        return Fail("line continued with '\\' at the end of the file");
      }
      int length = 0;
      const char* start = p_;
      while (p_ < end_ && !text::IsBlank(*p_) && *p_ != '\n' &&
             !text::IsContinuation(p_, end_, length) && !text::IsDanglingContinuation(p_, end_)) {
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
};

}  // namespace

bool ParseChunk(const ChunkInput& in, ChunkOutput& out) {
  // Every face corner takes at least two bytes ("1 "), so this bounds the chunk's indices.
  const std::size_t bytes = static_cast<std::size_t>(in.end - in.begin);
  if (!out.indices.Reserve(bytes / 2 + 2)) return false;
  ChunkParser(in, out).Run();
  return true;
}

}  // namespace dispex::obj
