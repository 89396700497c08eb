// Per-face resolution of vector displacements: SpectralAnalyzer's steps (constant test,
// truncation bound, DCT resampling, pinned edges, bilinear read-back with step-ups, the edge
// reading) run on the three channels at one common resolution, every error measured as the
// Euclidean norm of the vector's.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include "dispex/spectral.h"
#include "spectral/acceptance.h"
#include "spectral/aligned_buffer.h"
#include "spectral/bilinear_readback.h"
#include "spectral/block_shape.h"
#include "spectral/dct2d.h"
#include "spectral/dct_resample.h"
#include "spectral/edge_readback.h"
#include "spectral/nonzero_rule.h"
#include "spectral/truncation_bounds.h"

namespace dispex {

using spectral::Acceptance;
using spectral::BlockShape;
using spectral::ShapeOfLog2;

namespace {

constexpr int kChannels = 3;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A candidate resolution's errors: at the samples, and on the face's edges (0 when not
// measured), both as vector lengths.
struct Measured {
  double error = 0;
  double edge = 0;
};

}  // namespace

struct SpectralVectorAnalyzer::Impl {
  spectral::Dct2d dct;
  std::array<spectral::AlignedFloats, kChannels> samples, coefficients, texels, read_back;
  std::array<spectral::TruncationBounds, kChannels> bounds;
  spectral::AlignedFloats padded;
  std::array<spectral::AlignedFloats, 3> interleaved;  // the current resolution, two candidates
  std::array<float, kChannels> mean{};
  std::vector<double> edge_squares;
  bool pin = false, measure_edges = false;

  // The largest vector error of the per-face reader on the edges, for texels[c] at `res`.
  double EdgeError(const BlockShape& shape, const BlockShape& res) {
    if (!measure_edges) return 0;
    edge_squares.assign(spectral::EdgeReadCount(shape), 0.0);
    for (int c = 0; c < kChannels; ++c) {
      spectral::AddSquaredEdgeReadErrors(texels[c].data(), res, samples[c].data(), shape,
                                         edge_squares.data());
    }
    return std::sqrt(*std::max_element(edge_squares.begin(), edge_squares.end()));
  }

  // Splits the channels; the first non-finite value fails, named by (i, j) and channel.
  Status Load(std::span<const float> in, const BlockShape& shape) {
    const std::size_t n = shape.count();
    for (int c = 0; c < kChannels; ++c) {
      float* dst = samples[c].Reserve(n);
      double sum = 0;
      for (std::size_t k = 0; k < n; ++k) {
        dst[k] = in[kChannels * k + c];
        sum += dst[k];
      }
      if (!std::isfinite(sum)) {
        for (std::size_t k = 0; k < n; ++k) {
          if (!std::isfinite(dst[k])) {
            return Status::Error(
                fmt::format("sample ({}, {}) channel {} of the {} x {} block is not finite ({})",
                            k % shape.nx, k / shape.nx, c, shape.nx, shape.ny, dst[k]));
          }
        }
      }
      mean[c] = static_cast<float>(sum / static_cast<double>(n));
    }
    return Status::Ok();
  }

  double MaxDeviationFromMean(const BlockShape& shape) const {
    double worst = 0;
    for (std::size_t k = 0; k < shape.count(); ++k) {
      double d2 = 0;
      for (int c = 0; c < kChannels; ++c) {
        const double d = static_cast<double>(samples[c].data()[k]) - mean[c];
        d2 += d * d;
      }
      worst = std::max(worst, d2);
    }
    return std::sqrt(worst);
  }

  double Bound(int kx, int ky) const {
    double b2 = 0;
    for (const auto& b : bounds) b2 += b.Bound(kx, ky) * b.Bound(kx, ky);
    return std::sqrt(b2);
  }

  // TruncationBounds::Smallest on the vector bound.
  std::pair<int, int> Smallest(const BlockShape& shape, double tolerance) const {
    return spectral::SmallestWithin(shape.lx, shape.ly, tolerance,
                                    [this](int kx, int ky) { return Bound(kx, ky); });
  }

