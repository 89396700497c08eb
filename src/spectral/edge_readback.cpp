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

// The displacement on a face's edges and corners, extrapolated from its samples.
class EdgeValues {
 public:
  EdgeValues(const float* samples, const BlockShape& shape)
      : samples_(samples), nx_(shape.nx), ny_(shape.ny) {}
  // Beyond sample column i at the bottom (v = 0) / top edge, beyond row j at the left / right.
  double Bottom(int i) const { return Across(i, 0, 0, 1); }
  double Top(int i) const { return Across(i, ny_ - 1, 0, -1); }
  double Left(int j) const { return Across(0, j, 1, 0); }
  double Right(int j) const { return Across(nx_ - 1, j, -1, 0); }
  // At corner (ci, cj), 1 being the far side: extrapolated along u, then along v.
  double Corner(int ci, int cj) const {
    const int i0 = ci ? nx_ - 1 : 0, di = ci ? -1 : 1;
    const int j0 = cj ? ny_ - 1 : 0, dj = cj ? -1 : 1;
    return Extrapolate(Across(i0, j0, di, 0), ny_ > 1 ? Across(i0, j0 + dj, di, 0) : 0, ny_ > 1);
  }

 private:
  double At(int i, int j) const { return samples_[std::ptrdiff_t(j) * nx_ + i]; }
  // Beyond sample (i, j), the next one inward being (i + di, j + dj) when the block has it.
  double Across(int i, int j, int di, int dj) const {
    const bool have = di ? nx_ > 1 : ny_ > 1;
    return Extrapolate(At(i, j), have ? At(i + di, j + dj) : 0, have);
  }
  const float* samples_;
  int nx_, ny_;
};

template <class Visit>
void VisitEdgeReads(const float* texels, const BlockShape& res, const float* samples,
                    const BlockShape& shape, Visit&& visit) {
  const int nx = shape.nx, ny = shape.ny, rx = res.nx, ry = res.ny;
  const EdgeValues edge(samples, shape);
  std::size_t k = 0;
  for (int i = 0; i < nx; ++i) {  // bottom (v = 0) and top (v = 1) edges
    const double x = (i + 0.5) / nx;
    visit(k++, ReadAlong(texels, 1, rx, x) - edge.Bottom(i));
    visit(k++, ReadAlong(texels + std::ptrdiff_t(ry - 1) * rx, 1, rx, x) - edge.Top(i));
  }
  for (int j = 0; j < ny; ++j) {  // left (u = 0) and right (u = 1) edges
    const double y = (j + 0.5) / ny;
    visit(k++, ReadAlong(texels, rx, ry, y) - edge.Left(j));
    visit(k++, ReadAlong(texels + (rx - 1), rx, ry, y) - edge.Right(j));
  }
  // The corners: the corner texel, against the samples extrapolated both ways.
  for (int cj : {0, 1}) {
    for (int ci : {0, 1}) {
      const double texel = texels[std::ptrdiff_t(cj ? ry - 1 : 0) * rx + (ci ? rx - 1 : 0)];
      visit(k++, texel - edge.Corner(ci, cj));
    }
  }
}

}  // namespace

std::size_t EdgeReadCount(const BlockShape& shape) {
  return 2 * static_cast<std::size_t>(shape.nx) + 2 * static_cast<std::size_t>(shape.ny) + 4;
}

double MaxEdgeReadError(const float* texels, const BlockShape& res, const float* samples,
                        const BlockShape& shape) {
  double worst = 0;
  VisitEdgeReads(texels, res, samples, shape,
                 [&](std::size_t, double error) { worst = std::max(worst, std::fabs(error)); });
  return worst;
}

void AddSquaredEdgeReadErrors(const float* texels, const BlockShape& res, const float* samples,
                              const BlockShape& shape, double* squares) {
  VisitEdgeReads(texels, res, samples, shape,
                 [&](std::size_t k, double error) { squares[k] += error * error; });
}

void PinEdgeTexels(float* texels, const BlockShape& res, const float* samples,
                   const BlockShape& shape) {
  const int nx = shape.nx, ny = shape.ny, rx = res.nx, ry = res.ny;
  const EdgeValues edge(samples, shape);
  auto texel = [&](int i, int j) -> float& { return texels[std::ptrdiff_t(j) * rx + i]; };
  const bool rows = ry >= 2 && ry < ny, columns = rx >= 2 && rx < nx;
  if (rows) {
    const int span = nx / rx;
    for (int i = 0; i < rx; ++i) {
      double b = 0, t = 0;
      for (int k = i * span; k < (i + 1) * span; ++k) b += edge.Bottom(k), t += edge.Top(k);
      texel(i, 0) = static_cast<float>(b / span);
      texel(i, ry - 1) = static_cast<float>(t / span);
    }
  }
  if (columns) {
    const int span = ny / ry;
    for (int j = 0; j < ry; ++j) {
      double l = 0, r = 0;
      for (int k = j * span; k < (j + 1) * span; ++k) l += edge.Left(k), r += edge.Right(k);
      texel(0, j) = static_cast<float>(l / span);
      texel(rx - 1, j) = static_cast<float>(r / span);
    }
  }
  if (rows && columns) {
    for (int cj : {0, 1}) {
      for (int ci : {0, 1}) texel(ci ? rx - 1 : 0, cj ? ry - 1 : 0) = float(edge.Corner(ci, cj));
    }
  }
}

}  // namespace dispex::spectral
