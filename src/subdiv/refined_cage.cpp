#include "subdiv/refined_cage.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/check.h"

namespace dispex::subdiv {

namespace Far = OpenSubdiv::Far;

StatusOr<RefinedCage> RefinedCage::Build(const LimitSurface::Impl& surface) {
  RefinedCage cage;
  cage.s_ = &surface;
  cage.base_ = &surface.refiner->GetLevel(0);
  const Far::TopologyLevel& base = *cage.base_;
  const int num_faces = base.GetNumFaces();
  const int num_vertices = base.GetNumVertices();
  auto has_surface = [&](int face) { return surface.ptex_hole[surface.first_ptex[face]] == 0; };

  cage.face_corner_offsets_.resize(num_faces + 1);
  for (int f = 0; f < num_faces; ++f) {
    cage.face_corner_offsets_[f + 1] = cage.face_corner_offsets_[f] + cage.FaceSize(f);
  }
  cage.across_face_.assign(cage.face_corner_offsets_.back(), -1);
  cage.across_edge_.assign(cage.face_corner_offsets_.back(), -1);
  std::vector<std::uint8_t> edge_used(base.GetNumEdges(), 0);
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    const Far::ConstIndexArray faces = base.GetEdgeFaces(e);
    const Far::ConstLocalIndexArray local = base.GetEdgeFaceLocalIndices(e);
    const Far::ConstIndexArray ends = base.GetEdgeVertices(e);
    for (int k = 0; k < faces.size(); ++k) edge_used[e] |= has_surface(faces[k]);
    if (faces.size() > 2) {
      return Status::Error(
          fmt::format("{}: edge {}-{} has {} faces: matching a sculpt needs a manifold cage",
                      surface.source, ends[0], ends[1], faces.size()));
    }
    if (faces.size() < 2) continue;
    if (faces[0] == faces[1]) {
      return Status::Error(
          fmt::format("{}: face {} uses edge {}-{} twice: matching a sculpt needs a manifold cage",
                      surface.source, faces[0], ends[0], ends[1]));
    }
    const Far::ConstIndexArray fv0 = base.GetFaceVertices(faces[0]);
    const Far::ConstIndexArray fv1 = base.GetFaceVertices(faces[1]);
    if (fv0[local[0]] != fv1[(local[1] + 1) % fv1.size()]) {
      return Status::Error(fmt::format(
          "{}: faces {} and {} both run edge {}-{} the same way: matching a sculpt needs a "
          "consistently wound cage",
          surface.source, faces[0], faces[1], ends[0], ends[1]));
    }
    for (int k = 0; k < 2; ++k) {
      const int at = cage.face_corner_offsets_[faces[k]] + local[k];
      cage.across_face_[at] = faces[1 - k];
      cage.across_edge_[at] = static_cast<std::int8_t>(local[1 - k]);
    }
  }
  for (int e = 0; e < base.GetNumEdges(); ++e) cage.used_edges_ += edge_used[e];

  cage.valence_.assign(num_vertices, 0);
  cage.boundary_.assign(num_vertices, 0);
  cage.corner_offsets_.assign(num_vertices + 1, 0);
  for (int v = 0; v < num_vertices; ++v) {
    const Far::ConstIndexArray faces = base.GetVertexFaces(v);
    const Far::ConstLocalIndexArray local = base.GetVertexFaceLocalIndices(v);
    int valence = 0;
    for (int k = 0; k < faces.size(); ++k) {
      if (!has_surface(faces[k])) continue;
      ++valence;
      const int size = cage.FaceSize(faces[k]);
      const int first = surface.first_ptex[faces[k]];
      cage.corners_.push_back(size == 4 ? Corner{first, local[k]} : Corner{first + local[k], 0});
    }
    for (Far::Index e : base.GetVertexEdges(v)) {
      int with_surface = 0;
      for (Far::Index f : base.GetEdgeFaces(e)) with_surface += has_surface(f);
      cage.boundary_[v] |= with_surface == 1;
    }
    cage.valence_[v] = static_cast<std::uint16_t>(std::min(valence, 65535));
    cage.used_vertices_ += valence > 0;
    cage.corner_offsets_[v + 1] = static_cast<std::int32_t>(cage.corners_.size());
    std::sort(cage.corners_.begin() + cage.corner_offsets_[v], cage.corners_.end(),
              [](const Corner& a, const Corner& b) { return a.ptex < b.ptex; });
  }

