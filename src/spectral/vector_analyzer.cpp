// Per-face resolution of vector displacements: SpectralAnalyzer's steps (constant test,
// truncation bound, DCT resampling, bilinear read-back with step-ups) run on the three
// channels at one common resolution, every error measured as the Euclidean norm of the
// vector's.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "dispex/spectral.h"
#include "spectral/aligned_buffer.h"
#include "spectral/bilinear_readback.h"
#include "spectral/block_shape.h"
#include "spectral/dct2d.h"
#include "spectral/dct_resample.h"
#include "spectral/nonzero_rule.h"
#include "spectral/truncation_bounds.h"

namespace dispex {

using spectral::BlockShape;
using spectral::ShapeOfLog2;

namespace {

constexpr int kChannels = 3;

}  // namespace

struct SpectralVectorAnalyzer::Impl {
  spectral::Dct2d dct;
  std::array<spectral::AlignedFloats, kChannels> samples, coefficients, texels, read_back;
  std::array<spectral::TruncationBounds, kChannels> bounds;
  spectral::AlignedFloats padded;
  std::array<spectral::AlignedFloats, 3> interleaved;  // the current resolution, two candidates
  std::array<float, kChannels> mean{};

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

  // The channels resampled to `res`, interleaved into interleaved[slot]; returns the largest
  // vector read-back error at the samples.
  double ResampleAndMeasure(const BlockShape& shape, const BlockShape& res, int slot) {
    float* out = interleaved[slot].Reserve(kChannels * res.count());
    for (int c = 0; c < kChannels; ++c) {
      float* t = texels[c].Reserve(res.count());
      spectral::ResampleBlock(dct, samples[c].data(), coefficients[c].data(), shape, res, mean[c],
                              padded, t);
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
    return std::sqrt(worst);
  }
};

SpectralVectorAnalyzer::SpectralVectorAnalyzer() : impl_(std::make_unique<Impl>()) {}
SpectralVectorAnalyzer::~SpectralVectorAnalyzer() = default;
SpectralVectorAnalyzer::SpectralVectorAnalyzer(SpectralVectorAnalyzer&&) noexcept = default;
SpectralVectorAnalyzer& SpectralVectorAnalyzer::operator=(SpectralVectorAnalyzer&&) noexcept =
    default;

StatusOr<SpectralVectorFace> SpectralVectorAnalyzer::Analyze(std::span<const float> samples, int nx,
                                                             int ny,
                                                             const SpectralOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateSpectralOptions(options));
  if (options.edge_tolerance > 0 || options.pin_edges) {
    return Status::Error("vector faces take no edge tolerance and no pinned edges");
  }
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
  const double tolerance = options.tolerance;
  const bool verify = options.rule == ResolutionRule::kErrorBound && options.verify;
  const bool has_floor = options.min_ulog2 > 0 || options.min_vlog2 > 0;
  if (options.rule == ResolutionRule::kErrorBound && !has_floor) {
    const double deviation = m.MaxDeviationFromMean(shape);
    if (deviation <= tolerance) {
      float* texel = m.interleaved[0].Reserve(kChannels);
      std::copy(m.mean.begin(), m.mean.end(), texel);
      face.constant = true;
      face.constant_value = m.mean;
      face.texels = std::span<const float>(texel, kChannels);
      face.stats.texels_after = 1;
      face.stats.bound = deviation;
      face.stats.measured_error = deviation;
      face.stats.constant = true;
      return face;
    }
  }

  for (int c = 0; c < kChannels; ++c) {
    m.dct.Forward(shape.lx, shape.ly, m.samples[c].data(),
                  m.coefficients[c].Reserve(shape.count()));
    m.bounds[c].Build(m.coefficients[c].data(), shape);
  }
  int kx = 0;
  int ky = 0;
  switch (options.rule) {
    case ResolutionRule::kErrorBound:
      std::tie(kx, ky) = m.Smallest(shape, tolerance);
      break;
    case ResolutionRule::kNonzero:
      for (int c = 0; c < kChannels; ++c) {
        const auto [cx, cy] = spectral::NonzeroRuleResolution(m.coefficients[c].data(), shape,
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
  face.stats.bound_ulog2 = kx;
  face.stats.bound_vlog2 = ky;
  if (options.rule == ResolutionRule::kErrorBound) {
    kx = std::max(kx, std::min(options.min_ulog2, shape.lx));
    ky = std::max(ky, std::min(options.min_vlog2, shape.ly));
  }

  int slot = 0;
  double error = m.ResampleAndMeasure(shape, ShapeOfLog2(kx, ky), slot);
  while (verify && error > tolerance) {
    // Double u or v, whichever lowers the error more (ties go to u); the full resolution
    // holds the samples themselves, so the loop ends.
    const bool can_u = kx < shape.lx;
    const bool can_v = ky < shape.ly;
    if (!can_u && !can_v) break;
    const int slot_u = (slot + 1) % 3;
    const int slot_v = (slot + 2) % 3;
    constexpr double kNone = std::numeric_limits<double>::infinity();
    const double error_u =
        can_u ? m.ResampleAndMeasure(shape, ShapeOfLog2(kx + 1, ky), slot_u) : kNone;
    const double error_v =
        can_v ? m.ResampleAndMeasure(shape, ShapeOfLog2(kx, ky + 1), slot_v) : kNone;
    if (can_u && error_u <= error_v) {
      ++kx;
      slot = slot_u;
      error = error_u;
    } else {
      ++ky;
      slot = slot_v;
      error = error_v;
    }
    ++face.stats.step_ups;
  }

  const BlockShape res = ShapeOfLog2(kx, ky);
  face.ulog2 = kx;
  face.vlog2 = ky;
  face.texels = std::span<const float>(m.interleaved[slot].data(), kChannels * res.count());
  face.constant = res.count() == 1;
  if (face.constant) std::copy_n(face.texels.begin(), kChannels, face.constant_value.begin());
  face.stats.texels_after = static_cast<std::int64_t>(res.count());
  face.stats.bound = m.Bound(kx, ky);
  face.stats.measured_error = error;
  face.stats.constant = face.constant;
  return face;
}

}  // namespace dispex
