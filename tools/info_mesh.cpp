// `dispex info MESH`: counts, faces by size, groups, subdivision tags, bounds, edge length
// statistics and validation warnings of an OBJ or PLY mesh, as text or JSON.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_set>
#include <vector>

#include "command.h"
#include "dispex/mesh.h"
#include "info.h"

namespace dispex::cli {
namespace {

struct Summary {
  std::string format;
  std::map<int, std::size_t> face_sizes;  // size -> faces
  std::size_t infinite_creases = 0;
  BoundingBox bounds;
  double median_edge = 0;
  MeshValidation validation;
};

constexpr float kInfiniteSharpness = 10.0f;  // Sdc::Crease::SHARPNESS_INFINITE

std::string_view BoundaryName(BoundaryInterpolation b) {
  switch (b) {
    case BoundaryInterpolation::kNone:
      return "none";
    case BoundaryInterpolation::kEdgeOnly:
      return "edge_only";
    case BoundaryInterpolation::kEdgeAndCorner:
      return "edge_and_corner";
  }
  return "?";
}

std::string_view CreaseMethodName(CreaseMethod m) {
  return m == CreaseMethod::kChaikin ? "chaikin" : "uniform";
}

std::string_view TrianglesName(TriangleSubdivision t) {
  return t == TriangleSubdivision::kSmooth ? "smooth" : "catmark";
}

// The distinct ignored tag names, first appearance first.
std::vector<std::string> DistinctNames(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::unordered_set<std::string> seen;
  for (const std::string& n : names) {
    if (seen.insert(n).second) out.push_back(n);
  }
  return out;
}

std::string SizeName(int size, std::size_t count) {
  const char* plural = count == 1 ? "" : "s";
  if (size == 3) return fmt::format("{} triangle{}", count, plural);
  if (size == 4) return fmt::format("{} quad{}", count, plural);
  return fmt::format("{} {}-gon{}", count, size, plural);
}

std::string Point(const Float3& p) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x, p.y, p.z);
}

void PrintText(const InfoOptions& options, const Mesh& mesh, const Summary& s) {
  std::string sizes;
  for (const auto& [size, count] : s.face_sizes) {
    sizes += fmt::format("{}{}", sizes.empty() ? "" : ", ", SizeName(size, count));
  }
  std::string groups = fmt::format("{}", mesh.group_names.size());
  if (!mesh.group_names.empty()) {
    constexpr std::size_t kShown = 8;
    std::string names;
    for (std::size_t i = 0; i < mesh.group_names.size() && i < kShown; ++i) {
      names += fmt::format("{}'{}'", i > 0 ? ", " : "", mesh.group_names[i]);
    }
    if (mesh.group_names.size() > kShown) names += ", ...";
    groups += ": " + names;
  }
  const SubdivTags& t = mesh.tags;
  std::string out;
  out += fmt::format("mesh          {}\n", options.path);
  out += fmt::format("format        {}\n", s.format);
  out += fmt::format("vertices      {}\n", mesh.num_vertices());
  out += fmt::format("faces         {} ({})\n", mesh.num_faces(), sizes);
  out += fmt::format("face corners  {}\n", mesh.face_indices.size());
  out += fmt::format("groups        {}\n", groups);
  if (mesh.has_uvs()) {
    out += fmt::format("uvs           {} texture coordinates on every face\n", mesh.num_uvs());
  } else if (mesh.faces_without_uvs > 0) {
    out += fmt::format("uvs           none kept: {} of {} faces have no texture coordinates\n",
                       mesh.faces_without_uvs, mesh.num_faces());
  } else {
    out += "uvs           none\n";
  }
  out +=
      fmt::format("creases       {} ({} infinitely sharp)\n", t.creases.size(), s.infinite_creases);
  out += fmt::format("corners       {}\n", t.corners.size());
  out += fmt::format("holes         {}\n", t.holes.size());
  out += fmt::format("boundary      {} ({})\n", BoundaryName(t.boundary),
                     t.boundary_from_file ? "from the file" : "default");
  out += fmt::format("crease method {} ({})\n", CreaseMethodName(t.crease_method),
                     t.crease_method_from_file ? "from the file" : "default");
  out += fmt::format("triangles     {} ({})\n", TrianglesName(t.triangles),
                     t.triangles_from_file ? "from the file" : "default");
  if (t.ignored_tag_names.empty()) {
    out += "ignored tags  0\n";
  } else {
    std::vector<std::string> names = DistinctNames(t.ignored_tag_names);
    if (names.size() > 10) {
      names.resize(10);
      names.push_back("...");
    }
    out +=
        fmt::format("ignored tags  {} ({})\n", t.ignored_tag_names.size(), fmt::join(names, ", "));
  }
  out += fmt::format("bounds        min {} max {}\n", Point(s.bounds.min), Point(s.bounds.max));
  out += fmt::format("diagonal      {:.6g}\n", s.bounds.diagonal());
  out += fmt::format("median edge   {:.6g}\n", s.median_edge);
  const MeshValidation& v = s.validation;
  out += fmt::format("edges         {} boundary, {} non-manifold, {} inconsistently wound\n",
                     v.boundary_edges, v.non_manifold_edges, v.inconsistent_edges);
  out += fmt::format("unreferenced  {} vertices\n", v.unreferenced_vertices);
  out += fmt::format("degenerate    {} faces\n", v.degenerate_faces);
  out += fmt::format("warnings      {}\n", v.warnings.size());
  for (const std::string& w : v.warnings) out += fmt::format("  warning: {}\n", w);
  std::fputs(out.c_str(), stdout);
}

