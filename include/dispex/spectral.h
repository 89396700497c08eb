// Per-face resolution by frequency analysis.
//
// A face's displacement is sampled on an oversampled Nx x Ny grid at texel centres
// ((i+0.5)/Nx, (j+0.5)/Ny), row-major with u fastest: sample (i, j) is samples[j * Nx + i].
// Its orthonormal 2-D DCT-II F(u,v) gives the series
//   f(i,j) = sum a_x(u) a_y(v) F(u,v) cos(pi(2i+1)u / 2Nx) cos(pi(2j+1)v / 2Ny),
//   a_N(0) = sqrt(1/N), a_N(k) = sqrt(2/N),
// so keeping only u < rx, v < ry changes any sample by at most
//   E(rx,ry) = sum over dropped (u >= rx or v >= ry) of a_x(u) a_y(v) |F(u,v)|.
// The analyzer picks, per face, the power-of-two pair (rx, ry) of fewest texels with
// E <= tolerance, resamples the face to it in the DCT domain (exact at the new texel centres
// for the kept band), then measures what a renderer reads back -- the rx x ry texels
// bilinearly interpolated at the Nx x Ny sample positions, clamped to the edge texels at the
// face border -- and doubles u or v until that measured error is within the tolerance.
//
// Sizes: Nx and Ny are powers of two from 1 to 512 (kMaxSpectralSize); resolutions are given
// as log2 (Ptex's ulog2/vlog2), 0..9. Results are deterministic: the same block gives
// bit-identical output on any analyzer, thread or thread count (on the same machine).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "dispex/status.h"

namespace dispex {

inline constexpr int kMaxSpectralLog2 = 9;
inline constexpr int kMaxSpectralSize = 1 << kMaxSpectralLog2;  // 512

// How a face's resolution is chosen.
enum class ResolutionRule : std::uint8_t {
  // Default. Fewest texels whose DCT truncation bound is within `tolerance`; then (with
  // `verify`) the bilinear read-back error is measured and the resolution stepped up until it
  // is within `tolerance` too. Faces whose samples all lie within `tolerance` of their mean
  // become constant faces.
  kErrorBound,
  // The published rule, for comparison: "the highest non-zero frequency, times two", read
  // literally on the DCT index. u_max = the largest u with |F(u,v)| > nonzero_threshold for
  // some v (0 if none); rx = the smallest power of two >= 2 * u_max, at least 1, at most Nx;
  // ry likewise from v_max. Since 2 u_max >= u_max + 1 (u_max >= 1), every coefficient above
  // the threshold is kept. No tolerance, no verification (stats report bound and error).
  kNonzero,
  // Every face at 2^fixed_ulog2 x 2^fixed_vlog2 (zero-padded in the DCT domain, i.e.
  // band-limited interpolation, where that exceeds the sample grid).
  kFixed,
};

// "bound", "nonzero", "fixed".
std::string_view ResolutionRuleName(ResolutionRule rule);
// Parses a ResolutionRuleName; an error names the unknown value and lists the valid ones.
StatusOr<ResolutionRule> ParseResolutionRule(std::string_view name);

struct SpectralOptions {
  ResolutionRule rule = ResolutionRule::kErrorBound;
  // kErrorBound: the largest allowed error of any sample, in object units (>= 0, finite).
  double tolerance = 1e-3;
  // kErrorBound: measure the bilinear read-back and step up until it is within tolerance.
  // When false the bound alone decides: the band-limited series is then within tolerance at
  // every sample, but a bilinear read-back may deviate more.
  bool verify = true;
  // kErrorBound with verify: also step up until the per-face reader's value on each of the
  // face's edges (its outermost texels, clamped) is within this of the displacement there
  // (extrapolated from the two outermost sample rows), so that two faces read on their own
  // meet within twice this (0: off). Where even the samples cannot meet it the face stays at
  // the sample resolution (SpectralFaceStats::edge_limited).
  double edge_tolerance = 0.0;
  // kErrorBound with verify: the outermost texels hold the displacement on the face's edges
  // (extrapolated from the two outermost sample rows) instead of at their centres, so that
  // neighbours meet on the edge itself under any reader; the read-back check then measures
  // the cost inside the face.
  bool pin_edges = false;
  // kErrorBound: the least resolution (log2 per side, capped at the sample grid's), e.g. for
  // a face whose neighbours need it to meet without a step. Faces with a floor are never
  // made constant.
  int min_ulog2 = 0;
  int min_vlog2 = 0;
  // kNonzero: |F(u,v)| above this counts as non-zero (>= 0, finite; orthonormal scale).
  double nonzero_threshold = 0.0;
  // kFixed: the resolution, 0..kMaxSpectralLog2 each.
  int fixed_ulog2 = 6;
  int fixed_vlog2 = 6;
};

// OK, or an error naming the offending field and value.
Status ValidateSpectralOptions(const SpectralOptions& options);

// What happened to one face; the caller aggregates these (SpectralTotals).
struct SpectralFaceStats {
  std::int64_t texels_before = 0;  // Nx * Ny
  std::int64_t texels_after = 0;   // rx * ry (1 for a constant face)
  // Upper bound on |series truncated to rx x ry - sample| over all samples: E(rx,ry), or,
  // for a face found constant by the direct test, max |sample - mean| itself.
  double bound = 0.0;
  // max over samples of |bilinear read-back of the stored texels - sample| (computed in
  // double from the stored float texels). 0 at full resolution.
  double measured_error = 0.0;
  // The resolution the bound alone chose (kErrorBound), or the rule's choice; the final
  // resolution differs from it by `step_ups` doublings.
  int bound_ulog2 = 0;
  int bound_vlog2 = 0;
  int step_ups = 0;
  bool constant = false;
  // With an edge tolerance: the per-face reader's largest error on the face's edges, and
  // whether the edge tolerance was out of reach at the sample resolution.
  double edge_error = 0.0;
  bool edge_limited = false;
};

// Totals over faces. Every member is a count or a maximum, so the totals do not depend on the
// order in which faces are added or partial totals merged (thread count).
struct SpectralTotals {
  std::int64_t faces = 0;
  std::int64_t constant_faces = 0;
  std::int64_t stepped_up_faces = 0;  // faces where verification raised the resolution
  std::int64_t step_ups = 0;
  std::int64_t texels_before = 0;
  std::int64_t texels_after = 0;
  double max_bound = 0.0;
  double max_measured_error = 0.0;
  double max_edge_error = 0.0;
  std::int64_t edge_limited_faces = 0;
  // Faces by final ulog2 / vlog2.
  std::array<std::int64_t, kMaxSpectralLog2 + 1> ulog2_faces{};
  std::array<std::int64_t, kMaxSpectralLog2 + 1> vlog2_faces{};

