// Shared helpers of the subdiv tests: small cages built in code, bounding boxes, and the
// independent oracle -- OpenSubdiv's own Far::PatchTable + Far::PatchMap evaluation, built
// from a Far::TopologyDescriptor (not through dispex's refiner builder).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::subdiv_test {

// Closed unit cube, counter-clockwise faces (outward normals), 8 vertices of valence 3.
Mesh MakeCube();
// An n x n grid of unit quads in the plane z = 0, counter-clockwise seen from +z.
Mesh MakeGrid(int n);
// A raised pentagon surrounded by a ring of 5 quads (open, non-planar): valence-3 corners.
Mesh MakePentagonFan();
// A closed pentagonal prism: two pentagon caps and 5 side quads, outward.
Mesh MakePentagonPrism();
// Mesh from CSR-like arrays.
Mesh MakeMesh(std::vector<Float3> positions, const std::vector<std::vector<int>>& faces,
              std::string name = "test");

double BoundsDiagonal(const Mesh& mesh);
std::array<double, 3> Centroid(const Mesh& mesh);

// Far::PatchTable reference evaluation of a cage's limit surface (settings from
// docs/ARCHITECTURE.md, "OpenSubdiv pitfalls": Gregory-basis end caps, useInfSharpPatch, no legacy
// sharp corners, double precision, adaptive isolation `isolation`).
class PatchOracle {
 public:
  PatchOracle(const Mesh& cage, int isolation);
  ~PatchOracle();

  bool ok() const { return ok_; }
  int num_ptex_faces() const;
  // False when (ptex, u, v) has no patch (holes). Derivatives are d/du, d/dv of the Ptex face.
  bool Evaluate(int ptex, double u, double v, double p[3], double du[3], double dv[3]) const;
  // Whether base vertex v is extraordinary for the oracle's refiner (valence != regular,
  // or non-manifold), as OpenSubdiv tags it.
  bool IsExtraordinary(int vertex) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  bool ok_ = false;
};

// OpenSubdiv's own uniform refinement of `cage` (TopologyDescriptor, tags and holes) to
// `levels`, with Far::PrimvarRefiner::Limit positions and normals (cross of the limit
// tangents) of the last level. `from_base_vertex[v]` is 1 for the vertices that are the
// base vertices themselves (children of children of ... a base vertex), where Limit is
// inexact at darts and interior valence-2 vertices.
struct FarLimit {
  int num_vertices = 0;
  int num_faces = 0;
  std::vector<std::array<double, 3>> positions, normals;
  std::vector<std::uint8_t> from_base_vertex;
  std::vector<int> base_vertex_child;   // last-level id of each base vertex
  std::vector<std::vector<int>> faces;  // face-vertices of the last level
  std::vector<int> face_base;           // base face of each last-level face
};
FarLimit FarUniformLimit(const Mesh& cage, int levels);

// Angle in radians between two vectors (0 if either is zero).
double AngleBetween(const double a[3], const double b[3]);
double AngleBetween(const float a[3], const double b[3]);
void UnitCross(const double a[3], const double b[3], double out[3]);

}  // namespace dispex::subdiv_test

#include "dispex/subdiv.h"

namespace dispex::subdiv_test {

// dispex's limit evaluation against PatchOracle over every Ptex face, at the texel centres of
// an n x n grid (EvaluateGrid) and at points within 1/64 of each corner (EvaluatePoints).
struct OracleComparison {
  bool built = false;  // both sides built
  std::string error;   // why not
  std::int64_t samples = 0;
  int hole_mismatches = 0;              // Ptex faces that are holes on one side only
  double max_position_error = 0;        // / bbox diagonal
  double max_normal_angle_regular = 0;  // samples at least 1/16 (uv) from extraordinary corners
  double max_normal_angle = 0;          // all samples
  double mean_outward = 0;              // mean dot(normal, P - centroid) / diagonal
};

OracleComparison CompareWithOracle(const Mesh& cage, const SubdivOptions& options, int n,
                                   int oracle_isolation = 0);

}  // namespace dispex::subdiv_test
