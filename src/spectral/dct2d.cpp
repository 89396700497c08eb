// 2-D DCT-II / DCT-III through FFTW: see dct2d.h.
//
// Makhoul's 1-D DCT-II of length N (N even): reorder v(n) = x(2n), v(N-1-n) = x(2n+1) for
// n < N/2; V = DFT(v); then REDFT10(x)(k) = 2 Re(w_k V(k)), w_k = exp(-i pi k / 2N).
// Two real rows a, b go through one complex DFT: z = v_a + i v_b, Z = DFT(z), and with
// S = Z(k) + conj(Z(N-k)), D = Z(k) - conj(Z(N-k)):
//   REDFT10(a)(k) = Re(w_k S),  REDFT10(b)(k) = Im(w_k D).
// The DCT-III (REDFT01) runs the same steps backwards: with Y(N) = 0,
//   V'(k) = conj(w_k) (Y(k) - i Y(N-k))  makes  REDFT01(Y)(2n) = v(n), (2n+1) = v(N-1-n)
// for v = unnormalised inverse DFT of V'; packing two rows, Z = conj(w_k) ((Ya(k) + Yb(N-k)) +
// i (Yb(k) - Ya(N-k))) and the inverse DFT's real / imaginary parts are a's / b's v.
// In 2-D the row pass writes its output rows directly in the column pass's reordered row order,
// and the column pass pairs adjacent columns, which in a row-major block are adjacent floats:
// so one complex element per column pair and each pass is one batched FFTW plan.
#include "spectral/dct2d.h"

#include <fftw3.h>

#include <cmath>
#include <mutex>
#include <numbers>

#include "core/check.h"