  // The channels resampled to `res` (their edge texels pinned when `pin`), interleaved into
  // interleaved[slot]; returns the largest vector read-back error at the samples and on the
  // edges.
  Measured ResampleAndMeasure(const BlockShape& shape, const BlockShape& res, int slot) {
    float* out = interleaved[slot].Reserve(kChannels * res.count());
    for (int c = 0; c < kChannels; ++c) {
      float* t = texels[c].Reserve(res.count());
      spectral::ResampleBlock(dct, samples[c].data(), coefficients[c].data(), shape, res, mean[c],
                              padded, t);
      if (pin) spectral::PinEdgeTexels(t, res, samples[c].data(), shape);
      for (std::size_t k = 0; k < res.count(); ++k) out[kChannels * k + c] = t[k];
      spectral::ReadBack(t, res, shape, read_back[c].Reserve(shape.count()));
    }
    double worst = 0;
    for (std::size_t k = 0; k < shape.count(); ++k) {
      double d2 = 0;
      for (int c = 0; c < kChannels; ++c) {
        const double d = static_cast<double>(read_back[c].data()[k]) - samples[c].data()[k];
        d2 += d * d;
      }
      worst = std::max(worst, d2);
    }
    return Measured{std::sqrt(worst), EdgeError(shape, res)};
  }

