#include "verify/edge_steps.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "dispex/ptex_sampler.h"

namespace dispex {

std::vector<PtexFaceInfo> MapFacesOnSurface(const LimitSurface& surface, const PtexFile& map) {
  std::vector<PtexFaceInfo> faces(static_cast<std::size_t>(surface.num_ptex_faces()));
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const PtexFaceInfo& stored = map.face_info(PtexFaceId(f));
    PtexFaceInfo& info = faces[std::size_t(f)];
    info.ulog2 = stored.ulog2;
    info.vlog2 = stored.vlog2;
    info.subface = surface.num_ptex_faces(surface.base_face(PtexFaceId(f))) != 1;
    const PtexAdjacency& adjacency = surface.adjacency(PtexFaceId(f));
    for (int e = 0; e < 4; ++e) {
      info.adjfaces[std::size_t(e)] = adjacency.faces[std::size_t(e)].value;
      info.adjedges[std::size_t(e)] =
          adjacency.faces[std::size_t(e)].valid() ? std::uint8_t(adjacency.edges[std::size_t(e)]) : 0;
    }
  }
  return faces;
}

std::vector<std::uint8_t> SharpCreaseEdges(const Mesh& base, const LimitSurface& surface) {
  std::set<std::pair<std::int32_t, std::int32_t>> sharp;
  for (const auto& crease : base.tags.creases) {
    if (crease.sharpness < 10) continue;
    sharp.insert(std::minmax(crease.v0.value, crease.v1.value));
  }
  std::vector<std::uint8_t> bits(static_cast<std::size_t>(surface.num_ptex_faces()), 0);
  if (sharp.empty()) return bits;
  auto is_sharp = [&](std::int32_t a, std::int32_t b) { return sharp.count(std::minmax(a, b)) > 0; };
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const BaseFaceId base_face = surface.base_face(PtexFaceId(f));
    const auto verts = base.face(static_cast<std::size_t>(base_face.value));
    const int n = static_cast<int>(verts.size());
    auto vert = [&](int k) { return verts[static_cast<std::size_t>((k % n + n) % n)]; };
    std::uint8_t& b = bits[std::size_t(f)];
    if (n == 4) {
      for (int e = 0; e < 4; ++e) b |= std::uint8_t(is_sharp(vert(e), vert(e + 1)) << e);
    } else {
      const int q = surface.sub_face(PtexFaceId(f));
      b |= std::uint8_t(is_sharp(vert(q), vert(q + 1)) << 0);
      b |= std::uint8_t(is_sharp(vert(q - 1), vert(q)) << 3);
    }
  }
  return bits;
}

EdgeSteps MeasureEdgeSteps(std::span<const PtexFaceInfo> faces,
                           std::span<const std::vector<float>> texels,
                           std::span<const std::uint8_t> crease_edges,
                           std::span<const std::uint8_t> hole_faces) {
  const PtexMapSampler sampler(faces, texels);
  const std::size_t n = faces.size();
  struct FaceSteps {
    std::size_t edges = 0, crease_edges = 0;
    std::vector<float> per_face, across_faces;
    std::vector<VerifyReport::WorstEdge> worst;  // one per edge: its largest step
  };
  std::vector<FaceSteps> per(n);
  auto along = [&](int f, int e) {
    const PtexFaceInfo& info = faces[std::size_t(f)];
    return e % 2 == 0 ? info.ures() : info.vres();
  };
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t fi) {
    const int f = static_cast<int>(fi);
    if (hole_faces[fi]) return;
    FaceSteps& out = per[fi];
    for (int e = 0; e < 4; ++e) {
      PtexEdgeSide first;
      if (!PtexAcrossEdge(faces, PtexFaceId(f), e, 0.0, first)) continue;
      const int a = first.face.value;
      if (hole_faces[std::size_t(a)]) continue;
      // Between faces of one kind, each edge once: from the lower id (or lower edge on itself).
      if (faces[fi].subface == faces[std::size_t(a)].subface && (a < f || (a == f && first.edge < e))) {
        continue;
      }
      ++out.edges;
      if (crease_edges[fi] & (1u << e)) {
        ++out.crease_edges;
        continue;
      }
      const int points = std::max(16, 2 * std::max(along(f, e), along(a, first.edge)));
      VerifyReport::WorstEdge worst{f, e, a, 0, 0, ""};
      for (int j = 0; j <= points; ++j) {
        const double t = double(j) / points;
        PtexEdgeSide other;
        PtexAcrossEdge(faces, PtexFaceId(f), e, t, other);
        double u = 0, v = 0, ou = 0, ov = 0;
        PtexEdgePoint(e, t, u, v);
        PtexEdgePoint(other.edge, other.t, ou, ov);
        const double face_step =
            std::abs(sampler.SampleFace(PtexFaceId(f), u, v) - sampler.SampleFace(other.face, ou, ov));
        const double filter_step = std::abs(sampler.SampleAcrossFaces(PtexFaceId(f), u, v) -
                                            sampler.SampleAcrossFaces(other.face, ou, ov));
        out.per_face.push_back(static_cast<float>(face_step));
        out.across_faces.push_back(static_cast<float>(filter_step));
        if (face_step > worst.step) worst = {f, e, a, t, face_step, "per-face"};
        if (filter_step > worst.step) worst = {f, e, a, t, filter_step, "across-faces"};
      }
      if (worst.step > 0) out.worst.push_back(worst);
    }
  });
  EdgeSteps steps;
  for (FaceSteps& p : per) {
    steps.edges += p.edges;
    steps.crease_edges += p.crease_edges;
    steps.per_face.insert(steps.per_face.end(), p.per_face.begin(), p.per_face.end());
    steps.across_faces.insert(steps.across_faces.end(), p.across_faces.begin(), p.across_faces.end());
    steps.worst.insert(steps.worst.end(), p.worst.begin(), p.worst.end());
  }
  std::stable_sort(steps.worst.begin(), steps.worst.end(),
                   [](const auto& x, const auto& y) { return x.step > y.step; });
  if (steps.worst.size() > 10) steps.worst.resize(10);
  return steps;
}

}  // namespace dispex