namespace dispex::spectral {
namespace {

constexpr unsigned kPlannerFlags = FFTW_ESTIMATE | FFTW_CONSERVE_MEMORY;

std::mutex& PlannerMutex() {
  static std::mutex mutex;
  return mutex;
}

// w_k = exp(-i pi k / 2N) for every N = 2^l, l = 0..9, as interleaved (cos, -sin) floats.
struct Twiddles {
  std::array<float, 2 * 2 * kMaxSpectralSize> data{};
  Twiddles() {
    for (int l = 0; l <= kMaxSpectralLog2; ++l) {
      const int n = 1 << l;
      for (int k = 0; k < n; ++k) {
        const double angle = std::numbers::pi * k / (2.0 * n);
        data[2 * (n + k)] = static_cast<float>(std::cos(angle));
        data[2 * (n + k) + 1] = static_cast<float>(-std::sin(angle));
      }
    }
  }
  // The table for N = 2^l: entries 2k (real) and 2k+1 (imaginary).
  const float* For(int l) const { return data.data() + 2 * (1 << l); }
};

const Twiddles& GetTwiddles() {
  static const Twiddles twiddles;
  return twiddles;
}

// Position of sequence element i in Makhoul's reordering of a length-n sequence.
inline int Reordered(int i, int n) {
  return (i & 1) ? n - 1 - (i >> 1) : (i >> 1);
}

fftwf_complex* AsComplex(float* p) {
  return reinterpret_cast<fftwf_complex*>(p);
}

}  // namespace

Dct2d::~Dct2d() {
  std::lock_guard<std::mutex> lock(PlannerMutex());
  for (const PlanTable* table : {&r2r_, &rows_, &columns_}) {
    for (const auto& by_dir : *table) {
      for (const auto& by_ly : by_dir) {
        for (fftwf_plan_s* plan : by_ly) {
          if (plan != nullptr) fftwf_destroy_plan(plan);
        }
      }
    }
  }
}

Dct2d::Path Dct2d::AutoPath(int lx, int ly) {
  return lx >= 1 && ly >= 1 && lx + ly >= 7 ? Path::kPairedComplex : Path::kR2r;
}

void Dct2d::Forward(int lx, int ly, float* in, float* out, Path path) {
  DISPEX_CHECK(lx >= 0 && lx < kSizes && ly >= 0 && ly < kSizes && in != out);
  DISPEX_CHECK(fftwf_alignment_of(in) == 0 && fftwf_alignment_of(out) == 0);
  if (path == Path::kAuto) path = AutoPath(lx, ly);
  if (path == Path::kR2r) {
    R2r(0, lx, ly, in, out);
  } else {
    PairedForward(lx, ly, in, out);
  }
}

void Dct2d::Inverse(int lx, int ly, float* in, float* out, Path path) {
  DISPEX_CHECK(lx >= 0 && lx < kSizes && ly >= 0 && ly < kSizes && in != out);
  DISPEX_CHECK(fftwf_alignment_of(in) == 0 && fftwf_alignment_of(out) == 0);
  if (path == Path::kAuto) path = AutoPath(lx, ly);
  if (path == Path::kR2r) {
    R2r(1, lx, ly, in, out);
  } else {
    PairedInverse(lx, ly, in, out);
  }
}

void Dct2d::R2r(int dir, int lx, int ly, float* in, float* out) {
  fftwf_plan_s*& plan = r2r_[dir][ly][lx];
  if (plan == nullptr) [[unlikely]] {
    const fftwf_r2r_kind kind = dir == 0 ? FFTW_REDFT10 : FFTW_REDFT01;
    std::lock_guard<std::mutex> lock(PlannerMutex());
    // Row-major: the slow dimension (v, ny) first. FFTW_ESTIMATE never touches the arrays.
    plan = fftwf_plan_r2r_2d(1 << ly, 1 << lx, in, out, kind, kind, kPlannerFlags);
    DISPEX_CHECK(plan != nullptr);
  }
  fftwf_execute_r2r(plan, in, out);
}

fftwf_plan_s* Dct2d::RowPlan(int dir, int lx, int ly) {
  fftwf_plan_s*& plan = rows_[dir][ly][lx];
  if (plan == nullptr) [[unlikely]] {
    const int n = 1 << lx;
    std::lock_guard<std::mutex> lock(PlannerMutex());
    plan = fftwf_plan_many_dft(1, &n, 1 << (ly - 1), AsComplex(za_.data()), nullptr, 1, n,
                               AsComplex(zb_.data()), nullptr, 1, n,
                               dir == 0 ? FFTW_FORWARD : FFTW_BACKWARD, kPlannerFlags);
    DISPEX_CHECK(plan != nullptr);
  }
  return plan;
}

fftwf_plan_s* Dct2d::ColumnPlan(int dir, int lx, int ly) {
  fftwf_plan_s*& plan = columns_[dir][ly][lx];
  if (plan == nullptr) [[unlikely]] {
    const int n = 1 << ly;
    const int pairs = 1 << (lx - 1);
    std::lock_guard<std::mutex> lock(PlannerMutex());
    plan = fftwf_plan_many_dft(1, &n, pairs, AsComplex(za_.data()), nullptr, pairs, 1,
                               AsComplex(zb_.data()), nullptr, pairs, 1,
                               dir == 0 ? FFTW_FORWARD : FFTW_BACKWARD, kPlannerFlags);
    DISPEX_CHECK(plan != nullptr);
  }
  return plan;
}

void Dct2d::PairedForward(int lx, int ly, const float* in, float* out) {
  DISPEX_CHECK(lx >= 1 && ly >= 1);
  const int nx = 1 << lx, ny = 1 << ly, half_x = nx / 2;
  float* za = za_.Reserve(static_cast<std::size_t>(nx) * ny);
  float* zb = zb_.Reserve(static_cast<std::size_t>(nx) * ny);
  const float* wu = GetTwiddles().For(lx);
  const float* wv = GetTwiddles().For(ly);

  // Rows: pair p holds rows 2p (real) and 2p+1 (imaginary), each in Makhoul order.
  for (int p = 0; p < ny / 2; ++p) {
    const float* a = in + static_cast<std::size_t>(2 * p) * nx;
    const float* b = a + nx;
    float* z = za + static_cast<std::size_t>(2 * p) * nx;
    for (int n = 0; n < half_x; ++n) {
      z[2 * n] = a[2 * n];
      z[2 * n + 1] = b[2 * n];
      z[2 * (nx - 1 - n)] = a[2 * n + 1];
      z[2 * (nx - 1 - n) + 1] = b[2 * n + 1];
    }
  }
  fftwf_execute_dft(RowPlan(0, lx, ly), AsComplex(za), AsComplex(zb));
  // Row results go to za, row r at position Reordered(r, ny): the columns' Makhoul order.
  for (int p = 0; p < ny / 2; ++p) {
    const float* z = zb + static_cast<std::size_t>(2 * p) * nx;
    float* ra = za + static_cast<std::size_t>(Reordered(2 * p, ny)) * nx;
    float* rb = za + static_cast<std::size_t>(Reordered(2 * p + 1, ny)) * nx;
    for (int k = 0; k < nx; ++k) {
      const int c = (nx - k) & (nx - 1);
      const float sr = z[2 * k] + z[2 * c], si = z[2 * k + 1] - z[2 * c + 1];
      const float dr = z[2 * k] - z[2 * c], di = z[2 * k + 1] + z[2 * c + 1];
      ra[k] = wu[2 * k] * sr - wu[2 * k + 1] * si;
      rb[k] = wu[2 * k] * di + wu[2 * k + 1] * dr;
    }
  }
  // Columns: column pair q is complex element q of every row.
  fftwf_execute_dft(ColumnPlan(0, lx, ly), AsComplex(za), AsComplex(zb));
  for (int k = 0; k < ny; ++k) {
    const float* zk = zb + static_cast<std::size_t>(k) * nx;
    const float* zc = zb + static_cast<std::size_t>((ny - k) & (ny - 1)) * nx;
    const float wr = wv[2 * k], wi = wv[2 * k + 1];
    float* o = out + static_cast<std::size_t>(k) * nx;
    for (int q = 0; q < half_x; ++q) {
      const float sr = zk[2 * q] + zc[2 * q], si = zk[2 * q + 1] - zc[2 * q + 1];
      const float dr = zk[2 * q] - zc[2 * q], di = zk[2 * q + 1] + zc[2 * q + 1];
      o[2 * q] = wr * sr - wi * si;
      o[2 * q + 1] = wr * di + wi * dr;
    }
  }
}

void Dct2d::PairedInverse(int lx, int ly, const float* in, float* out) {
  DISPEX_CHECK(lx >= 1 && ly >= 1);
  const int nx = 1 << lx, ny = 1 << ly, half_x = nx / 2;
  float* za = za_.Reserve(static_cast<std::size_t>(nx) * ny);
  float* zb = zb_.Reserve(static_cast<std::size_t>(nx) * ny);
  const float* wu = GetTwiddles().For(lx);
  const float* wv = GetTwiddles().For(ly);

  // Columns first: pair q = columns 2q, 2q+1; conj(w_k) = (wr, -wi).
  for (int k = 0; k < ny; ++k) {
    const float* yk = in + static_cast<std::size_t>(k) * nx;
    const float* yc = in + static_cast<std::size_t>(ny - k) * nx;  // read only when k > 0
    const float er = wv[2 * k], ei = -wv[2 * k + 1];
    float* z = za + static_cast<std::size_t>(k) * nx;
    for (int q = 0; q < half_x; ++q) {
      const float ac = k > 0 ? yc[2 * q] : 0.0f;
      const float bc = k > 0 ? yc[2 * q + 1] : 0.0f;
      const float re = yk[2 * q] + bc, im = yk[2 * q + 1] - ac;
      z[2 * q] = er * re - ei * im;
      z[2 * q + 1] = er * im + ei * re;
    }
  }
  fftwf_execute_dft(ColumnPlan(1, lx, ly), AsComplex(za), AsComplex(zb));
  // Row r of the column pass's output is row Reordered(r, ny) of zb (real parts in even
  // floats: column 2q; imaginary in odd: column 2q+1). Rows: pair p = rows 2p, 2p+1.
  for (int p = 0; p < ny / 2; ++p) {
    const float* ta = zb + static_cast<std::size_t>(Reordered(2 * p, ny)) * nx;
    const float* tb = zb + static_cast<std::size_t>(Reordered(2 * p + 1, ny)) * nx;
    float* z = za + static_cast<std::size_t>(2 * p) * nx;
    for (int k = 0; k < nx; ++k) {
      const float er = wu[2 * k], ei = -wu[2 * k + 1];
      const float ac = k > 0 ? ta[nx - k] : 0.0f;
      const float bc = k > 0 ? tb[nx - k] : 0.0f;
      const float re = ta[k] + bc, im = tb[k] - ac;
      z[2 * k] = er * re - ei * im;
      z[2 * k + 1] = er * im + ei * re;
    }
  }
  fftwf_execute_dft(RowPlan(1, lx, ly), AsComplex(za), AsComplex(zb));
  for (int p = 0; p < ny / 2; ++p) {
    const float* z = zb + static_cast<std::size_t>(2 * p) * nx;
    float* xa = out + static_cast<std::size_t>(2 * p) * nx;
    float* xb = xa + nx;
    for (int n = 0; n < half_x; ++n) {
      xa[2 * n] = z[2 * n];
      xb[2 * n] = z[2 * n + 1];
      xa[2 * n + 1] = z[2 * (nx - 1 - n)];
      xb[2 * n + 1] = z[2 * (nx - 1 - n) + 1];
    }
  }
}

}  // namespace dispex::spectral