void PrintJson(const InfoOptions& options, const Mesh& mesh, const Summary& s) {
  nlohmann::ordered_json j;
  j["file"] = options.path;
  j["format"] = s.format;
  j["vertices"] = mesh.num_vertices();
  j["faces"] = mesh.num_faces();
  nlohmann::ordered_json sizes = nlohmann::ordered_json::object();
  for (const auto& [size, count] : s.face_sizes) sizes[std::to_string(size)] = count;
  j["faces_by_size"] = sizes;
  j["face_corners"] = mesh.face_indices.size();
  j["groups"] = mesh.group_names;
  j["uvs"] = {{"texture_coordinates", mesh.num_uvs()},
              {"faces_without_uvs", mesh.faces_without_uvs}};
  const SubdivTags& t = mesh.tags;
  j["tags"] = {{"creases", t.creases.size()},
               {"infinitely_sharp_creases", s.infinite_creases},
               {"corners", t.corners.size()},
               {"holes", t.holes.size()},
               {"boundary", std::string(BoundaryName(t.boundary))},
               {"boundary_from_file", t.boundary_from_file},
               {"crease_method", std::string(CreaseMethodName(t.crease_method))},
               {"crease_method_from_file", t.crease_method_from_file},
               {"triangles", std::string(TrianglesName(t.triangles))},
               {"triangles_from_file", t.triangles_from_file},
               {"ignored", t.ignored_tag_names.size()},
               {"ignored_names", DistinctNames(t.ignored_tag_names)}};
  // A float as the double nearest to its shortest decimal form: -0.337421, not
  // -0.3374210000038147.
  const auto real = [](float f) { return std::stod(fmt::format("{}", f)); };
  const auto point = [&](const Float3& p) {
    return nlohmann::ordered_json::array({real(p.x), real(p.y), real(p.z)});
  };

  j["bounds"] = {{"min", point(s.bounds.min)}, {"max", point(s.bounds.max)}};
  j["diagonal"] = real(s.bounds.diagonal());
  j["median_edge_length"] = s.median_edge;
  const MeshValidation& v = s.validation;
  j["validation"] = {{"clean", v.clean()},
                     {"unreferenced_vertices", v.unreferenced_vertices},
                     {"degenerate_faces", v.degenerate_faces},
                     {"non_manifold_edges", v.non_manifold_edges},
                     {"inconsistent_edges", v.inconsistent_edges},
                     {"boundary_edges", v.boundary_edges},
                     {"warnings", v.warnings}};
  std::fputs((j.dump(2) + "\n").c_str(), stdout);
}

}  // namespace

int MeshInfo(const InfoOptions& options) {
  StatusOr<Mesh> read = ReadMesh(options.path);
  if (!read.ok()) return ReportFailure(read.status());
  const Mesh& mesh = *read;

  Summary s;
  s.format = DetectMeshFormat(options.path) == MeshFormat::kPly ? "PLY" : "OBJ";
  std::vector<std::size_t> by_size;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto n = static_cast<std::size_t>(mesh.face_size(f));
    if (n >= by_size.size()) by_size.resize(n + 1, 0);
    ++by_size[n];
  }
  for (std::size_t n = 0; n < by_size.size(); ++n) {
    if (by_size[n] > 0) s.face_sizes[static_cast<int>(n)] = by_size[n];
  }
  for (const auto& c : mesh.tags.creases) s.infinite_creases += c.sharpness >= kInfiniteSharpness;
  s.bounds = ComputeBounds(mesh);
  s.median_edge = MedianEdgeLength(mesh);
  s.validation = ValidateMesh(mesh);

  if (options.json) {
    PrintJson(options, mesh, s);
  } else {
    PrintText(options, mesh, s);
  }
  std::fflush(stdout);
  if (options.strict) {
    const Status clean = RequireClean(mesh, s.validation);
    if (!clean.ok()) return ReportFailure(clean);
  }
  return 0;
}

}  // namespace dispex::cli
