// SummarizeMesh and MeshSummaryJson: what `dispex info` reports of a mesh.
#include "dispex/mesh_summary.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <unordered_set>

#include "core/enum_names.h"

namespace dispex {

namespace {
constexpr float kInfiniteSharpness = 10.0f;  // Sdc::Crease::SHARPNESS_INFINITE

constexpr auto kBoundaryInterpolationNames = EnumTable<BoundaryInterpolation>({
    {BoundaryInterpolation::kNone, "none"},
    {BoundaryInterpolation::kEdgeOnly, "edge_only"},
    {BoundaryInterpolation::kEdgeAndCorner, "edge_and_corner"},
});
constexpr auto kCreaseMethodNames = EnumTable<CreaseMethod>({
    {CreaseMethod::kUniform, "uniform"},
    {CreaseMethod::kChaikin, "chaikin"},
});
constexpr auto kTriangleSubdivisionNames = EnumTable<TriangleSubdivision>({
    {TriangleSubdivision::kCatmark, "catmark"},
    {TriangleSubdivision::kSmooth, "smooth"},
});
}  // namespace

std::string_view BoundaryInterpolationName(BoundaryInterpolation boundary) {
  return EnumName(kBoundaryInterpolationNames, boundary);
}

std::string_view CreaseMethodName(CreaseMethod method) {
  return EnumName(kCreaseMethodNames, method);
}

std::string_view TriangleSubdivisionName(TriangleSubdivision triangles) {
  return EnumName(kTriangleSubdivisionNames, triangles);
}

std::vector<std::string> DistinctNames(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::unordered_set<std::string> seen;
  for (const std::string& n : names) {
    if (seen.insert(n).second) out.push_back(n);
  }
  return out;
}

MeshSummary SummarizeMesh(const Mesh& mesh, MeshFormat format) {
  MeshSummary s;
  s.format = format;
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
  return s;
}

std::string MeshSummaryJson(const std::string& path, const Mesh& mesh, const MeshSummary& s) {
  nlohmann::ordered_json j;
  j["file"] = path;
  j["format"] = s.format == MeshFormat::kPly ? "PLY" : "OBJ";
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
               {"boundary", std::string(BoundaryInterpolationName(t.boundary))},
               {"boundary_from_file", t.boundary_from_file},
               {"crease_method", std::string(CreaseMethodName(t.crease_method))},
               {"crease_method_from_file", t.crease_method_from_file},
               {"triangles", std::string(TriangleSubdivisionName(t.triangles))},
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
  return j.dump(2);
}

}  // namespace dispex
