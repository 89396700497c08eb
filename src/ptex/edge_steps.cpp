// Edge steps of a map under both readers (include/dispex/ptex_sampler.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/check.h"
#include "dispex/ptex_sampler.h"

namespace dispex {

namespace {

// The step between two readings of every component: its absolute value for one component, the
// length of the step vector for several.
template <class Read>
double Step(std::size_t components, Read read) {
  if (components == 1) return std::abs(read(0));
  double sum = 0;
  for (std::size_t c = 0; c < components; ++c) {
    const double d = read(c);
    sum += d * d;
  }
  return std::sqrt(sum);
}

// Calls visit(e, first) for every edge e of face fi that the measurement counts, `first` the
// side across it at t = 0: between two faces not skipped, each edge once, with a
// face flagged in measure.only_faces on either side where that is given.
template <class Visit>
void ForEachCountedEdge(std::span<const PtexFaceInfo> faces, std::size_t fi,
                        std::span<const std::uint8_t> skip_faces, const PtexEdgeMeasure& measure,
                        Visit visit) {
  const int f = static_cast<int>(fi);
  if (skip_faces[fi]) return;
  for (int e = 0; e < 4; ++e) {
    PtexEdgeSide first;
    if (!PtexAcrossEdge(faces, PtexFaceId(f), e, 0.0, first)) continue;
    const int a = first.face.value;
    if (skip_faces[std::size_t(a)]) continue;
    // Between faces of one kind, each edge once: from the lower id (or lower edge on itself).
    if (faces[fi].subface == faces[std::size_t(a)].subface &&
        (a < f || (a == f && first.edge < e))) {
      continue;
    }
    if (!measure.only_faces.empty() && !measure.only_faces[fi] &&
        !measure.only_faces[std::size_t(a)]) {
      continue;
    }
    visit(e, first);
  }
}

// Whether edge e of face fi (neighbour a) takes its steps from measure.known, and where.
const double* KnownSteps(std::size_t fi, int e, int a, const PtexEdgeMeasure& measure) {
  if (measure.known.empty() || measure.changed[fi] || measure.changed[std::size_t(a)]) {
    return nullptr;
  }
  const double* known = &measure.known[8 * fi + 2 * std::size_t(e)];
  return std::isnan(known[0]) || std::isnan(known[1]) ? nullptr : known;
}

PtexEdgeSteps MeasureSteps(std::span<const PtexFaceInfo> faces,
                           std::span<const PtexMapSampler> samplers,
                           std::span<const std::uint8_t> skip_edges,
                           std::span<const std::uint8_t> skip_faces,
                           const PtexEdgeMeasure& measure) {
  const std::size_t n = faces.size();
  const std::size_t components = samplers.size();
  if (!measure.known.empty()) {
    DISPEX_CHECK_EQ(measure.known.size(), 8 * n);
    DISPEX_CHECK_EQ(measure.changed.size(), n);
  }
  struct FaceSteps {
    std::size_t edges = 0, skipped_edges = 0, known_edges = 0;
    std::vector<float> per_face, across_faces;
    std::vector<PtexEdgeStep> edge_max;
  };
  std::vector<FaceSteps> per(n);
  auto along = [&](int f, int e) {
    const PtexFaceInfo& info = faces[std::size_t(f)];
    return e % 2 == 0 ? info.ures() : info.vres();
  };
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t fi) {
    const int f = static_cast<int>(fi);
    FaceSteps& out = per[fi];
    ForEachCountedEdge(faces, fi, skip_faces, measure, [&](int e, const PtexEdgeSide& first) {
      const int a = first.face.value;
      ++out.edges;
      if (skip_edges[fi] & (1u << e)) {
        ++out.skipped_edges;
        return;
      }
      if (const double* known = KnownSteps(fi, e, a, measure)) {
        ++out.known_edges;
        out.edge_max.push_back({f, e, a, known[0], known[1], 0, 0});
        return;
      }
      const int points = std::max(16, 2 * std::max(along(f, e), along(a, first.edge)));
      PtexEdgeStep worst{f, e, a, 0, 0, 0, 0};
      for (int j = 0; j <= points; ++j) {
        const double t = double(j) / points;
        PtexEdgeSide other;
        PtexAcrossEdge(faces, PtexFaceId(f), e, t, other);
        double u = 0, v = 0, ou = 0, ov = 0;
        PtexEdgePoint(e, t, u, v);
        PtexEdgePoint(other.edge, other.t, ou, ov);
        const double face_step = measure.per_face
                                     ? Step(components,
                                            [&](std::size_t c) {
                                              return samplers[c].SampleFace(PtexFaceId(f), u, v) -
                                                     samplers[c].SampleFace(other.face, ou, ov);
                                            })
                                     : 0.0;
        const double filter_step = Step(components, [&](std::size_t c) {
          return samplers[c].SampleAcrossFaces(PtexFaceId(f), u, v) -
                 samplers[c].SampleAcrossFaces(other.face, ou, ov);
        });
        if (measure.keep_points) {
          out.per_face.push_back(static_cast<float>(face_step));
          out.across_faces.push_back(static_cast<float>(filter_step));
        }
        if (face_step > worst.per_face) worst.per_face = face_step, worst.t_per_face = t;
        if (filter_step > worst.across_faces) {
          worst.across_faces = filter_step, worst.t_across_faces = t;
        }
      }
      out.edge_max.push_back(worst);
    });
  });
  PtexEdgeSteps steps;
  for (FaceSteps& p : per) {
    steps.edges += p.edges;
    steps.skipped_edges += p.skipped_edges;
    steps.known_edges += p.known_edges;
    steps.per_face.insert(steps.per_face.end(), p.per_face.begin(), p.per_face.end());
    steps.across_faces.insert(steps.across_faces.end(), p.across_faces.begin(),
                              p.across_faces.end());
    steps.edge_max.insert(steps.edge_max.end(), p.edge_max.begin(), p.edge_max.end());
  }
  return steps;
}

}  // namespace

