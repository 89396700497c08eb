// OpenSubdiv `t` tag lines; see obj_tags.h for the grammar and its meaning.
#include "mesh/obj_tags.h"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mesh/text_scan.h"

namespace dispex::mesh {
namespace {

bool AtLineEnd(const char* p, const char* end) {
  return p == end || *p == '\n' || *p == '#';
}

// Reads one blank-separated token; false at the end of the line.
bool NextToken(const char*& p, const char* end, std::int64_t& line, std::string_view& token) {
  SkipBlanks(p, end, line);
  if (AtLineEnd(p, end)) return false;
  const char* start = p;
  while (p < end && !IsBlank(*p) && *p != '\n') {
    int length = 0;
    if (IsContinuation(p, end, length)) break;
    ++p;
  }
  token = std::string_view(start, static_cast<std::size_t>(p - start));
  return true;
}

bool ParseTagInt(std::string_view token, std::int64_t& value) {
  const char* p = token.data();
  const char* end = p + token.size();
  return ParseInt(p, end, value) == NumberResult::kOk && p == end;
}

std::string Quoted(std::string_view token) {
  return fmt::format("'{}'", TokenForMessage(token.data(), token.data() + token.size()));
}

// A tag line read but not yet interpreted: "t <name> <nint>/<nfloat>/<nstring> <args>".
struct TagArguments {
  std::string_view name_token;
  std::string name;
  std::string shown;  // the name as messages show it
  std::int64_t counts[3] = {0, 0, 0};
  std::vector<std::int64_t> ints;
  std::vector<float> floats;
  std::vector<std::string_view> strings;
};

// "<nint>/<nfloat>/<nstring>"
bool ParseCounts(std::string_view token, std::int64_t counts[3]) {
  const char* q = token.data();
  const char* q_end = q + token.size();
  bool ok = true;
  for (int k = 0; k < 3 && ok; ++k) {
    if (k > 0) {
      ok = q < q_end && *q == '/';
      ++q;
    }
    ok = ok && ParseInt(q, q_end, counts[k]) == NumberResult::kOk && counts[k] >= 0;
  }
  return ok && q == q_end;
}

bool ReadInts(const char*& p, const char* end, std::int64_t& line, TagArguments& tag,
              std::string& error) {
  std::string_view token;
  for (std::int64_t i = 0; i < tag.counts[0]; ++i) {
    std::int64_t value = 0;
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} integers", tag.shown, i, tag.counts[0]);
      return false;
    }
    if (!ParseTagInt(token, value)) {
      error = fmt::format("tag '{}': bad integer {}", tag.shown, Quoted(token));
      return false;
    }
    tag.ints.push_back(value);
  }
  return true;
}

bool ReadFloats(const char*& p, const char* end, std::int64_t& line, TagArguments& tag,
                std::string& error) {
  std::string_view token;
  for (std::int64_t i = 0; i < tag.counts[1]; ++i) {
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} floats", tag.shown, i, tag.counts[1]);
      return false;
    }
    const char* q = token.data();
    const char* q_end = q + token.size();
    float value = 0;
    const NumberResult r = ParseReal(q, q_end, value);
    if (r == NumberResult::kNotFinite) {
      error = fmt::format("tag '{}': value {} is not a finite number", tag.shown, Quoted(token));
      return false;
    }
    if (r != NumberResult::kOk || q != q_end) {
      error = fmt::format("tag '{}': bad number {}", tag.shown, Quoted(token));
      return false;
    }
    tag.floats.push_back(value);
  }
  return true;
}

bool ReadStrings(const char*& p, const char* end, std::int64_t& line, TagArguments& tag,
                 std::string& error) {
  std::string_view token;
  for (std::int64_t i = 0; i < tag.counts[2]; ++i) {
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} strings", tag.shown, i, tag.counts[2]);
      return false;
    }
    tag.strings.push_back(token);
  }
  return true;
}

// The whole tag line, up to its end.
bool ReadTagArguments(const char*& p, const char* end, std::int64_t& line, TagArguments& tag,
                      std::string& error) {
  if (!NextToken(p, end, line, tag.name_token)) {
    error = "tag line without a tag name";
    return false;
  }
  tag.name = std::string(tag.name_token);
  tag.shown = TokenForMessage(tag.name_token.data(), tag.name_token.data() + tag.name_token.size());
  std::string_view counts_token;
  if (!NextToken(p, end, line, counts_token)) {
    error = fmt::format("tag '{}' without its <nint>/<nfloat>/<nstring> counts", tag.shown);
    return false;
  }
  if (!ParseCounts(counts_token, tag.counts)) {
    error = fmt::format("tag '{}': bad argument counts {} (expected <nint>/<nfloat>/<nstring>)",
                        tag.shown, Quoted(counts_token));
    return false;
  }
  if (!ReadInts(p, end, line, tag, error) || !ReadFloats(p, end, line, tag, error) ||
      !ReadStrings(p, end, line, tag, error)) {
    return false;
  }
  SkipBlanks(p, end, line);
  if (!AtLineEnd(p, end)) {
    error = IsDanglingContinuation(p, end)
                ? std::string("line continued with '\\' at the end of the file")
                : fmt::format("tag '{}': unexpected {} after its {}/{}/{} arguments", tag.shown,
                              Quoted(std::string_view(p, static_cast<std::size_t>(end - p))),
                              tag.counts[0], tag.counts[1], tag.counts[2]);
    return false;
  }
  return true;
}

