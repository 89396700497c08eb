// Unnormalised 2-D DCT-II / DCT-III in FFTW's conventions (REDFT10 / REDFT01) on aligned
// row-major blocks (u fastest), with FFTW plans made once per size and kept by this object.
//
//   Forward(x)(u,v) = 4 sum_ij x(i,j) cos(pi(2i+1)u/2nx) cos(pi(2j+1)v/2ny)   (REDFT10 x REDFT10)
//   Inverse(y)(i,j) = REDFT01 x REDFT01 of y;  Inverse(Forward(x)) = 4 nx ny x.
// Callers apply the orthonormal scaling (dct_scale.h).
//
// Two implementations of the same transform:
//  - kR2r: FFTW's r2r plan (fftwf_plan_r2r_2d). FFTW has no SIMD codelets for r2r, and
//    measured 24 us for 64 x 64 on the development machine;
//  - kPairedComplex: Makhoul's DCT through a DFT of the same length (J. Makhoul, "A fast
//    cosine transform in one and two dimensions", IEEE Trans. ASSP 28(1), 1980), two real rows
//    packed into one complex sequence, so that each direction is one batched complex FFTW plan
//    (SIMD codelets) plus O(n) pre/post-processing: 5.7 us for 64 x 64 (4x faster).
// kAuto takes kPairedComplex when both sides are >= 2 and the block has >= 128 samples (below
// that FFTW's small r2r codelets are as fast) -- a fixed rule, so a given size always takes the
// same path and results are deterministic.
//
// Determinism: plans use FFTW_ESTIMATE, a fixed heuristic, never timing (FFTW_MEASURE could pick
// a different algorithm per run and change the last bits). FFTW_ESTIMATE alone would still adopt
// wisdom that other code in the process gathers with FFTW_MEASURE for the same transform (it
// did: 2910 of 4096 coefficients of a 64 x 64 block changed in their last bits); adding
// FFTW_CONSERVE_MEMORY, a restriction such wisdom was not planned under, makes FFTW ignore it
// (same block, bit-identical). Every array comes from fftwf_malloc, so plans are made and
// executed with the same alignment and fftwf_execute_* on new arrays is valid. Plan creation
// and destruction go through one process-wide mutex (FFTW's planner is not thread-safe);
// execution is.
#pragma once

#include <array>

#include "dispex/spectral.h"
#include "spectral/aligned_buffer.h"

struct fftwf_plan_s;  // FFTW's plan type (fftwf_plan is a pointer to it)

namespace dispex::spectral {

class Dct2d {
 public:
  enum class Path { kAuto, kR2r, kPairedComplex };

  Dct2d() = default;
  ~Dct2d();
  Dct2d(const Dct2d&) = delete;
  Dct2d& operator=(const Dct2d&) = delete;

  // out = REDFT10 of the 2^lx x 2^ly block `in`. `in` and `out` are distinct fftwf_malloc
  // arrays of at least 2^(lx+ly) floats; `in` is preserved. kPairedComplex needs lx, ly >= 1.
  void Forward(int lx, int ly, float* in, float* out, Path path = Path::kAuto);
  // out = REDFT01 of `in`, same rules.
  void Inverse(int lx, int ly, float* in, float* out, Path path = Path::kAuto);

  static Path AutoPath(int lx, int ly);

 private:
  static constexpr int kSizes = kMaxSpectralLog2 + 1;
  // [direction 0 forward / 1 inverse][ly][lx]
  using PlanTable = std::array<std::array<std::array<fftwf_plan_s*, kSizes>, kSizes>, 2>;

  void R2r(int dir, int lx, int ly, float* in, float* out);
  void PairedForward(int lx, int ly, const float* in, float* out);
  void PairedInverse(int lx, int ly, const float* in, float* out);
  fftwf_plan_s* RowPlan(int dir, int lx, int ly);     // 2^(ly-1) DFTs of length 2^lx
  fftwf_plan_s* ColumnPlan(int dir, int lx, int ly);  // 2^(lx-1) DFTs of length 2^ly

  PlanTable r2r_{};
  PlanTable rows_{};
  PlanTable columns_{};
  AlignedFloats za_;  // complex scratch, interleaved (re, im)
  AlignedFloats zb_;
};

}  // namespace dispex::spectral