  // Analyze's steps, in order (SpectralAnalyzer's: see spectral_analyzer.cpp).
  //
  // A resolution 2^kx x 2^ky, its texels in interleaved[slot], and their errors.
  struct Candidate {
    int kx = 0, ky = 0, slot = 0;
    Measured measured;
  };
  // 1. The face as the samples' mean, when that is within the tolerances.
  bool AcceptConstant(const BlockShape& shape, const SpectralOptions& options,
                      const Acceptance& accept, SpectralVectorFace& face);
  // 2. The rule's resolution (on the vector bound, the largest of the channels' nonzero rules,
  // or the fixed one), into face.stats, raised to the floor.
  std::pair<int, int> RuleResolution(const BlockShape& shape, const SpectralOptions& options,
                                     SpectralFaceStats& stats);
  // 3. With verify: u or v doubled, whichever scores lower (ties go to u), until accepted; the
  // full resolution holds the samples themselves, so the loop ends.
  void StepUp(const BlockShape& shape, const Acceptance& accept, Candidate& at,
              SpectralFaceStats& stats);
};

bool SpectralVectorAnalyzer::Impl::AcceptConstant(const BlockShape& shape,
                                                  const SpectralOptions& options,
                                                  const Acceptance& accept,
                                                  SpectralVectorFace& face) {
  if (!spectral::ConstantAllowed(options)) return false;
  const double deviation = MaxDeviationFromMean(shape);
  if (!(deviation <= accept.tolerance)) return false;
  for (int c = 0; c < kChannels; ++c) texels[c].Reserve(1)[0] = mean[c];
  const Measured constant{deviation, EdgeError(shape, ShapeOfLog2(0, 0))};
  if (!accept.Accepted(constant.error, constant.edge)) return false;
  float* texel = interleaved[0].Reserve(kChannels);
  std::copy(mean.begin(), mean.end(), texel);
  face.constant = true;
  face.constant_value = mean;
  face.texels = std::span<const float>(texel, kChannels);
  face.stats.texels_after = 1;
  face.stats.bound = deviation;
  face.stats.measured_error = deviation;
  face.stats.edge_error = constant.edge;
  face.stats.constant = true;
  return true;
}

std::pair<int, int> SpectralVectorAnalyzer::Impl::RuleResolution(const BlockShape& shape,
                                                                 const SpectralOptions& options,
                                                                 SpectralFaceStats& stats) {
  for (int c = 0; c < kChannels; ++c) {
    dct.Forward(shape.lx, shape.ly, samples[c].data(), coefficients[c].Reserve(shape.count()));
    bounds[c].Build(coefficients[c].data(), shape);
  }
  int kx = 0;
  int ky = 0;
  switch (options.rule) {
    case ResolutionRule::kErrorBound:
      std::tie(kx, ky) = Smallest(shape, options.tolerance);
      break;
    case ResolutionRule::kNonzero:
      for (int c = 0; c < kChannels; ++c) {
        const auto [cx, cy] = spectral::NonzeroRuleResolution(coefficients[c].data(), shape,
                                                              options.nonzero_threshold);
        kx = std::max(kx, cx);
        ky = std::max(ky, cy);
      }
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

void SpectralVectorAnalyzer::Impl::StepUp(const BlockShape& shape, const Acceptance& accept,
                                          Candidate& at, SpectralFaceStats& stats) {
  while (!accept.Accepted(at.measured.error, at.measured.edge)) {
    const bool can_u = at.kx < shape.lx;
    const bool can_v = at.ky < shape.ly;
    if (!can_u && !can_v) {
      // Only the edge criterion can still fail, where the samples are too coarse for it.
      stats.edge_limited = measure_edges;
      break;
    }
    const Measured none{kInfinity, kInfinity};
    Candidate u{at.kx + 1, at.ky, (at.slot + 1) % 3, none};
    Candidate v{at.kx, at.ky + 1, (at.slot + 2) % 3, none};
    if (can_u) u.measured = ResampleAndMeasure(shape, ShapeOfLog2(u.kx, u.ky), u.slot);
    if (can_v) v.measured = ResampleAndMeasure(shape, ShapeOfLog2(v.kx, v.ky), v.slot);
    const bool take_u = can_u && accept.Score(u.measured.error, u.measured.edge) <=
                                     accept.Score(v.measured.error, v.measured.edge);
    at = take_u ? u : v;
    ++stats.step_ups;
  }
}

SpectralVectorAnalyzer::SpectralVectorAnalyzer() : impl_(std::make_unique<Impl>()) {}
SpectralVectorAnalyzer::~SpectralVectorAnalyzer() = default;
SpectralVectorAnalyzer::SpectralVectorAnalyzer(SpectralVectorAnalyzer&&) noexcept = default;
SpectralVectorAnalyzer& SpectralVectorAnalyzer::operator=(SpectralVectorAnalyzer&&) noexcept =
    default;

StatusOr<SpectralVectorFace> SpectralVectorAnalyzer::Analyze(std::span<const float> samples, int nx,
                                                             int ny,
                                                             const SpectralOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSpectralOptions(options));
  DISPEX_ASSIGN_OR_RETURN(const BlockShape shape, spectral::MakeBlockShape(nx, ny));
  if (samples.size() != kChannels * shape.count()) {
    return Status::Error(
        fmt::format("samples holds {} values, a {} x {} block of 3 channels "
                    "needs {}",
                    samples.size(), nx, ny, kChannels * shape.count()));
  }
  Impl& m = *impl_;
  DISPEX_RETURN_IF_ERROR(m.Load(samples, shape));

  SpectralVectorFace face;
  face.stats.texels_before = static_cast<std::int64_t>(shape.count());
  const Acceptance accept(options);
  m.measure_edges = accept.measure_edges();
  m.pin = accept.pin;
  if (m.AcceptConstant(shape, options, accept, face)) return face;

  Impl::Candidate at;
  std::tie(at.kx, at.ky) = m.RuleResolution(shape, options, face.stats);
  at.measured = m.ResampleAndMeasure(shape, ShapeOfLog2(at.kx, at.ky), at.slot);
  if (accept.verify) m.StepUp(shape, accept, at, face.stats);

  const BlockShape res = ShapeOfLog2(at.kx, at.ky);
  face.ulog2 = at.kx;
  face.vlog2 = at.ky;
  face.texels = std::span<const float>(m.interleaved[at.slot].data(), kChannels * res.count());
  face.constant = res.count() == 1;
  if (face.constant) std::copy_n(face.texels.begin(), kChannels, face.constant_value.begin());
  face.stats.texels_after = static_cast<std::int64_t>(res.count());
  face.stats.bound = m.Bound(at.kx, at.ky);
  face.stats.measured_error = at.measured.error;
  face.stats.edge_error = at.measured.edge;
  face.stats.constant = face.constant;
  return face;
}

}  // namespace dispex
