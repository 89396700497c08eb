// The small textures of the golden tests (golden_test.cpp, cli_test.cpp): each is written
// with the default writer options and dumped; the dumps are checked in under
// tests/data/ptex-golden/ (see the README there for how to regenerate them).
#pragma once

#include <cmath>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "subdiv_ptex_faces.h"

namespace dispex::ptex_test {

struct GoldenCase {
  std::string name;
  PtexWriterOptions options;
  int num_faces = 0;
  std::function<Status(PtexWriter&)> fill;
};
inline void PrintTo(const GoldenCase& c, std::ostream* os) {
  *os << c.name;
}

// Reproducible texel values (multiples of 1/16), so every platform computes the same bits.
inline float GoldenValue(int face, int u, int v, int c) {
  return static_cast<float>(((face * 7 + u * 3 + v * 5 + c * 11) % 17) - 8) / 16.0f;
}

inline std::vector<float> GoldenFace(int face, const PtexFaceInfo& info, int nch, bool unit) {
  std::vector<float> t;
  for (int v = 0; v < info.vres(); ++v)
    for (int u = 0; u < info.ures(); ++u)
      for (int c = 0; c < nch; ++c) {
        const float x = GoldenValue(face, u, v, c);
        t.push_back(unit ? 0.5f + x : x);  // [0, 1) for integer types
      }
  return t;
}

inline std::vector<GoldenCase> GoldenCases() {
  std::vector<GoldenCase> cases;
  {
    // The Catmull-Clark example of docs/ptex.md ("OpenSubdiv Ptex adjacency"): a quad, a
    // pentagon, a quad and a triangle.
    GoldenCase c{"pentagon_triangle_float", {}, 10, nullptr};
    c.fill = [](PtexWriter& w) -> Status {
      Mesh mesh;
      mesh.source = "pentagon_triangle";
      mesh.positions = {{0, 0, 0}, {1, 0, 0},    {2, 0, 0},    {0, 1, 0},      {1, 1, 0},
                        {2, 1, 0}, {0.5f, 2, 0}, {1.5f, 2, 0}, {2.5f, 1.5f, 0}};
      mesh.face_offsets = {0, 4, 9, 13, 16};
      mesh.face_indices = {0, 1, 4, 3, 1, 2, 5, 7, 4, 3, 4, 7, 6, 5, 8, 7};
      DISPEX_ASSIGN_OR_RETURN(SubdivPtexFaces layout, ComputeSubdivPtexFaces(mesh));
      const int res[10][2] = {{4, 3}, {2, 2}, {2, 2}, {2, 2}, {1, 2},
                              {2, 2}, {3, 3}, {2, 2}, {2, 0}, {0, 2}};
      for (int f = 0; f < 10; ++f) {
        PtexFaceInfo info = layout.faces[std::size_t(f)];
        info.ulog2 = static_cast<std::int8_t>(res[f][0]);
        info.vlog2 = static_cast<std::int8_t>(res[f][1]);
        if (f == 3) {
          DISPEX_RETURN_IF_ERROR(w.SetConstantFace(PtexFaceId(f), info, std::vector<float>{0.25f}));
        } else {
          DISPEX_RETURN_IF_ERROR(w.SetFace(PtexFaceId(f), info, GoldenFace(f, info, 1, false)));
        }
      }
      DISPEX_RETURN_IF_ERROR(w.AddMetaData("dispex:test", "golden"));
      return AddMeshMetaData(w, mesh);
    };
    cases.push_back(c);
  }
  {
    // A cube cage, half floats, 2 channels; one face never set.
    GoldenCase c{"cube_half2", {}, 6, nullptr};
    c.options.data_type = PtexDataType::kHalf;
    c.options.num_channels = 2;
    c.options.u_border = PtexBorderMode::kPeriodic;
    c.fill = [](PtexWriter& w) -> Status {
      Mesh mesh;
      mesh.positions = {{-1, -1, 1}, {1, -1, 1}, {-1, 1, 1},   {1, 1, 1},
                        {-1, 1, -1}, {1, 1, -1}, {-1, -1, -1}, {1, -1, -1}};
      mesh.face_offsets = {0, 4, 8, 12, 16, 20, 24};
      mesh.face_indices = {0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4};
      DISPEX_ASSIGN_OR_RETURN(SubdivPtexFaces layout, ComputeSubdivPtexFaces(mesh));
      const int res[6][2] = {{3, 3}, {2, 4}, {4, 2}, {1, 1}, {0, 0}, {3, 2}};
      for (int f = 0; f < 6; ++f) {
        if (f == 4) continue;
        PtexFaceInfo info = layout.faces[std::size_t(f)];
        info.ulog2 = static_cast<std::int8_t>(res[f][0]);
        info.vlog2 = static_cast<std::int8_t>(res[f][1]);
        DISPEX_RETURN_IF_ERROR(w.SetFace(PtexFaceId(f), info, GoldenFace(f, info, 2, false)));
      }
      return Status::Ok();
    };
    cases.push_back(c);
  }
  {
    // A tetrahedron, triangle mesh, uint16 with 3 channels.
    GoldenCase c{"tetra_uint16", {}, 4, nullptr};
    c.options.mesh_type = PtexMeshType::kTriangle;
    c.options.data_type = PtexDataType::kUint16;
    c.options.num_channels = 3;
    c.fill = [](PtexWriter& w) -> Status {
      const int adj[4][6] = {
          {2, 2, 3, 0, 1, 0}, {0, 2, 3, 2, 2, 0}, {1, 2, 3, 1, 0, 0}, {0, 1, 2, 1, 1, 1}};
      const int res[4] = {3, 2, 1, 4};
      for (int f = 0; f < 4; ++f) {
        PtexFaceInfo info;
        info.ulog2 = info.vlog2 = static_cast<std::int8_t>(res[f]);
        for (int e = 0; e < 3; ++e) {
          info.adjfaces[std::size_t(e)] = adj[f][2 * e];
          info.adjedges[std::size_t(e)] = static_cast<std::uint8_t>(adj[f][2 * e + 1]);
        }
        DISPEX_RETURN_IF_ERROR(w.SetFace(PtexFaceId(f), info, GoldenFace(f, info, 3, true)));
      }
      return Status::Ok();
    };
    cases.push_back(c);
  }
  {
    // uint8 RGBA with alpha: premultiplied reductions, alpha-weighted averages.
    GoldenCase c{"quads_uint8_rgba", {}, 3, nullptr};
    c.options.data_type = PtexDataType::kUint8;
    c.options.num_channels = 4;
    c.options.alpha_channel = 3;
    c.options.edge_filter = PtexEdgeFilterMode::kTangentVector;
    c.fill = [](PtexWriter& w) -> Status {
      const int res[3][2] = {{4, 3}, {3, 3}, {2, 2}};
      for (int f = 0; f < 3; ++f) {
        PtexFaceInfo info;
        info.ulog2 = static_cast<std::int8_t>(res[f][0]);
        info.vlog2 = static_cast<std::int8_t>(res[f][1]);
        if (f > 0) {
          info.adjfaces[3] = f - 1;
          info.adjedges[3] = 1;
        }
        if (f < 2) {
          info.adjfaces[1] = f + 1;
          info.adjedges[1] = 3;
        }
        DISPEX_RETURN_IF_ERROR(w.SetFace(PtexFaceId(f), info, GoldenFace(f, info, 4, true)));
      }
      return Status::Ok();
    };
    cases.push_back(c);
  }
  return cases;
}

}  // namespace dispex::ptex_test
