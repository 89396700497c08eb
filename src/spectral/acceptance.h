// How SpectralAnalyzer and SpectralVectorAnalyzer judge a face's candidate resolutions
// (SpectralOptions, dispex/spectral.h): the read-back error against the tolerance and, with an
// edge tolerance, the per-face reader's error on the face's edges against that; and the
// rule's resolution raised to the options' floor. Inline: both analyzers call them per face.
#pragma once

#include <algorithm>

#include "dispex/spectral.h"
#include "spectral/block_shape.h"

namespace dispex::spectral {

struct Acceptance {
  explicit Acceptance(const SpectralOptions& options)
      : tolerance(options.tolerance),
        verify(options.rule == ResolutionRule::kErrorBound && options.verify),
        edge_tolerance(verify ? options.edge_tolerance : 0.0),
        pin(verify && options.pin_edges) {}

  double tolerance;
  bool verify;            // step up until a resolution is accepted
  double edge_tolerance;  // > 0: the edges are measured too
  bool pin;               // the edge texels are pinned to the samples

  bool measure_edges() const { return edge_tolerance > 0; }
  // Accepted when both errors are within theirs.
  bool Accepted(double error, double edge) const {
    return error <= tolerance && (edge_tolerance <= 0 || edge <= edge_tolerance);
  }
  // Candidates compete on the larger of the two ratios (on the error alone without edges).
  double Score(double error, double edge) const {
    return edge_tolerance > 0 ? std::max(error / tolerance, edge / edge_tolerance) : error;
  }
};

// Whether the options let a face be stored as one constant texel: the error-bound rule with no
// floor on the resolution.
inline bool ConstantAllowed(const SpectralOptions& options) {
  const bool has_floor = options.min_ulog2 > 0 || options.min_vlog2 > 0;
  return options.rule == ResolutionRule::kErrorBound && !has_floor;
}

// The error-bound rule's resolution (log2) raised to the options' floor, within the block's.
inline void RaiseToFloor(const SpectralOptions& options, const BlockShape& shape, int& kx,
                         int& ky) {
  if (options.rule != ResolutionRule::kErrorBound) return;
  kx = std::max(kx, std::min(options.min_ulog2, shape.lx));
  ky = std::max(ky, std::min(options.min_vlog2, shape.ly));
}

}  // namespace dispex::spectral
