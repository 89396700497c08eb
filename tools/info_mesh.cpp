// `dispex info MESH`: counts, faces by size, groups, subdivision tags, bounds, edge length
// statistics and validation warnings of an OBJ or PLY mesh, as text or JSON.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/mesh_summary.h"
#include "info.h"

namespace dispex::cli {
namespace {

std::string SizeName(int size, std::size_t count) {
  const char* plural = count == 1 ? "" : "s";
  if (size == 3) return fmt::format("{} triangle{}", count, plural);
  if (size == 4) return fmt::format("{} quad{}", count, plural);
  return fmt::format("{} {}-gon{}", count, size, plural);
}

std::string Point(const Float3& p) {
  return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x, p.y, p.z);
}

void PrintText(const InfoOptions& options, const Mesh& mesh, const MeshSummary& s) {
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
  out += fmt::format("format        {}\n", s.format == MeshFormat::kPly ? "PLY" : "OBJ");
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
  out += fmt::format("boundary      {} ({})\n", BoundaryInterpolationName(t.boundary),
                     t.boundary_from_file ? "from the file" : "default");
  out += fmt::format("crease method {} ({})\n", CreaseMethodName(t.crease_method),
                     t.crease_method_from_file ? "from the file" : "default");
  out += fmt::format("triangles     {} ({})\n", TriangleSubdivisionName(t.triangles),
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

}  // namespace

int MeshInfo(const InfoOptions& options) {
  StatusOr<Mesh> read = ReadMesh(options.path);
  if (!read.ok()) return ReportFailure(read.status());
  const Mesh& mesh = *read;
  if (options.fingerprint) {
    std::fputs((MeshFingerprint(mesh) + "\n").c_str(), stdout);
    return 0;
  }

  const MeshSummary s = SummarizeMesh(mesh, DetectMeshFormat(options.path));
  if (options.json) {
    std::fputs((MeshSummaryJson(options.path, mesh, s) + "\n").c_str(), stdout);
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