PtexEdgeSteps MeasurePtexEdgeSteps(std::span<const PtexFaceInfo> faces,
                                   std::span<const std::vector<float>> texels,
                                   std::span<const std::uint8_t> skip_edges,
                                   std::span<const std::uint8_t> skip_faces,
                                   const PtexEdgeMeasure& measure) {
  const PtexMapSampler sampler[1] = {PtexMapSampler(faces, texels)};
  return MeasureSteps(faces, sampler, skip_edges, skip_faces, measure);
}

PtexEdgeSteps MeasurePtexVectorEdgeSteps(
    std::span<const PtexFaceInfo> faces,
    std::span<const std::vector<std::vector<float>>> components,
    std::span<const std::uint8_t> skip_edges, std::span<const std::uint8_t> skip_faces,
    const PtexEdgeMeasure& measure) {
  std::vector<PtexMapSampler> samplers;
  samplers.reserve(components.size());
  for (const std::vector<std::vector<float>>& texels : components) {
    samplers.emplace_back(faces, texels);
  }
  return MeasureSteps(faces, samplers, skip_edges, skip_faces, measure);
}

std::vector<std::uint8_t> PtexFacesSampled(std::span<const PtexFaceInfo> faces,
                                           std::span<const std::uint8_t> skip_edges,
                                           std::span<const std::uint8_t> skip_faces,
                                           const PtexEdgeMeasure& measure) {
  std::vector<std::uint8_t> sampled(faces.size(), 0);
  for (std::size_t fi = 0; fi < faces.size(); ++fi) {
    ForEachCountedEdge(faces, fi, skip_faces, measure, [&](int e, const PtexEdgeSide& first) {
      const int a = first.face.value;
      if ((skip_edges[fi] & (1u << e)) || KnownSteps(fi, e, a, measure) != nullptr) return;
      sampled[fi] = sampled[std::size_t(a)] = 1;
    });
  }
  return sampled;
}

std::vector<double> PtexEdgeStepsByFace(std::span<const PtexEdgeStep> edge_max,
                                        std::size_t num_faces) {
  std::vector<double> by_face(8 * num_faces, std::numeric_limits<double>::quiet_NaN());
  for (const PtexEdgeStep& s : edge_max) {
    const std::size_t at = 8 * std::size_t(s.face) + 2 * std::size_t(s.edge);
    by_face[at] = s.per_face;
    by_face[at + 1] = s.across_faces;
  }
  return by_face;
}

std::size_t CountEdgesTouching(std::span<const PtexFaceInfo> faces,
                               std::span<const std::uint8_t> touching,
                               std::span<const std::uint8_t> skip_faces) {
  std::size_t count = 0;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    if (skip_faces[f]) continue;
    for (int e = 0; e < 4; ++e) {
      PtexEdgeSide other;
      if (!PtexAcrossEdge(faces, PtexFaceId(static_cast<int>(f)), e, 0.0, other)) continue;
      const auto a = static_cast<std::size_t>(other.face.value);
      if (skip_faces[a] || !(touching[f] || touching[a])) continue;
      // Once per edge: between faces of one kind from the lower id, else from the sub-face.
      if (faces[f].subface == faces[a].subface && (a < f || (a == f && other.edge < e))) continue;
      ++count;
    }
  }
  return count;
}

}  // namespace dispex
