// OpenSubdiv `t` tag lines; see obj_tags.h for the grammar and its meaning.
#include "mesh/obj_tags.h"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mesh/text_scan.h"

namespace dispex::obj {
namespace {

bool AtLineEnd(const char* p, const char* end) {
  return p == end || *p == '\n' || *p == '#';
}

// Reads one blank-separated token; false at the end of the line.
bool NextToken(const char*& p, const char* end, std::int64_t& line, std::string_view& token) {
  text::SkipBlanks(p, end, line);
  if (AtLineEnd(p, end)) return false;
  const char* start = p;
  while (p < end && !text::IsBlank(*p) && *p != '\n') {
    int length = 0;
    if (text::IsContinuation(p, end, length)) break;
    ++p;
  }
  token = std::string_view(start, static_cast<std::size_t>(p - start));
  return true;
}

bool ParseTagInt(std::string_view token, std::int64_t& value) {
  const char* p = token.data();
  const char* end = p + token.size();
  return text::ParseInt(p, end, value) == text::NumberResult::kOk && p == end;
}

std::string Quoted(std::string_view token) {
  return fmt::format("'{}'", text::TokenForMessage(token.data(), token.data() + token.size()));
}

}  // namespace

bool ParseTag(const char*& p, const char* end, std::int64_t& line, const TagLimits& limits,
              SubdivTags& tags, std::string& error) {
  std::string_view name_token;
  if (!NextToken(p, end, line, name_token)) {
    error = "tag line without a tag name";
    return false;
  }
  const std::string name(name_token);
  const std::string shown =
      text::TokenForMessage(name_token.data(), name_token.data() + name_token.size());

  // "<nint>/<nfloat>/<nstring>"
  std::string_view counts_token;
  std::int64_t counts[3] = {0, 0, 0};
  if (!NextToken(p, end, line, counts_token)) {
    error = fmt::format("tag '{}' without its <nint>/<nfloat>/<nstring> counts", shown);
    return false;
  }
  {
    const char* q = counts_token.data();
    const char* q_end = q + counts_token.size();
    bool ok = true;
    for (int k = 0; k < 3 && ok; ++k) {
      if (k > 0) {
        ok = q < q_end && *q == '/';
        ++q;
      }
      ok = ok && text::ParseInt(q, q_end, counts[k]) == text::NumberResult::kOk && counts[k] >= 0;
    }
    if (!ok || q != q_end) {
      error = fmt::format("tag '{}': bad argument counts {} (expected <nint>/<nfloat>/<nstring>)",
                          shown, Quoted(counts_token));
      return false;
    }
  }

  std::vector<std::int64_t> ints;
  std::vector<float> floats;
  std::string_view token;
  for (std::int64_t i = 0; i < counts[0]; ++i) {
    std::int64_t value = 0;
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} integers", shown, i, counts[0]);
      return false;
    }
    if (!ParseTagInt(token, value)) {
      error = fmt::format("tag '{}': bad integer {}", shown, Quoted(token));
      return false;
    }
    ints.push_back(value);
  }
  for (std::int64_t i = 0; i < counts[1]; ++i) {
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} floats", shown, i, counts[1]);
      return false;
    }
    const char* q = token.data();
    const char* q_end = q + token.size();
    float value = 0;
    const text::NumberResult r = text::ParseReal(q, q_end, value);
    if (r == text::NumberResult::kNotFinite) {
      error = fmt::format("tag '{}': value {} is not a finite number", shown, Quoted(token));
      return false;
    }
    if (r != text::NumberResult::kOk || q != q_end) {
      error = fmt::format("tag '{}': bad number {}", shown, Quoted(token));
      return false;
    }
    floats.push_back(value);
  }
  std::vector<std::string_view> strings;
  for (std::int64_t i = 0; i < counts[2]; ++i) {
    if (!NextToken(p, end, line, token)) {
      error = fmt::format("tag '{}' ends after {} of its {} strings", shown, i, counts[2]);
      return false;
    }
    strings.push_back(token);
  }
  text::SkipBlanks(p, end, line);
  if (!AtLineEnd(p, end)) {
    error = text::IsDanglingContinuation(p, end)
                ? std::string("line continued with '\\' at the end of the file")
                : fmt::format("tag '{}': unexpected {} after its {}/{}/{} arguments", shown,
                              Quoted(std::string_view(p, static_cast<std::size_t>(end - p))),
                              counts[0], counts[1], counts[2]);
    return false;
  }

  auto check_vertex = [&](std::int64_t v) {
    if (v >= 0 && v < limits.num_vertices) return true;
    error = fmt::format("{} tag: vertex id {} out of range ({} vertices; tag ids are 0-based)",
                        shown, v, limits.num_vertices);
    return false;
  };
  auto sharpness = [&](std::size_t i) {
    const float s = floats.size() > 1 ? floats[i] : floats[0];
    return s > 0 ? s : 0.0f;
  };

  if (name == "crease") {
    const std::size_t edges = ints.size() / 2;
    if (ints.empty() || ints.size() % 2 != 0) {
      error = fmt::format("crease tag needs pairs of vertex ids (got {} integers)", ints.size());
      return false;
    }
    if (floats.size() != 1 && floats.size() != edges) {
      error =
          fmt::format("crease tag needs 1 or {} sharpness values (got {})", edges, floats.size());
      return false;
    }
    for (std::size_t e = 0; e < edges; ++e) {
      if (!check_vertex(ints[2 * e]) || !check_vertex(ints[2 * e + 1])) return false;
      if (ints[2 * e] == ints[2 * e + 1]) {
        error = fmt::format("crease tag: edge {}-{} joins a vertex to itself", ints[2 * e],
                            ints[2 * e + 1]);
        return false;
      }
      tags.creases.push_back({VertexId(static_cast<std::int32_t>(ints[2 * e])),
                              VertexId(static_cast<std::int32_t>(ints[2 * e + 1])), sharpness(e)});
    }
  } else if (name == "corner") {
    if (ints.empty()) {
      error = "corner tag without vertex ids";
      return false;
    }
    if (floats.size() != 1 && floats.size() != ints.size()) {
      error = fmt::format("corner tag needs 1 or {} sharpness values (got {})", ints.size(),
                          floats.size());
      return false;
    }
    for (std::size_t i = 0; i < ints.size(); ++i) {
      if (!check_vertex(ints[i])) return false;
      tags.corners.push_back({VertexId(static_cast<std::int32_t>(ints[i])), sharpness(i)});
    }
  } else if (name == "hole") {
    for (std::int64_t f : ints) {
      if (f < 0 || f >= limits.num_faces) {
        error = fmt::format("hole tag: face id {} out of range ({} faces; tag ids are 0-based)", f,
                            limits.num_faces);
        return false;
      }
      tags.holes.push_back(BaseFaceId(static_cast<std::int32_t>(f)));
    }
  } else if (name == "interpolateboundary") {
    if (ints.size() != 1) {
      error = fmt::format("interpolateboundary tag needs 1 integer (got {})", ints.size());
      return false;
    }
    switch (ints[0]) {
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
            ints[0]);
        return false;
    }
    tags.boundary_from_file = true;
  } else if (name == "creasemethod") {
    if (strings.size() != 1 || !ints.empty() || !floats.empty()) {
      error = fmt::format("creasemethod tag needs 1 string, normal or chaikin (got {}/{}/{})",
                          counts[0], counts[1], counts[2]);
      return false;
    }
    if (strings[0] == "normal") {
      tags.crease_method = CreaseMethod::kUniform;
    } else if (strings[0] == "chaikin") {
      tags.crease_method = CreaseMethod::kChaikin;
    } else {
      error = fmt::format("creasemethod {} is not normal or chaikin", Quoted(strings[0]));
      return false;
    }
    tags.crease_method_from_file = true;
  } else if (name == "smoothtriangles") {
    if (strings.size() == 1 && ints.empty() && floats.empty()) {
      if (strings[0] == "catmark") {
        tags.triangles = TriangleSubdivision::kCatmark;
      } else if (strings[0] == "smooth") {
        tags.triangles = TriangleSubdivision::kSmooth;
      } else {
        error = fmt::format("smoothtriangles {} is not catmark or smooth", Quoted(strings[0]));
        return false;
      }
    } else if (ints.size() == 1 && floats.empty() && strings.empty()) {
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
                          counts[0], counts[1], counts[2]);
      return false;
    }
    tags.triangles_from_file = true;
  } else {
    // Printable and at most 64 bytes, so that warnings stay one line.
    tags.ignored_tag_names.push_back(
        text::TokenForMessage(name_token.data(), name_token.data() + name_token.size(), 64));
  }
  return true;
}

}  // namespace dispex::obj

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