bool CheckVertex(std::int64_t v, const TagArguments& tag, const TagLimits& limits,
                 std::string& error) {
  if (v >= 0 && v < limits.num_vertices) return true;
  error = fmt::format("{} tag: vertex id {} out of range ({} vertices; tag ids are 0-based)",
                      tag.shown, v, limits.num_vertices);
  return false;
}

// One sharpness for all, or one each; negative values count as 0.
float Sharpness(const TagArguments& tag, std::size_t i) {
  const float s = tag.floats.size() > 1 ? tag.floats[i] : tag.floats[0];
  return s > 0 ? s : 0.0f;
}

bool ApplyCrease(const TagArguments& tag, const TagLimits& limits, SubdivTags& tags,
                 std::string& error) {
  const std::vector<std::int64_t>& ints = tag.ints;
  const std::size_t edges = ints.size() / 2;
  if (ints.empty() || ints.size() % 2 != 0) {
    error = fmt::format("crease tag needs pairs of vertex ids (got {} integers)", ints.size());
    return false;
  }
  if (tag.floats.size() != 1 && tag.floats.size() != edges) {
    error =
        fmt::format("crease tag needs 1 or {} sharpness values (got {})", edges, tag.floats.size());
    return false;
  }
  for (std::size_t e = 0; e < edges; ++e) {
    if (!CheckVertex(ints[2 * e], tag, limits, error) ||
        !CheckVertex(ints[2 * e + 1], tag, limits, error)) {
      return false;
    }
    if (ints[2 * e] == ints[2 * e + 1]) {
      error = fmt::format("crease tag: edge {}-{} joins a vertex to itself", ints[2 * e],
                          ints[2 * e + 1]);
      return false;
    }
    tags.creases.push_back({VertexId(static_cast<std::int32_t>(ints[2 * e])),
                            VertexId(static_cast<std::int32_t>(ints[2 * e + 1])),
                            Sharpness(tag, e)});
  }
  return true;
}

bool ApplyCorner(const TagArguments& tag, const TagLimits& limits, SubdivTags& tags,
                 std::string& error) {
  const std::vector<std::int64_t>& ints = tag.ints;
  if (ints.empty()) {
    error = "corner tag without vertex ids";
    return false;
  }
  if (tag.floats.size() != 1 && tag.floats.size() != ints.size()) {
    error = fmt::format("corner tag needs 1 or {} sharpness values (got {})", ints.size(),
                        tag.floats.size());
    return false;
  }
  for (std::size_t i = 0; i < ints.size(); ++i) {
    if (!CheckVertex(ints[i], tag, limits, error)) return false;
    tags.corners.push_back({VertexId(static_cast<std::int32_t>(ints[i])), Sharpness(tag, i)});
  }
  return true;
}

bool ApplyHole(const TagArguments& tag, const TagLimits& limits, SubdivTags& tags,
               std::string& error) {
  for (std::int64_t f : tag.ints) {
    if (f < 0 || f >= limits.num_faces) {
      error = fmt::format("hole tag: face id {} out of range ({} faces; tag ids are 0-based)", f,
                          limits.num_faces);
      return false;
    }
    tags.holes.push_back(BaseFaceId(static_cast<std::int32_t>(f)));
  }
  return true;
}

bool ApplyInterpolateBoundary(const TagArguments& tag, SubdivTags& tags, std::string& error) {
  if (tag.ints.size() != 1) {
    error = fmt::format("interpolateboundary tag needs 1 integer (got {})", tag.ints.size());
    return false;
  }
  switch (tag.ints[0]) {
    case 0:
      tags.boundary = BoundaryInterpolation::kNone;
      break;
    case 1:
      tags.boundary = BoundaryInterpolation::kEdgeAndCorner;
      break;
    case 2:
      tags.boundary = BoundaryInterpolation::kEdgeOnly;
      break;
    default:
      error = fmt::format(
          "interpolateboundary {} is not 0 (none), 1 (edge and corner) or 2 (edge only)",
          tag.ints[0]);
      return false;
  }
  tags.boundary_from_file = true;
  return true;
}

