#include "spectral/edge_readback.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace dispex::spectral {
namespace {

// Linear interpolation of `count` values spaced `stride` apart (texel centres (k + 0.5) /
// count) at position x in [0, 1], clamped beyond the outermost centres.
double ReadAlong(const float* values, std::ptrdiff_t stride, int count, double x) {
  const double t = x * count - 0.5;
  if (t <= 0) return values[0];
  if (t >= count - 1) return values[std::ptrdiff_t(count - 1) * stride];
  const double base = std::floor(t);
  const auto k = static_cast<std::ptrdiff_t>(base);
  const double w = t - base;
  return (1 - w) * values[k * stride] + w * values[(k + 1) * stride];
}

// The value on the edge beyond sample s0, with s1 the next sample inward (one spacing away):
// the edge lies half a spacing beyond s0.
double Extrapolate(double s0, double s1, bool have_s1) {
  return have_s1 ? 1.5 * s0 - 0.5 * s1 : s0;
}

}  // namespace

double MaxEdgeReadError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& shape) {
  const int nx = shape.nx, ny = shape.ny, rx = res.nx, ry = res.ny;
  const std::ptrdiff_t row = nx;
  double worst = 0;
  for (int i = 0; i < nx; ++i) {  // bottom (v = 0) and top (v = 1) edges
    const double x = (i + 0.5) / nx;
    const double bottom = ReadAlong(texels, 1, rx, x);
    const double top = ReadAlong(texels + std::ptrdiff_t(ry - 1) * rx, 1, rx, x);
    const double at_bottom = Extrapolate(samples[i], ny > 1 ? samples[row + i] : 0, ny > 1);
    const double at_top =
        Extrapolate(samples[std::ptrdiff_t(ny - 1) * row + i],
                    ny > 1 ? samples[std::ptrdiff_t(ny - 2) * row + i] : 0, ny > 1);
    worst = std::max({worst, std::fabs(bottom - at_bottom), std::fabs(top - at_top)});
  }
  for (int j = 0; j < ny; ++j) {  // left (u = 0) and right (u = 1) edges
    const double y = (j + 0.5) / ny;
    const double left = ReadAlong(texels, rx, ry, y);
    const double right = ReadAlong(texels + (rx - 1), rx, ry, y);
    const float* s = samples + std::ptrdiff_t(j) * row;
    const double at_left = Extrapolate(s[0], nx > 1 ? s[1] : 0, nx > 1);
    const double at_right = Extrapolate(s[nx - 1], nx > 1 ? s[nx - 2] : 0, nx > 1);
    worst = std::max({worst, std::fabs(left - at_left), std::fabs(right - at_right)});
  }
  // The corners: the corner texel, against the samples extrapolated both ways.
  for (int cj : {0, 1}) {
    for (int ci : {0, 1}) {
      const int i0 = ci ? nx - 1 : 0, i1 = ci ? nx - 2 : 1;
      const int j0 = cj ? ny - 1 : 0, j1 = cj ? ny - 2 : 1;
      auto at = [&](int i, int j) { return double(samples[std::ptrdiff_t(j) * row + i]); };
      auto edge_value = [&](int j) {
        return Extrapolate(at(i0, j), nx > 1 ? at(i1, j) : 0, nx > 1);
      };
      const double corner = Extrapolate(edge_value(j0), ny > 1 ? edge_value(j1) : 0, ny > 1);
      const double texel = texels[std::ptrdiff_t(cj ? ry - 1 : 0) * rx + (ci ? rx - 1 : 0)];
      worst = std::max(worst, std::fabs(texel - corner));
    }
  }
  return worst;
}

void PinEdgeTexels(float* texels, const BlockShape& res, const float* samples,
                   const BlockShape& shape) {
  const int nx = shape.nx, ny = shape.ny, rx = res.nx, ry = res.ny;
  const std::ptrdiff_t row = nx;
  auto at = [&](int i, int j) { return double(samples[std::ptrdiff_t(j) * row + i]); };
  // The edge value beyond sample (i, j) at the bottom / top / left / right.
  auto bottom = [&](int i) { return Extrapolate(at(i, 0), ny > 1 ? at(i, 1) : 0, ny > 1); };
  auto top = [&](int i) { return Extrapolate(at(i, ny - 1), ny > 1 ? at(i, ny - 2) : 0, ny > 1); };
  auto left = [&](int j) { return Extrapolate(at(0, j), nx > 1 ? at(1, j) : 0, nx > 1); };
  auto right = [&](int j) {
    return Extrapolate(at(nx - 1, j), nx > 1 ? at(nx - 2, j) : 0, nx > 1);
  };
  auto texel = [&](int i, int j) -> float& { return texels[std::ptrdiff_t(j) * rx + i]; };
  const bool rows = ry >= 2 && ry < ny, columns = rx >= 2 && rx < nx;
  if (rows) {
    const int span = nx / rx;
    for (int i = 0; i < rx; ++i) {
      double b = 0, t = 0;
      for (int k = i * span; k < (i + 1) * span; ++k) b += bottom(k), t += top(k);
      texel(i, 0) = static_cast<float>(b / span);
      texel(i, ry - 1) = static_cast<float>(t / span);
    }
  }
  if (columns) {
    const int span = ny / ry;
    for (int j = 0; j < ry; ++j) {
      double l = 0, r = 0;
      for (int k = j * span; k < (j + 1) * span; ++k) l += left(k), r += right(k);
      texel(0, j) = static_cast<float>(l / span);
      texel(rx - 1, j) = static_cast<float>(r / span);
    }
  }
  if (rows && columns) {
    for (int cj : {0, 1}) {
      for (int ci : {0, 1}) {
        const int i0 = ci ? nx - 1 : 0, i1 = ci ? nx - 2 : 1;
        const int j0 = cj ? ny - 1 : 0, j1 = cj ? ny - 2 : 1;
        auto edge_value = [&](int j) { return Extrapolate(at(i0, j), at(i1, j), true); };
        texel(ci ? rx - 1 : 0, cj ? ry - 1 : 0) =
            static_cast<float>(Extrapolate(edge_value(j0), edge_value(j1), true));
      }
    }
  }
}

}  // namespace dispex::spectral