  // Adds one face: its stats and its final resolution (SpectralFace::ulog2, vlog2).
  void Add(const SpectralFaceStats& face, int ulog2, int vlog2);
  // Adds another partial total (e.g. one per thread).
  void Merge(const SpectralTotals& other);
};

// The analysis of one face.
struct SpectralFace {
  int ulog2 = 0;  // final resolution: rx = 1 << ulog2, ry = 1 << vlog2
  int vlog2 = 0;
  bool constant = false;        // true exactly when rx = ry = 1
  float constant_value = 0.0f;  // the samples' mean (rounded to float) when constant
  // rx * ry texels, row-major, u fastest: texel (i, j) at ((i+0.5)/rx, (j+0.5)/ry). At full
  // resolution (rx = Nx, ry = Ny) they are the samples themselves. Points into the analyzer's
  // scratch: valid until its next call.
  std::span<const float> texels;
  SpectralFaceStats stats;
};

// Per-thread analysis state: FFTW plans per size and aligned scratch buffers, reused across
// faces, so that steady-state analysis allocates nothing. Not thread-safe: give each thread
// its own (e.g. tbb::enumerable_thread_specific). Creating plans for a new size takes a
// process-wide lock (FFTW's planner is not thread-safe). Plans use FFTW_ESTIMATE, so the
// algorithm does not depend on timing, plus FFTW_CONSERVE_MEMORY, so that FFTW wisdom other
// code in the process gathers with default flags is not adopted (it would change last bits).
// A moved-from analyzer may only be destroyed or assigned to.
namespace spectral {
struct AnalyzerSteps;
}  // namespace spectral

class SpectralAnalyzer {
 public:
  SpectralAnalyzer();
  ~SpectralAnalyzer();
  SpectralAnalyzer(SpectralAnalyzer&&) noexcept;
  SpectralAnalyzer& operator=(SpectralAnalyzer&&) noexcept;
  SpectralAnalyzer(const SpectralAnalyzer&) = delete;
  SpectralAnalyzer& operator=(const SpectralAnalyzer&) = delete;

