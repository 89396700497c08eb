// Reading a Ptex map at any point as the renderers that use it do, to measure what they see
// where faces meet (docs/ptex.md, "Reading across face edges").
//
// Two readers:
//  - Per face: bilinear between the face's own texel centres ((i + 0.5) / ures,
//    (j + 0.5) / vres), clamped to its outermost texels (PtexFile::Sample; GPU Ptex without
//    border texels, and any reader that does not filter across faces).
//  - Across faces: the reference library's bilinear filter at zero filter width (wdas/ptex
//    PtexBilinearFilter on PtexSeparableFilter). A 2 x 2 kernel at the face's resolution;
//    where it reaches over an edge, the overhanging part is rotated into the neighbour and
//    applied there at the coarser of the two resolutions (the kernel is merged pairwise when
//    the neighbour is coarser; the neighbour's texels are box-reduced when it is finer);
//    over a corner it goes to the diagonal face at a regular (valence-4) vertex, is made
//    symmetric and shared by all corner faces at a valence-5+ vertex, and is dropped (the
//    weights renormalised) at a valence-2 or -3 vertex; at an edge without neighbour it is
//    folded back into the face (clamp). Sub-faces of n-gons follow the reference's sub-face
//    rules. Differences from the reference: arithmetic is in double and reductions are exact
//    box averages (the reference rounds each halving to the file's data type), so values
//    agree to float rounding.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "dispex/ids.h"
#include "dispex/ptex.h"

namespace dispex {

class PtexMapSampler {
 public:
  // `faces`: the map's face records (resolution, adjacency, sub-face flags); `texels`: per
  // face one channel of its level-0 texels, ures x vres values v-major, or a single value for
  // a constant face. Both must outlive the sampler. Precondition: one entry per face, sizes
  // as stated, adjacency within range.
  PtexMapSampler(std::span<const PtexFaceInfo> faces, std::span<const std::vector<float>> texels);
  ~PtexMapSampler();
  PtexMapSampler(PtexMapSampler&&) noexcept;
  PtexMapSampler& operator=(PtexMapSampler&&) noexcept;

  int num_faces() const;

  // The per-face reader at (u, v), clamped to [0, 1].
  double SampleFace(PtexFaceId face, double u, double v) const;
  // The reference bilinear filter at (u, v), clamped to [0, 1]. Thread-safe: box reductions
  // are built on first use, per face.
  double SampleAcrossFaces(PtexFaceId face, double u, double v) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where on its edge `edge` (0 bottom, 1 right, 2 top, 3 left) face parameter t in [0, 1]
// lies, counter-clockwise: (t, 0), (1, t), (1 - t, 1), (0, 1 - t).
void PtexEdgePoint(int edge, double t, double& u, double& v);

// The same point of the surface seen from across the edge: the neighbour and its edge and
// parameter. Between two faces or two sub-faces the parameter is reversed (1 - t); from a
// sub-face to the quad it borders, the sub-face's edge is half of the quad's (the half met
// first along the quad's edge when the quad names this sub-face, the second half otherwise).
// Returns false when the edge has no neighbour, or when `face` is a quad bordering sub-faces
// (measure those edges from the sub-face side, which covers them).
struct PtexEdgeSide {
  PtexFaceId face;
  int edge = 0;
  double t = 0;
};
bool PtexAcrossEdge(std::span<const PtexFaceInfo> faces, PtexFaceId face, int edge, double t,
                    PtexEdgeSide& other);

// ---- Steps where faces meet ------------------------------------------------------------------

// The largest steps on one edge, from `face`'s edge `edge` to `neighbour`, under each reader,
// and where along the face's edge (t) they are.
struct PtexEdgeStep {
  int face = -1, edge = 0, neighbour = -1;
  double per_face = 0, across_faces = 0;
  double t_per_face = 0, t_across_faces = 0;
};

// Steps on every edge between two faces, at t = j / n (j = 0..n) along it, n = max(16, 2 x
// the finer side's texels along the edge): every texel centre and edge of either side, where
// the piecewise-linear steps have their extremes, so the largest is exact. Edges flagged in
// `skip_edges` (bit e of a face's entry: its edge e, e.g. an infinitely sharp crease where
// the displacement itself jumps) are counted, not measured; faces flagged in `skip_faces`
// (holes) are left out with their edges. Deterministic: face by face in id order. `faces`
// and `texels` as for PtexMapSampler.
struct PtexEdgeSteps {
  std::size_t edges = 0, skipped_edges = 0;
  std::size_t known_edges = 0;                // of `edges`, taken from PtexEdgeMeasure::known
  std::vector<float> per_face, across_faces;  // one |step| per point, in edge order
  std::vector<PtexEdgeStep> edge_max;         // per measured edge its largest step
};
// PtexEdgeSteps::edge_max laid out as PtexEdgeMeasure::known reads it, for `num_faces` faces.
std::vector<double> PtexEdgeStepsByFace(std::span<const PtexEdgeStep> edge_max,
                                        std::size_t num_faces);

// Edges between two faces not in `skip_faces` of which at least one is in `touching`, each
// counted once (e.g. the edges a measurement left out because a face's data is not held).
std::size_t CountEdgesTouching(std::span<const PtexFaceInfo> faces,
                               std::span<const std::uint8_t> touching,
                               std::span<const std::uint8_t> skip_faces);

struct PtexEdgeMeasure {
  bool per_face = true;     // also the per-face reader (0 steps reported for it otherwise)
  bool keep_points = true;  // fill PtexEdgeSteps::per_face / across_faces
  // Empty: every edge. Else only the edges with a flagged face on either side (one per face).
  std::span<const std::uint8_t> only_faces;
  // Steps an earlier measurement of the same faces gave: per face, per edge e of it, per_face
  // and across_faces at [8 face + 2 e] and [8 face + 2 e + 1] (NaN where it measured none,
  // PtexEdgeStepsByFace). An edge with neither side flagged in `changed` (one per face: the
  // faces whose edges may step otherwise now, with every face around their corners) takes
  // them, t = 0, instead of being sampled where they are not NaN (keep_points: no points).
  std::span<const double> known;
  std::span<const std::uint8_t> changed;
};
PtexEdgeSteps MeasurePtexEdgeSteps(std::span<const PtexFaceInfo> faces,
                                   std::span<const std::vector<float>> texels,
                                   std::span<const std::uint8_t> skip_edges,
                                   std::span<const std::uint8_t> skip_faces,
                                   const PtexEdgeMeasure& measure = {});
// The same for a vector field given as its components (one `texels` as above per component,
// on the same faces), each read by its own sampler -- as the reference filter reads each
// channel of a map whose edge filter mode is none: per point the length of the step vector.
PtexEdgeSteps MeasurePtexVectorEdgeSteps(
    std::span<const PtexFaceInfo> faces,
    std::span<const std::vector<std::vector<float>>> components,
    std::span<const std::uint8_t> skip_edges, std::span<const std::uint8_t> skip_faces,
    const PtexEdgeMeasure& measure = {});
// The faces on either side of the edges MeasurePtex*EdgeSteps samples with these arguments
// (not those it skips or takes from measure.known), one flag per face: with the faces around
// their edges' ends, those whose texels it reads.
std::vector<std::uint8_t> PtexFacesSampled(std::span<const PtexFaceInfo> faces,
                                           std::span<const std::uint8_t> skip_edges,
                                           std::span<const std::uint8_t> skip_faces,
                                           const PtexEdgeMeasure& measure = {});

}  // namespace dispex
