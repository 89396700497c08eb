// What `dispex info MESH` reports of a mesh: faces by size, tags, bounds, edge length and
// validation, and the same as JSON (`dispex info --json`, the Python module's dispex.info).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/mesh.h"

namespace dispex {

struct MeshSummary {
  MeshFormat format = MeshFormat::kUnknown;
  std::map<int, std::size_t> face_sizes;  // vertices per face -> faces
  std::size_t infinite_creases = 0;       // creases of sharpness >= 10
  BoundingBox bounds;
  double median_edge = 0;
  MeshValidation validation;
};

MeshSummary SummarizeMesh(const Mesh& mesh, MeshFormat format);

// The summary as JSON, pretty-printed (2 spaces, no final newline), `path` as the file.
std::string MeshSummaryJson(const std::string& path, const Mesh& mesh, const MeshSummary& summary);

// "none", "edge_only", "edge_and_corner"; "uniform", "chaikin"; "catmark", "smooth".
std::string_view BoundaryInterpolationName(BoundaryInterpolation boundary);
std::string_view CreaseMethodName(CreaseMethod method);
std::string_view TriangleSubdivisionName(TriangleSubdivision triangles);

// The distinct names of `names`, first appearance first (for tags.ignored_tag_names).
std::vector<std::string> DistinctNames(const std::vector<std::string>& names);

}  // namespace dispex