  // Chooses the face's resolution and computes its texels (see SpectralOptions).
  // `samples` holds nx * ny finite values. Errors (Status): nx or ny not a power of two in
  // 1..512, samples.size() != nx * ny, a non-finite sample (named by (i, j)), invalid options.
  // Guarantee with kErrorBound and verify: stats.measured_error <= tolerance, and
  // stats.edge_error <= edge_tolerance unless stats.edge_limited.
  StatusOr<SpectralFace> Analyze(std::span<const float> samples, int nx, int ny,
                                 const SpectralOptions& options);

 private:
  // The analysis's steps one at a time, for tests and benchmarks: reached through
  // spectral::AnalyzerSteps (src/spectral/analyzer_steps.h), not part of the library's API.
  friend struct spectral::AnalyzerSteps;

  // Orthonormal 2-D DCT-II of an nx x ny block: coefficients[v * nx + u] = F(u,v).
  // Same size rules as Analyze; `coefficients` must hold nx * ny values and not overlap.
  Status ForwardDct(std::span<const float> samples, int nx, int ny, std::span<float> coefficients);
  // Its inverse (orthonormal DCT-III): InverseDct(ForwardDct(x)) = x up to rounding.
  Status InverseDct(std::span<const float> coefficients, int nx, int ny, std::span<float> samples);

  // Resamples an nx x ny block to 2^ulog2 x 2^vlog2 texels in the DCT domain: coefficients
  // with u >= rx or v >= ry are dropped (or, where rx > nx, zeros are appended), scaled by
  // sqrt(rx ry / (nx ny)), and inverted at size rx x ry. The texels equal the kept series at
  // their centres; at rx = nx, ry = ny they are the samples, bit for bit. `texels` must hold
  // rx * ry values. Errors as for Analyze, plus ulog2/vlog2 outside 0..9.
  Status Resample(std::span<const float> samples, int nx, int ny, int ulog2, int vlog2,
                  std::span<float> texels);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---- Vector faces ------------------------------------------------------------------------------

// The analysis of one face of a 3-channel (vector) displacement: the rules above with every
// error the Euclidean norm over the channels -- the largest |vector read-back - vector sample|
// -- and the truncation bound sqrt(E_0^2 + E_1^2 + E_2^2) of the channels' bounds (each channel
// moves by at most its E, so the vector by at most that).
struct SpectralVectorFace {
  int ulog2 = 0;
  int vlog2 = 0;
  bool constant = false;
  std::array<float, 3> constant_value{};  // the channels' means when constant
  // rx * ry texels of 3 interleaved channels, row-major, u fastest. Points into the
  // analyzer's scratch: valid until its next call.
  std::span<const float> texels;
  SpectralFaceStats stats;  // errors and bound of the vector
};

// Per-thread analysis of vector faces, like SpectralAnalyzer (same plans, same determinism).
// Supports every ResolutionRule (kNonzero: the largest of the channels' resolutions), the
// resolution floor and the edge options (pin_edges pins each channel; edge_tolerance bounds the
// vector length of the edge read error).
class SpectralVectorAnalyzer {
 public:
  SpectralVectorAnalyzer();
  ~SpectralVectorAnalyzer();
  SpectralVectorAnalyzer(SpectralVectorAnalyzer&&) noexcept;
  SpectralVectorAnalyzer& operator=(SpectralVectorAnalyzer&&) noexcept;
  SpectralVectorAnalyzer(const SpectralVectorAnalyzer&) = delete;
  SpectralVectorAnalyzer& operator=(const SpectralVectorAnalyzer&) = delete;

  // `samples` holds 3 * nx * ny finite values, the channels interleaved. Errors as for
  // SpectralAnalyzer::Analyze. Guarantee with kErrorBound and verify: stats.measured_error <=
  // tolerance.
  StatusOr<SpectralVectorFace> Analyze(std::span<const float> samples, int nx, int ny,
                                       const SpectralOptions& options);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dispex