bool ApplyCreaseMethod(const TagArguments& tag, SubdivTags& tags, std::string& error) {
  if (tag.strings.size() != 1 || !tag.ints.empty() || !tag.floats.empty()) {
    error = fmt::format("creasemethod tag needs 1 string, normal or chaikin (got {}/{}/{})",
                        tag.counts[0], tag.counts[1], tag.counts[2]);
    return false;
  }
  if (tag.strings[0] == "normal") {
    tags.crease_method = CreaseMethod::kUniform;
  } else if (tag.strings[0] == "chaikin") {
    tags.crease_method = CreaseMethod::kChaikin;
  } else {
    error = fmt::format("creasemethod {} is not normal or chaikin", Quoted(tag.strings[0]));
    return false;
  }
  tags.crease_method_from_file = true;
  return true;
}

bool ApplySmoothTriangles(const TagArguments& tag, SubdivTags& tags, std::string& error) {
  const auto& ints = tag.ints;
  const auto& strings = tag.strings;
  if (strings.size() == 1 && ints.empty() && tag.floats.empty()) {
    if (strings[0] == "catmark") {
      tags.triangles = TriangleSubdivision::kCatmark;
    } else if (strings[0] == "smooth") {
      tags.triangles = TriangleSubdivision::kSmooth;
    } else {
      error = fmt::format("smoothtriangles {} is not catmark or smooth", Quoted(strings[0]));
      return false;
    }
  } else if (ints.size() == 1 && tag.floats.empty() && strings.empty()) {
    // Hbr's integer form (OpenSubdiv 2): 2 is its edge rule, which Far's smooth triangles
    // implement; 1 is its older face rule, which OpenSubdiv 3 does not have.
    if (ints[0] == 0) {
      tags.triangles = TriangleSubdivision::kCatmark;
    } else if (ints[0] == 2) {
      tags.triangles = TriangleSubdivision::kSmooth;
    } else if (ints[0] == 1) {
      error =
          "smoothtriangles 1 (Hbr's older face rule) is not in OpenSubdiv 3; use 2 or "
          "0/0/1 smooth (the edge rule)";
      return false;
    } else {
      error = fmt::format("smoothtriangles {} is not 0 (catmark) or 2 (smooth)", ints[0]);
      return false;
    }
  } else {
    error = fmt::format("smoothtriangles tag needs 1 string, catmark or smooth (got {}/{}/{})",
                        tag.counts[0], tag.counts[1], tag.counts[2]);
    return false;
  }
  tags.triangles_from_file = true;
  return true;
}

}  // namespace

bool ParseTag(const char*& p, const char* end, std::int64_t& line, const TagLimits& limits,
              SubdivTags& tags, std::string& error) {
  TagArguments tag;
  if (!ReadTagArguments(p, end, line, tag, error)) return false;
  if (tag.name == "crease") return ApplyCrease(tag, limits, tags, error);
  if (tag.name == "corner") return ApplyCorner(tag, limits, tags, error);
  if (tag.name == "hole") return ApplyHole(tag, limits, tags, error);
  if (tag.name == "interpolateboundary") return ApplyInterpolateBoundary(tag, tags, error);
  if (tag.name == "creasemethod") return ApplyCreaseMethod(tag, tags, error);
  if (tag.name == "smoothtriangles") return ApplySmoothTriangles(tag, tags, error);
  // Printable and at most 64 bytes, so that warnings stay one line.
  tags.ignored_tag_names.push_back(
      TokenForMessage(tag.name_token.data(), tag.name_token.data() + tag.name_token.size(), 64));
  return true;
}

}  // namespace dispex::mesh

namespace dispex {

std::vector<std::string> IgnoredTagWarnings(const Mesh& mesh) {
  constexpr std::size_t kMaxNames = 10;  // a fuzzed file may hold millions of names
  std::vector<std::pair<std::string_view, std::size_t>> distinct;  // name, lines
  std::unordered_map<std::string_view, std::size_t> index;
  for (const std::string& name : mesh.tags.ignored_tag_names) {
    auto [it, added] = index.try_emplace(name, distinct.size());
    if (added) distinct.emplace_back(name, 0);
    ++distinct[it->second].second;
  }
  std::vector<std::string> out;
  for (std::size_t i = 0; i < std::min(distinct.size(), kMaxNames); ++i) {
    const auto& [name, lines] = distinct[i];
    // Face-varying settings shape texture coordinates only, never the limit surface.
    const bool face_varying =
        name == "facevaryinginterpolateboundary" || name == "facevaryingpropagatecorners";
    out.push_back(fmt::format(
        "{}: tag '{}' ({} line{}) ignored{}", mesh.source, name, lines, lines == 1 ? "" : "s",
        face_varying ? " (face-varying data is not used)" : ": dispex does not know it"));
  }
  if (distinct.size() > kMaxNames) {
    out.push_back(
        fmt::format("{}: {} more tag names ignored", mesh.source, distinct.size() - kMaxNames));
  }
  return out;
}

}  // namespace dispex
