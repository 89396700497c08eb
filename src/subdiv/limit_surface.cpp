// LimitSurface: the cage's OpenSubdiv topology plus the Ptex bookkeeping every stage needs
// (Far::PtexIndices numbering and adjacency, holes, infinitely sharp edges).
#include <fmt/format.h>
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/far/ptexIndices.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include "dispex/subdiv.h"
#include "subdiv/osd_messages.h"
#include "subdiv/refiner_builder.h"
#include "subdiv/surface_impl.h"

namespace dispex {
namespace {

namespace Bfr = OpenSubdiv::Bfr;
namespace Far = OpenSubdiv::Far;

constexpr int kMinApproxLevel = 1;
constexpr int kMaxApproxLevel = 10;  // Far's maximum isolation level

StatusOr<SubdivOptions> ResolveOptions(const Mesh& cage, const SubdivOptions& in) {
  SubdivOptions out = in;
  const std::string where = cage.source.empty() ? "cage" : cage.source;
  if (in.approx_level_smooth < kMinApproxLevel || in.approx_level_smooth > kMaxApproxLevel) {
    return Status::Error(fmt::format("{}: approx_level_smooth {} outside {}..{}", where,
                                     in.approx_level_smooth, kMinApproxLevel, kMaxApproxLevel));
  }
  if (in.approx_level_sharp == 0) {
    const int needed = static_cast<int>(std::ceil(subdiv::MaxSemiSharpness(cage.tags)));
    out.approx_level_sharp = std::clamp(needed, in.approx_level_smooth, kMaxApproxLevel);
  } else if (in.approx_level_sharp < kMinApproxLevel || in.approx_level_sharp > kMaxApproxLevel) {
    return Status::Error(fmt::format("{}: approx_level_sharp {} outside {}..{} (or 0: auto)", where,
                                     in.approx_level_sharp, kMinApproxLevel, kMaxApproxLevel));
  }
  return out;
}

void CopyPositions(const Mesh& cage, LimitSurface::Impl& impl) {
  impl.positions.resize(3 * cage.num_vertices());
  for (std::size_t v = 0; v < cage.num_vertices(); ++v) {
    impl.positions[3 * v + 0] = cage.positions[v].x;
    impl.positions[3 * v + 1] = cage.positions[v].y;
    impl.positions[3 * v + 2] = cage.positions[v].z;
  }
}

// The Ptex numbering (Far::PtexIndices) of the base faces, each Ptex face's base face, sub-face,
// hole flag and adjacency. PtexIndices reports through Far::Error: the caller holds a capture.
void IndexPtexFaces(LimitSurface::Impl& impl) {
  const Far::TopologyRefiner& refiner = *impl.refiner;
  const Far::TopologyLevel& base = refiner.GetLevel(0);
  const int num_faces = base.GetNumFaces();
  Far::PtexIndices ptex(refiner);
  const int num_ptex = ptex.GetNumFaces();

  // A throwaway factory answers which faces have a limit surface (holes, and faces that
  // boundary interpolation "none" leaves without one).
  Bfr::RefinerSurfaceFactory<> factory(refiner);

  LimitSurfaceStats& stats = impl.stats;
  impl.first_ptex.resize(num_faces + 1);
  impl.ptex_base.resize(num_ptex);
  impl.ptex_sub.resize(num_ptex);
  impl.ptex_hole.resize(num_ptex);
  impl.adjacency.resize(num_ptex);
  for (int f = 0; f < num_faces; ++f) {
    const int first = ptex.GetFaceId(f);
    const int n = base.GetFaceVertices(f).size();
    const int count = (n == 4) ? 1 : n;
    impl.first_ptex[f] = first;
    const bool hole = !factory.FaceHasLimitSurface(f);
    for (int k = 0; k < count; ++k) {
      const int p = first + k;
      impl.ptex_base[p] = f;
      impl.ptex_sub[p] = static_cast<std::uint16_t>(k);
      impl.ptex_hole[p] = hole ? 1 : 0;
      int adj_faces[4], adj_edges[4];
      ptex.GetAdjacency(refiner, f, k, adj_faces, adj_edges);
      for (int e = 0; e < 4; ++e) {
        impl.adjacency[p].faces[e] = PtexFaceId(adj_faces[e]);
        impl.adjacency[p].edges[e] = static_cast<std::int8_t>(adj_edges[e]);
      }
    }
    stats.hole_ptex_faces += hole ? count : 0;
    stats.irregular_base_faces += (n != 4);
  }
  impl.first_ptex[num_faces] = num_ptex;
}

// OpenSubdiv 3.5's Bfr::IrregularPatchBuilder mishandles face neighbourhoods that fold
// over an interior valence-2 vertex (OpenSubdiv PRs #1301 and #1353: wrong surfaces, reads
// out of bounds). Faces whose neighbourhood contains such a vertex never reach Bfr; they
// are evaluated through a Far::PatchTable instead.
Status RouteValence2FacesToPatchTable(LimitSurface::Impl& impl) {
  const Far::TopologyRefiner& refiner = *impl.refiner;
  const Far::TopologyLevel& base = refiner.GetLevel(0);
  const int num_faces = base.GetNumFaces();
  const int num_vertices = base.GetNumVertices();
  std::vector<std::uint8_t> val2(num_vertices, 0);
  for (int v = 0; v < num_vertices; ++v) {
    val2[v] = !base.IsVertexBoundary(v) && !base.IsVertexNonManifold(v) &&
              base.GetVertexFaces(v).size() == 2;
  }
  impl.use_patch_table.assign(num_faces, 0);
  std::vector<int> failed;
  for (int f = 0; f < num_faces; ++f) {
    if (impl.ptex_hole[impl.first_ptex[f]]) continue;
    bool risky = false;
    for (Far::Index corner : base.GetFaceVertices(f)) {
      for (Far::Index g : base.GetVertexFaces(corner)) {
        for (Far::Index w : base.GetFaceVertices(g)) risky = risky || val2[w];
      }
    }
    if (risky) {
      impl.use_patch_table[f] = 1;
      failed.push_back(f);
    }
  }
  if (!failed.empty()) {
    auto table = subdiv::PatchTableEvaluator::Build(refiner, impl.positions, failed,
                                                    impl.options.approx_level_sharp,
                                                    impl.options.approx_level_smooth);
    if (!table.ok()) return table.status().WithPrefix(impl.source);
    impl.patch_table = std::move(table).value();
  }
  impl.stats.patch_table_faces = static_cast<int>(failed.size());
  return Status::Ok();
}

// Counts the non-manifold edges and lists the infinitely sharp ones.
void FindSharpEdges(LimitSurface::Impl& impl) {
  const Far::TopologyLevel& base = impl.refiner->GetLevel(0);
  for (int e = 0; e < base.GetNumEdges(); ++e) {
    if (base.IsEdgeNonManifold(e)) ++impl.stats.non_manifold_edges;
    if (base.IsEdgeBoundary(e) || !base.IsEdgeInfSharp(e)) continue;
    // The normal has two values only where surface exists on both sides.
    int faces_with_surface = 0;
    for (Far::Index f : base.GetEdgeFaces(e)) faces_with_surface += !base.IsFaceHole(f);
    if (faces_with_surface < 2) continue;
    Far::ConstIndexArray ev = base.GetEdgeVertices(e);
    impl.inf_sharp_edges.push_back({VertexId(ev[0]), VertexId(ev[1])});
  }
}

}  // namespace

StatusOr<LimitSurface> LimitSurface::Build(const Mesh& cage, const SubdivOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->source = cage.source;
  DISPEX_ASSIGN_OR_RETURN(impl->options, ResolveOptions(cage, options));
  DISPEX_ASSIGN_OR_RETURN(impl->refiner, subdiv::BuildTopologyRefiner(cage));
  CopyPositions(cage, *impl);

  // Held to the end: PtexIndices reports through Far::Error (IndexPtexFaces).
  subdiv::OsdMessageCapture capture;
  IndexPtexFaces(*impl);
  if (!capture.empty()) {
    return Status::Error(impl->source + ": OpenSubdiv Ptex indexing failed: " + capture.messages());
  }
  DISPEX_RETURN_IF_ERROR(RouteValence2FacesToPatchTable(*impl));
  FindSharpEdges(*impl);

  LimitSurfaceStats& stats = impl->stats;
  stats.base_faces = impl->num_base_faces();
  stats.ptex_faces = impl->num_ptex_faces();
  stats.inf_sharp_edges = static_cast<int>(impl->inf_sharp_edges.size());
  stats.approx_level_smooth = impl->options.approx_level_smooth;
  stats.approx_level_sharp = impl->options.approx_level_sharp;
  return LimitSurface(std::move(impl));
}

LimitSurface::LimitSurface(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
LimitSurface::LimitSurface(LimitSurface&&) noexcept = default;
LimitSurface& LimitSurface::operator=(LimitSurface&&) noexcept = default;
LimitSurface::~LimitSurface() = default;

const std::string& LimitSurface::source() const {
  return impl_->source;
}
const SubdivOptions& LimitSurface::options() const {
  return impl_->options;
}
LimitSurfaceStats LimitSurface::stats() const {
  return impl_->stats;
}

int LimitSurface::num_vertices() const {
  return static_cast<int>(impl_->positions.size() / 3);
}
int LimitSurface::num_base_faces() const {
  return impl_->num_base_faces();
}
int LimitSurface::num_ptex_faces() const {
  return impl_->num_ptex_faces();
}

BaseFaceId LimitSurface::base_face(PtexFaceId face) const {
  assert(face.value >= 0 && face.value < num_ptex_faces());
  return BaseFaceId(impl_->ptex_base[face.value]);
}

int LimitSurface::sub_face(PtexFaceId face) const {
  assert(face.value >= 0 && face.value < num_ptex_faces());
  return impl_->ptex_sub[face.value];
}

PtexFaceId LimitSurface::first_ptex_face(BaseFaceId face) const {
  assert(face.value >= 0 && face.value < num_base_faces());
  return PtexFaceId(impl_->first_ptex[face.value]);
}

int LimitSurface::num_ptex_faces(BaseFaceId face) const {
  assert(face.value >= 0 && face.value < num_base_faces());
  return impl_->first_ptex[face.value + 1] - impl_->first_ptex[face.value];
}

int LimitSurface::base_face_size(BaseFaceId face) const {
  assert(face.value >= 0 && face.value < num_base_faces());
  return impl_->face_size(face.value);
}

bool LimitSurface::is_hole(PtexFaceId face) const {
  assert(face.value >= 0 && face.value < num_ptex_faces());
  return impl_->ptex_hole[face.value] != 0;
}

const PtexAdjacency& LimitSurface::adjacency(PtexFaceId face) const {
  assert(face.value >= 0 && face.value < num_ptex_faces());
  return impl_->adjacency[face.value];
}

std::span<const CageEdge> LimitSurface::inf_sharp_edges() const {
  return impl_->inf_sharp_edges;
}

}  // namespace dispex
