// Per-face resolution by frequency analysis.
//
// Follows the DCT approach to per-face Ptex resolution (take the 2-D DCT-II of the face's
// oversampled displacements, keep the band that holds its detail, resample to it) and makes
// "holds its detail" a guarantee in object units:
//   1. a face whose samples all lie within the tolerance of their mean is constant;
//   2. otherwise the truncation bound E(rx,ry) (truncation_bounds.h) picks the power-of-two
//      pair of fewest texels whose dropped coefficients cannot move a sample by more than
//      the tolerance;
//   3. the face is resampled to it in the DCT domain -- truncated coefficients scaled by
//      sqrt(rx ry / (nx ny)) and inverted at rx x ry, which is exact at the new texel centres
//      because the oversampled grid uses the same texel-centre rule as DCT-II;
//   4. the error a renderer sees (bilinear read-back, bilinear_readback.h) is measured, and u
//      or v, whichever lowers it more, is doubled until it is within the tolerance. The full
//      resolution stores the samples themselves, so the loop always ends.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <tuple>
#include <utility>

#include "core/check.h"
#include "dispex/spectral.h"
#include "spectral/acceptance.h"
#include "spectral/aligned_buffer.h"
#include "spectral/bilinear_readback.h"
#include "spectral/block_shape.h"
#include "spectral/dct2d.h"
#include "spectral/dct_resample.h"
#include "spectral/dct_scale.h"
#include "spectral/edge_readback.h"
#include "spectral/nonzero_rule.h"
#include "spectral/truncation_bounds.h"

namespace dispex {

using spectral::Acceptance;
using spectral::BlockShape;
using spectral::ShapeOfLog2;

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

struct SpectralAnalyzer::Impl {
  // What Load learns about a block while copying it.
  struct Summary {
    float mean = 0.0f;           // the mean, rounded to float (the constant-face value)
    double max_deviation = 0.0;  // max |sample - mean| (with the float mean)
  };

  spectral::Dct2d dct;
  spectral::AlignedFloats samples;                // aligned copy of the caller's block
  spectral::AlignedFloats coefficients;           // REDFT10 of `samples`
  spectral::AlignedFloats padded;                 // truncated / zero-padded input of the inverse
  std::array<spectral::AlignedFloats, 3> texels;  // current resolution and two candidates
  spectral::TruncationBounds bounds;

  // Copies `in` into `samples`; fails on the first non-finite value, named by (i, j).
  StatusOr<Summary> Load(std::span<const float> in, const BlockShape& shape, const char* what);

  // Resamples the loaded block (whose REDFT10 is in `coefficients` unless `res` equals `shape`
  // or is 1 x 1) to `res`, into texels[slot]; returns the texels.
  float* ResampleLoaded(const BlockShape& shape, const BlockShape& res, float mean, int slot);