  for (int f = 0; f < num_faces; ++f) {
    if (!has_surface(f)) continue;
    const int size = cage.FaceSize(f);
    if (size == 4) {
      ++cage.quads_;
    } else {
      ++cage.ngons_;
      cage.ngon_corners_ += size;
    }
  }
  return cage;
}

std::uint64_t RefinedCage::CountFaces(int levels) const {
  if (levels == 0) return ngons_ ? 0 : quads_;
  return (quads_ << (2 * levels)) + (ngon_corners_ << (2 * (levels - 1)));
}

std::uint64_t RefinedCage::CountVertices(int levels) const {
  if (levels == 0) return ngons_ ? 0 : used_vertices_;
  const std::uint64_t inner = (std::uint64_t{1} << levels) - 1;       // per quad side
  const std::uint64_t half = (std::uint64_t{1} << (levels - 1)) - 1;  // per sub-face side
  return used_vertices_ + used_edges_ * inner + quads_ * inner * inner + ngons_ +
         ngon_corners_ * (half + half * half);
}

void RefinedCage::SetLevels(int levels) {
  DISPEX_CHECK(levels >= 0 && levels <= 7);
  levels_ = levels;
  edge_cells_ = 1 << levels;
  half_cells_ = levels > 0 ? 1 << (levels - 1) : 0;
}

int RefinedCage::grid_size(int ptex) const {
  if (is_hole(ptex)) return 0;
  return FaceSize(s_->ptex_base[ptex]) == 4 ? edge_cells_ : half_cells_;
}

GridPoint RefinedCage::OnEdge(int n, int edge, int position, bool cells) {
  const int last = cells ? n - 1 : n;
  switch (edge) {
    case 0:
      return {position, 0};
    case 1:
      return {last, position};
    case 2:
      return {last - position, last};
    default:
      return {0, last - position};
  }
}

PtexEdgePlace RefinedCage::Across(int ptex, int edge, int position, bool cells) const {
  const int face = s_->ptex_base[ptex];
  const int size = FaceSize(face);
  const int first = s_->first_ptex[face];
  const int cell = cells ? 1 : 0;
  const int sub = s_->ptex_sub[ptex];
  // Spokes of an n-gon: sub-face k's edge 1 is sub-face k+1's edge 2, the other way.
  if (size != 4 && (edge == 1 || edge == 2)) {
    const int other = edge == 1 ? (sub + 1) % size : (sub + size - 1) % size;
    return {first + other, 3 - edge, half_cells_ - cell - position};
  }
  // Otherwise a base edge, at `along` cells or points from its start in this face.
  int local = edge, along = position;
  if (size != 4) {
    local = edge == 0 ? sub : (sub + size - 1) % size;
    along = edge == 0 ? position : half_cells_ + position;
  }
  const int at = face_corner_offsets_[face] + local;
  const int other = across_face_[at];
  if (other < 0 || s_->ptex_hole[s_->first_ptex[other]]) return {};
  const int other_local = across_edge_[at];
  const int other_along = edge_cells_ - cell - along;
  const int other_first = s_->first_ptex[other];
  const int other_size = FaceSize(other);
  if (other_size == 4) return {other_first, other_local, other_along};
  if (other_along < half_cells_ || (!cells && other_along == half_cells_)) {
    return {other_first + other_local, 0, other_along};
  }
  return {other_first + (other_local + 1) % other_size, 3, other_along - half_cells_};
}

int RefinedCage::CornerVertex(int ptex, int corner) const {
  const int face = s_->ptex_base[ptex];
  const Far::ConstIndexArray fv = base_->GetFaceVertices(face);
  if (fv.size() == 4) return fv[corner];
  return corner == 0 ? fv[s_->ptex_sub[ptex]] : -1;
}

}  // namespace dispex::subdiv
