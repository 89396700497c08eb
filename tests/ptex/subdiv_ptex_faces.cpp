// Ptex faces and adjacency of a Catmull-Clark base mesh, from its topology alone.
//
// Follows OpenSubdiv 3.5: Far::PtexIndices (numbering: a quad is one Ptex face, an n-gon n
// sub-faces) and Far::PtexIndices::GetAdjacency (docs/ptex.md, "OpenSubdiv Ptex adjacency"), with
// edges identified as Vtr does (Vtr::Level::completeTopologyFromFaceVertices, see BuildEdges), and
// an edge has a neighbour only when exactly two face corners use it. subdiv_faces_test compares
// the result with OpenSubdiv itself on every cage in tests/data/meshes.
#include "subdiv_ptex_faces.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dispex {

namespace {

constexpr std::int64_t kMaxPtexFaces = std::int64_t{1} << 28;

// Face-edge topology: the edge of every face corner, and each edge's incident faces (their
// number, and the first two).
struct EdgeTopology {
  std::vector<std::int32_t> corner_edge;  // per entry of mesh.face_indices
  std::vector<std::int32_t> face_count;   // per edge
  std::vector<std::array<std::int32_t, 2>> faces;
  std::vector<std::int32_t> last_face;  // the face that used it last
};

// Edges as Vtr::Level::completeTopologyFromFaceVertices (OpenSubdiv 3.5) makes them, face
// after face and corner after corner: a corner (v0, v1) uses the first edge already made
// between v0 and v1, except that a degenerate corner (v0 == v1), or a face meeting the same
// edge a second time, makes a new edge of its own.
EdgeTopology BuildEdges(const Mesh& mesh) {
  EdgeTopology t;
  t.corner_edge.assign(mesh.face_indices.size(), 0);
  std::unordered_map<std::uint64_t, std::int32_t> first_edge;
  first_edge.reserve(mesh.face_indices.size());
  auto new_edge = [&t](std::int32_t face) {
    t.face_count.push_back(1);
    t.faces.push_back({face, -1});
    t.last_face.push_back(face);
    return static_cast<std::int32_t>(t.face_count.size() - 1);
  };
  for (std::size_t fi = 0; fi < mesh.num_faces(); ++fi) {
    const auto f = static_cast<std::int32_t>(fi);
    std::span<const std::int32_t> fv = mesh.face(fi);
    const std::uint32_t base = mesh.face_offsets[fi];
    for (std::size_t i = 0; i < fv.size(); ++i) {
      auto a = static_cast<std::uint32_t>(fv[i]);
      auto b = static_cast<std::uint32_t>(fv[(i + 1) % fv.size()]);
      std::int32_t e = -1;
      if (a != b) {
        if (a > b) std::swap(a, b);
        const std::uint64_t key = (std::uint64_t{a} << 32) | b;
        auto [it, inserted] = first_edge.try_emplace(key, -1);
        if (inserted) {
          it->second = e = new_edge(f);
        } else {
          e = it->second;
          const std::int32_t n = t.face_count[std::size_t(e)];
          if (t.last_face[std::size_t(e)] == f) {
            e = new_edge(f);  // the face meets this edge again: a separate edge
          } else {
            if (n < 2) t.faces[std::size_t(e)][std::size_t(n)] = f;
            ++t.face_count[std::size_t(e)];
            t.last_face[std::size_t(e)] = f;
          }
        }
      } else {
        e = new_edge(f);  // degenerate: never shared
      }
      t.corner_edge[base + i] = e;
    }
  }
  return t;
}

}  // namespace