  // Analyze's steps, in order (see the top of this file).
  //
  // A resolution 2^kx x 2^ky, its texels in texels[slot], and their errors: read back at the
  // samples, and on the edges (0 when not measured).
  struct Candidate {
    int kx = 0, ky = 0, slot = 0;
    double error = 0, edge = 0;
  };
  // The per-face reader's largest error on the edges, when they are measured.
  double EdgeError(const float* t, const BlockShape& res, const BlockShape& shape,
                   const Acceptance& accept) const {
    return accept.measure_edges() ? spectral::MaxEdgeReadError(t, res, samples.data(), shape) : 0.0;
  }
  // 1. The face as the samples' mean, when that is within the tolerances.
  bool AcceptConstant(const BlockShape& shape, const Summary& summary,
                      const SpectralOptions& options, const Acceptance& accept, SpectralFace& face);
  // 2. The rule's resolution (the truncation bound's, the nonzero rule's or the fixed one),
  // into face.stats, raised to the floor.
  std::pair<int, int> RuleResolution(const BlockShape& shape, const SpectralOptions& options,
                                     SpectralFaceStats& stats);
  // 3. Resamples to `res` into texels[slot], the edge texels pinned when accept.pin.
  const float* ResampleInto(const BlockShape& shape, const BlockShape& res, float mean, int slot,
                            const Acceptance& accept);
  // 4. With verify: u or v doubled, whichever scores lower (ties go to u), until accepted.
  void StepUp(const BlockShape& shape, float mean, const Acceptance& accept, Candidate& at,
              SpectralFaceStats& stats);
};

StatusOr<SpectralAnalyzer::Impl::Summary> SpectralAnalyzer::Impl::Load(std::span<const float> in,
                                                                       const BlockShape& shape,
                                                                       const char* what) {
  float* dst = samples.Reserve(shape.count());
  std::copy(in.begin(), in.end(), dst);
  // Four independent lanes (a fixed order: deterministic) keep the loop off the latency of
  // one accumulator. Sums of finite floats cannot overflow a double, so a non-finite sum
  // means a non-finite value: the loop stays branch-free and the culprit is searched for
  // only on failure.
  double lane_sum[4] = {0, 0, 0, 0};
  float lane_lo[4] = {dst[0], dst[0], dst[0], dst[0]};
  float lane_hi[4] = {dst[0], dst[0], dst[0], dst[0]};
  const std::size_t n = in.size();
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    for (int l = 0; l < 4; ++l) {
      const float x = dst[k + l];
      lane_sum[l] += x;
      lane_lo[l] = x < lane_lo[l] ? x : lane_lo[l];
      lane_hi[l] = x > lane_hi[l] ? x : lane_hi[l];
    }
  }
  for (; k < n; ++k) {
    lane_sum[0] += dst[k];
    lane_lo[0] = std::min(lane_lo[0], dst[k]);
    lane_hi[0] = std::max(lane_hi[0], dst[k]);
  }
  const double sum = (lane_sum[0] + lane_sum[1]) + (lane_sum[2] + lane_sum[3]);
  const float lo = std::min(std::min(lane_lo[0], lane_lo[1]), std::min(lane_lo[2], lane_lo[3]));
  const float hi = std::max(std::max(lane_hi[0], lane_hi[1]), std::max(lane_hi[2], lane_hi[3]));
  if (!std::isfinite(sum)) {
    for (std::size_t bad = 0; bad < n; ++bad) {
      if (!std::isfinite(in[bad])) {
        return Status::Error(fmt::format("{} ({}, {}) of the {} x {} block is not finite ({})",
                                         what, bad % shape.nx, bad / shape.nx, shape.nx, shape.ny,
                                         in[bad]));
      }
    }
  }
  Summary summary;
  summary.mean = static_cast<float>(sum / static_cast<double>(shape.count()));
  summary.max_deviation =
      std::max(static_cast<double>(hi) - summary.mean, static_cast<double>(summary.mean) - lo);
  return summary;
}

float* SpectralAnalyzer::Impl::ResampleLoaded(const BlockShape& shape, const BlockShape& res,
                                              float mean, int slot) {
  float* out = texels[slot].Reserve(res.count());
  spectral::ResampleBlock(dct, samples.data(), coefficients.data(), shape, res, mean, padded, out);
  return out;
}

SpectralAnalyzer::SpectralAnalyzer() : impl_(std::make_unique<Impl>()) {}
SpectralAnalyzer::~SpectralAnalyzer() = default;
SpectralAnalyzer::SpectralAnalyzer(SpectralAnalyzer&&) noexcept = default;
SpectralAnalyzer& SpectralAnalyzer::operator=(SpectralAnalyzer&&) noexcept = default;

bool SpectralAnalyzer::Impl::AcceptConstant(const BlockShape& shape, const Summary& summary,
                                            const SpectralOptions& options,
                                            const Acceptance& accept, SpectralFace& face) {
  if (!spectral::ConstantAllowed(options) || !(summary.max_deviation <= accept.tolerance)) {
    return false;
  }
  float* texel = texels[0].Reserve(1);
  texel[0] = summary.mean;
  const double edge = EdgeError(texel, ShapeOfLog2(0, 0), shape, accept);
  if (!accept.Accepted(summary.max_deviation, edge)) return false;
  face.constant = true;
  face.constant_value = summary.mean;
  face.texels = std::span<const float>(texel, 1);
  face.stats.texels_after = 1;
  face.stats.bound = summary.max_deviation;
  face.stats.measured_error = summary.max_deviation;
  face.stats.edge_error = edge;
  face.stats.constant = true;
  return true;
}

