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

#include "core/check.h"
#include "dispex/spectral.h"
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

StatusOr<SpectralFace> SpectralAnalyzer::Analyze(std::span<const float> samples, int nx, int ny,
                                                 const SpectralOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSpectralOptions(options));
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  DISPEX_RETURN_IF_ERROR(spectral::CheckSpanSize(samples.size(), shape, "samples"));
  Impl& m = *impl_;
  DISPEX_ASSIGN_OR_RETURN(const Impl::Summary summary, m.Load(samples, shape, "sample"));

  SpectralFace face;
  face.stats.texels_before = static_cast<std::int64_t>(shape.count());
  const double tolerance = options.tolerance;
  const bool verify = options.rule == ResolutionRule::kErrorBound && options.verify;
  // With an edge tolerance, a resolution is accepted when both the read-back error and the
  // per-face reader's error on the face's edges are within theirs; candidates compete on the
  // larger of the two ratios.
  const double edge_tolerance = verify ? options.edge_tolerance : 0.0;
  auto edge_error = [&](const float* texels, const BlockShape& res) {
    return edge_tolerance > 0 ? spectral::MaxEdgeReadError(texels, res, m.samples.data(), shape)
                              : 0.0;
  };
  auto score = [&](double error, double edge) {
    return edge_tolerance > 0 ? std::max(error / tolerance, edge / edge_tolerance) : error;
  };
  auto accepted = [&](double error, double edge) {
    return error <= tolerance && (edge_tolerance <= 0 || edge <= edge_tolerance);
  };
  const bool has_floor = options.min_ulog2 > 0 || options.min_vlog2 > 0;
  if (options.rule == ResolutionRule::kErrorBound && summary.max_deviation <= tolerance &&
      !has_floor) {
    float* texel = m.texels[0].Reserve(1);
    texel[0] = summary.mean;
    const double edge = edge_error(texel, ShapeOfLog2(0, 0));
    if (accepted(summary.max_deviation, edge)) {
      face.constant = true;
      face.constant_value = summary.mean;
      face.texels = std::span<const float>(texel, 1);
      face.stats.texels_after = 1;
      face.stats.bound = summary.max_deviation;
      face.stats.measured_error = summary.max_deviation;
      face.stats.edge_error = edge;
      face.stats.constant = true;
      return face;
    }
  }

  m.dct.Forward(shape.lx, shape.ly, m.samples.data(), m.coefficients.Reserve(shape.count()));
  m.bounds.Build(m.coefficients.data(), shape);
  int kx = 0;
  int ky = 0;
  switch (options.rule) {
    case ResolutionRule::kErrorBound:
      std::tie(kx, ky) = m.bounds.Smallest(tolerance);
      break;
    case ResolutionRule::kNonzero:
      std::tie(kx, ky) =
          spectral::NonzeroRuleResolution(m.coefficients.data(), shape, options.nonzero_threshold);
      break;
    case ResolutionRule::kFixed:
      kx = options.fixed_ulog2;
      ky = options.fixed_vlog2;
      break;
  }
  face.stats.bound_ulog2 = kx;
  face.stats.bound_vlog2 = ky;
  if (options.rule == ResolutionRule::kErrorBound) {
    kx = std::max(kx, std::min(options.min_ulog2, shape.lx));
    ky = std::max(ky, std::min(options.min_vlog2, shape.ly));
  }

  const bool pin = verify && options.pin_edges;
  auto resample = [&](const BlockShape& res, int into) -> const float* {
    float* t = m.ResampleLoaded(shape, res, summary.mean, into);
    if (pin) spectral::PinEdgeTexels(t, res, m.samples.data(), shape);
    return t;
  };
  int slot = 0;
  const float* texels = resample(ShapeOfLog2(kx, ky), slot);
  const bool early_stop = verify && edge_tolerance <= 0;
  double error = spectral::MaxReadBackError(texels, ShapeOfLog2(kx, ky), m.samples.data(), shape,
                                            verify ? tolerance : kInfinity);
  double edge = edge_error(texels, ShapeOfLog2(kx, ky));
  while (verify && !accepted(error, edge)) {
    // Candidates: u doubled into one free slot, v doubled into the other. The v candidate's
    // measurement may stop once it exceeds the u candidate's (it has lost: ties go to u).
    const bool can_u = kx < shape.lx;
    const bool can_v = ky < shape.ly;
    if (!can_u && !can_v) {
      // The full resolution reads back exactly; only the edge criterion can still fail, where
      // the samples themselves are too coarse for it.
      DISPEX_CHECK(error <= tolerance);
      face.stats.edge_limited = true;
      break;
    }
    const int slot_u = (slot + 1) % 3;
    const int slot_v = (slot + 2) % 3;
    double error_u = kInfinity, edge_u = kInfinity;
    double error_v = kInfinity, edge_v = kInfinity;
    if (can_u) {
      const BlockShape res = ShapeOfLog2(kx + 1, ky);
      const float* t = resample(res, slot_u);
      error_u = spectral::MaxReadBackError(t, res, m.samples.data(), shape, kInfinity);
      edge_u = edge_error(t, res);
    }
    if (can_v) {
      const BlockShape res = ShapeOfLog2(kx, ky + 1);
      const float* t = resample(res, slot_v);
      error_v = spectral::MaxReadBackError(t, res, m.samples.data(), shape,
                                           early_stop ? error_u : kInfinity);
      edge_v = edge_error(t, res);
    }
    if (can_u && score(error_u, edge_u) <= score(error_v, edge_v)) {
      ++kx;
      slot = slot_u;
      error = error_u;
      edge = edge_u;
    } else {
      ++ky;
      slot = slot_v;
      error = error_v;
      edge = edge_v;
    }
    ++face.stats.step_ups;
  }

  const BlockShape res = ShapeOfLog2(kx, ky);
  face.ulog2 = kx;
  face.vlog2 = ky;
  face.texels = std::span<const float>(m.texels[slot].data(), res.count());
  face.constant = res.count() == 1;
  face.constant_value = face.constant ? face.texels[0] : 0.0f;
  face.stats.texels_after = static_cast<std::int64_t>(res.count());
  face.stats.bound = m.bounds.Bound(kx, ky);
  face.stats.measured_error = error;
  face.stats.edge_error = edge;
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