StatusOr<SubdivPtexFaces> ComputeSubdivPtexFaces(const Mesh& mesh) {
  const std::string name = mesh.source.empty() ? std::string("mesh") : mesh.source;
  const std::size_t nfaces = mesh.num_faces();
  if (mesh.face_offsets.empty() || mesh.face_offsets[0] != 0 ||
      mesh.face_offsets.back() != mesh.face_indices.size()) {
    return Status::Error(name + ": face offsets do not match the face index list");
  }
  std::int64_t total = 0;
  for (std::size_t f = 0; f < nfaces; ++f) {
    if (mesh.face_offsets[f + 1] < mesh.face_offsets[f]) {
      return Status::Error(name + ": face " + std::to_string(f) + ": decreasing face offsets");
    }
    const int n = mesh.face_size(f);
    if (n < 3) {
      return Status::Error(name + ": face " + std::to_string(f) + " has " + std::to_string(n) +
                           " vertices; Catmull-Clark Ptex faces need at least 3");
    }
    for (std::int32_t v : mesh.face(f)) {
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.num_vertices()) {
        return Status::Error(name + ": face " + std::to_string(f) + ": vertex index " +
                             std::to_string(v) + " out of range (" +
                             std::to_string(mesh.num_vertices()) + " vertices)");
      }
    }
    total += n == 4 ? 1 : n;
    if (total > kMaxPtexFaces) {
      return Status::Error(name + ": more than " + std::to_string(kMaxPtexFaces) + " Ptex faces");
    }
  }

  SubdivPtexFaces out;
  out.first_face.resize(nfaces + 1);
  std::int32_t next = 0;
  for (std::size_t f = 0; f < nfaces; ++f) {
    out.first_face[f] = PtexFaceId(next);
    next += mesh.face_size(f) == 4 ? 1 : mesh.face_size(f);
  }
  out.first_face[nfaces] = PtexFaceId(next);
  out.faces.resize(std::size_t(next));
  out.base_face.resize(std::size_t(next));
  out.subface_index.resize(std::size_t(next));

  const EdgeTopology topo = BuildEdges(mesh);
  auto face_edges = [&](std::int32_t f) {
    return std::span<const std::int32_t>(
        topo.corner_edge.data() + mesh.face_offsets[std::size_t(f)],
        topo.corner_edge.data() + mesh.face_offsets[std::size_t(f) + 1]);
  };
  auto find_index = [](std::span<const std::int32_t> edges, std::int32_t e) {
    return static_cast<int>(std::find(edges.begin(), edges.end(), e) - edges.begin());
  };
  // The face across edge `e` from `f`, or -1 unless the edge has exactly two face uses.
  auto across = [&](std::int32_t e, std::int32_t f) -> std::int32_t {
    if (topo.face_count[std::size_t(e)] != 2) return -1;
    const std::array<std::int32_t, 2>& ef = topo.faces[std::size_t(e)];
    return ef[0] == f ? ef[1] : ef[0];
  };
  // Neighbour of a Ptex face across base edge `e`. For an n-gon neighbour the sub-face is
  // the one whose edge 3 (`primary`, seen from a quad or a sub-face's edge 0) or edge 0
  // (seen from a sub-face's edge 3) lies on that edge.
  auto link = [&](std::int32_t e, std::int32_t f, bool primary, std::int32_t& adj_face,
                  std::uint8_t& adj_edge) {
    const std::int32_t g = across(e, f);
    if (g < 0) {
      adj_face = -1;
      adj_edge = 0;
      return;
    }
    std::span<const std::int32_t> ge = face_edges(g);
    const int k = find_index(ge, e);
    if (ge.size() == 4) {
      adj_face = out.first_face[std::size_t(g)].value;
      adj_edge = static_cast<std::uint8_t>(k);
    } else if (primary) {
      adj_face = out.first_face[std::size_t(g)].value + (k + 1) % static_cast<int>(ge.size());
      adj_edge = 3;
    } else {
      adj_face = out.first_face[std::size_t(g)].value + k;
      adj_edge = 0;
    }
  };

  for (std::size_t fi = 0; fi < nfaces; ++fi) {
    const auto f = static_cast<std::int32_t>(fi);
    std::span<const std::int32_t> fe = face_edges(f);
    const int n = static_cast<int>(fe.size());
    const std::int32_t first = out.first_face[fi].value;
    if (n == 4) {
      PtexFaceInfo& info = out.faces[std::size_t(first)];
      for (int e = 0; e < 4; ++e)
        link(fe[std::size_t(e)], f, true, info.adjfaces[e], info.adjedges[e]);
      out.base_face[std::size_t(first)] = BaseFaceId(f);
      continue;
    }
    for (int q = 0; q < n; ++q) {
      PtexFaceInfo& info = out.faces[std::size_t(first + q)];
      info.subface = true;
      info.adjfaces[1] = first + (q + 1) % n;
      info.adjedges[1] = 2;
      info.adjfaces[2] = first + (q + n - 1) % n;
      info.adjedges[2] = 1;
      link(fe[std::size_t(q)], f, true, info.adjfaces[0], info.adjedges[0]);
      link(fe[std::size_t((q + n - 1) % n)], f, false, info.adjfaces[3], info.adjedges[3]);
      out.base_face[std::size_t(first + q)] = BaseFaceId(f);
      out.subface_index[std::size_t(first + q)] = q;
    }
  }
  return out;
}

}  // namespace dispex