std::pair<int, int> SpectralAnalyzer::Impl::RuleResolution(const BlockShape& shape,
                                                           const SpectralOptions& options,
                                                           SpectralFaceStats& stats) {
  dct.Forward(shape.lx, shape.ly, samples.data(), coefficients.Reserve(shape.count()));
  bounds.Build(coefficients.data(), shape);
  int kx = 0;
  int ky = 0;
  switch (options.rule) {
    case ResolutionRule::kErrorBound:
      std::tie(kx, ky) = bounds.Smallest(options.tolerance);
      break;
    case ResolutionRule::kNonzero:
      std::tie(kx, ky) =
          spectral::NonzeroRuleResolution(coefficients.data(), shape, options.nonzero_threshold);
      break;
    case ResolutionRule::kFixed:
      kx = options.fixed_ulog2;
      ky = options.fixed_vlog2;
      break;
  }
  stats.bound_ulog2 = kx;
  stats.bound_vlog2 = ky;
  spectral::RaiseToFloor(options, shape, kx, ky);
  return {kx, ky};
}

const float* SpectralAnalyzer::Impl::ResampleInto(const BlockShape& shape, const BlockShape& res,
                                                  float mean, int slot, const Acceptance& accept) {
  float* t = ResampleLoaded(shape, res, mean, slot);
  if (accept.pin) spectral::PinEdgeTexels(t, res, samples.data(), shape);
  return t;
}

void SpectralAnalyzer::Impl::StepUp(const BlockShape& shape, float mean, const Acceptance& accept,
                                    Candidate& at, SpectralFaceStats& stats) {
  const bool early_stop = accept.verify && !accept.measure_edges();
  while (!accept.Accepted(at.error, at.edge)) {
    // Candidates: u doubled into one free slot, v doubled into the other. The v candidate's
    // measurement may stop once it exceeds the u candidate's (it has lost: ties go to u).
    const bool can_u = at.kx < shape.lx;
    const bool can_v = at.ky < shape.ly;
    if (!can_u && !can_v) {
      // The full resolution reads back exactly; only the edge criterion can still fail, where
      // the samples themselves are too coarse for it.
      DISPEX_CHECK(at.error <= accept.tolerance);
      stats.edge_limited = true;
      break;
    }
    Candidate u{at.kx + 1, at.ky, (at.slot + 1) % 3, kInfinity, kInfinity};
    Candidate v{at.kx, at.ky + 1, (at.slot + 2) % 3, kInfinity, kInfinity};
    if (can_u) {
      const BlockShape res = ShapeOfLog2(u.kx, u.ky);
      const float* t = ResampleInto(shape, res, mean, u.slot, accept);
      u.error = spectral::MaxReadBackError(t, res, samples.data(), shape, kInfinity);
      u.edge = EdgeError(t, res, shape, accept);
    }
    if (can_v) {
      const BlockShape res = ShapeOfLog2(v.kx, v.ky);
      const float* t = ResampleInto(shape, res, mean, v.slot, accept);
      v.error = spectral::MaxReadBackError(t, res, samples.data(), shape,
                                           early_stop ? u.error : kInfinity);
      v.edge = EdgeError(t, res, shape, accept);
    }
    at = can_u && accept.Score(u.error, u.edge) <= accept.Score(v.error, v.edge) ? u : v;
    ++stats.step_ups;
  }
}

StatusOr<SpectralFace> SpectralAnalyzer::Analyze(std::span<const float> samples, int nx, int ny,
                                                 const SpectralOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSpectralOptions(options));
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  Impl& m = *impl_;
  DISPEX_ASSIGN_OR_RETURN(const Impl::Summary summary, m.Load(samples, shape, "sample"));

  SpectralFace face;
  face.stats.texels_before = static_cast<std::int64_t>(shape.count());
  const Acceptance accept(options);
  if (m.AcceptConstant(shape, summary, options, accept, face)) return face;

  Impl::Candidate at;
  std::tie(at.kx, at.ky) = m.RuleResolution(shape, options, face.stats);
  const BlockShape first = ShapeOfLog2(at.kx, at.ky);
  const float* texels = m.ResampleInto(shape, first, summary.mean, at.slot, accept);
  at.error = spectral::MaxReadBackError(texels, first, m.samples.data(), shape,
                                        accept.verify ? accept.tolerance : kInfinity);
  at.edge = m.EdgeError(texels, first, shape, accept);
  if (accept.verify) m.StepUp(shape, summary.mean, accept, at, face.stats);

  const BlockShape res = ShapeOfLog2(at.kx, at.ky);
  face.ulog2 = at.kx;
  face.vlog2 = at.ky;
  face.texels = std::span<const float>(m.texels[at.slot].data(), res.count());
  face.constant = res.count() == 1;
  face.constant_value = face.constant ? face.texels[0] : 0.0f;
  face.stats.texels_after = static_cast<std::int64_t>(res.count());
  face.stats.bound = m.bounds.Bound(at.kx, at.ky);
  face.stats.measured_error = at.error;
  face.stats.edge_error = at.edge;
  face.stats.constant = face.constant;
  return face;
}

Status SpectralAnalyzer::ForwardDct(std::span<const float> samples, int nx, int ny,
                                    std::span<float> coefficients) {
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(coefficients.size(), shape, "coefficients"));
  Impl& m = *impl_;
  DISPEX_RETURN_IF_ERROR(m.Load(samples, shape, "sample").status());
  float* y = m.coefficients.Reserve(shape.count());
  m.dct.Forward(shape.lx, shape.ly, m.samples.data(), y);
  double sx[kMaxSpectralSize];
  for (int u = 0; u < nx; ++u) sx[u] = spectral::ForwardScale(u, nx);
  for (int v = 0; v < ny; ++v) {
    const double sy = spectral::ForwardScale(v, ny);
    for (int u = 0; u < nx; ++u) {
      const std::size_t k = static_cast<std::size_t>(v) * nx + u;
      coefficients[k] = static_cast<float>(y[k] * (sx[u] * sy));
    }
  }
  return Status::Ok();
}

Status SpectralAnalyzer::InverseDct(std::span<const float> coefficients, int nx, int ny,
                                    std::span<float> samples) {
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(coefficients.size(), shape, "coefficients"));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  Impl& m = *impl_;
  DISPEX_RETURN_IF_ERROR(m.Load(coefficients, shape, "coefficient").status());
  float* z = m.padded.Reserve(shape.count());
  double tx[kMaxSpectralSize];
  for (int u = 0; u < nx; ++u) tx[u] = spectral::InverseScale(u, nx);
  for (int v = 0; v < ny; ++v) {
    const double ty = spectral::InverseScale(v, ny);
    for (int u = 0; u < nx; ++u) {
      const std::size_t k = static_cast<std::size_t>(v) * nx + u;
      z[k] = static_cast<float>(m.samples.data()[k] * (tx[u] * ty));
    }
  }
  float* out = m.texels[0].Reserve(shape.count());
  m.dct.Inverse(shape.lx, shape.ly, z, out);
  std::copy(out, out + shape.count(), samples.begin());
  return Status::Ok();
}

Status SpectralAnalyzer::Resample(std::span<const float> samples, int nx, int ny, int ulog2,
                                  int vlog2, std::span<float> texels) {
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_ASSIGN_OR_RETURN(const BlockShape res, spectral::MakeTexelShape(ulog2, vlog2));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(texels.size(), res, "texels"));
  Impl& m = *impl_;
  DISPEX_ASSIGN_OR_RETURN(const Impl::Summary summary, m.Load(samples, shape, "sample"));
  m.dct.Forward(shape.lx, shape.ly, m.samples.data(), m.coefficients.Reserve(shape.count()));
  const float* out = m.ResampleLoaded(shape, res, summary.mean, 0);
  std::copy(out, out + res.count(), texels.begin());
  return Status::Ok();
}

}  // namespace dispex
