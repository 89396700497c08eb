#include "dct_reference.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dispex::spectral_test {

double Alpha(int k, int n) {
  return std::sqrt((k == 0 ? 1.0 : 2.0) / n);
}

namespace {

double Basis(int k, int x, int n) {
  return std::cos(std::numbers::pi * (2 * x + 1) * k / (2.0 * n));
}

}  // namespace

std::vector<double> NaiveDct(const std::vector<double>& x, int nx, int ny) {
  std::vector<double> f(x.size());
  for (int v = 0; v < ny; ++v) {
    for (int u = 0; u < nx; ++u) {
      double sum = 0;
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) sum += x[j * nx + i] * Basis(u, i, nx) * Basis(v, j, ny);
      }
      f[v * nx + u] = Alpha(u, nx) * Alpha(v, ny) * sum;
    }
  }
  return f;
}

std::vector<double> NaiveInverseDct(const std::vector<double>& f, int nx, int ny) {
  std::vector<double> x(f.size());
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      double sum = 0;
      for (int v = 0; v < ny; ++v) {
        for (int u = 0; u < nx; ++u) {
          sum += Alpha(u, nx) * Alpha(v, ny) * f[v * nx + u] * Basis(u, i, nx) * Basis(v, j, ny);
        }
      }
      x[j * nx + i] = sum;
    }
  }
  return x;
}

std::vector<double> SeparableDct(const std::vector<double>& x, int nx, int ny) {
  std::vector<double> cx(static_cast<std::size_t>(nx) * nx), cy(static_cast<std::size_t>(ny) * ny);
  for (int k = 0; k < nx; ++k) {
    for (int i = 0; i < nx; ++i) cx[k * nx + i] = Alpha(k, nx) * Basis(k, i, nx);
  }
  for (int k = 0; k < ny; ++k) {
    for (int j = 0; j < ny; ++j) cy[k * ny + j] = Alpha(k, ny) * Basis(k, j, ny);
  }
  std::vector<double> rows(x.size()), f(x.size());
  for (int j = 0; j < ny; ++j) {
    for (int u = 0; u < nx; ++u) {
      double sum = 0;
      for (int i = 0; i < nx; ++i) sum += cx[u * nx + i] * x[j * nx + i];
      rows[j * nx + u] = sum;
    }
  }
  for (int v = 0; v < ny; ++v) {
    for (int u = 0; u < nx; ++u) f[v * nx + u] = 0;
    for (int j = 0; j < ny; ++j) {
      const double c = cy[v * ny + j];
      for (int u = 0; u < nx; ++u) f[v * nx + u] += c * rows[j * nx + u];
    }
  }
  return f;
}

double EvaluateSeries(const std::vector<double>& f, int nx, int ny, int keep_u, int keep_v,
                      double s, double t) {
  // Sample index i sits at s = (i+0.5)/nx, so the basis argument pi(2i+1)u/2nx is pi s u.
  double sum = 0;
  for (int v = 0; v < std::min(keep_v, ny); ++v) {
    for (int u = 0; u < std::min(keep_u, nx); ++u) {
      sum += Alpha(u, nx) * Alpha(v, ny) * f[v * nx + u] * std::cos(std::numbers::pi * s * u) *
             std::cos(std::numbers::pi * t * v);
    }
  }
  return sum;
}

double DirectBound(const std::vector<double>& f, int nx, int ny, int rx, int ry) {
  double sum = 0;
  for (int v = 0; v < ny; ++v) {
    for (int u = 0; u < nx; ++u) {
      if (u >= rx || v >= ry) sum += Alpha(u, nx) * Alpha(v, ny) * std::fabs(f[v * nx + u]);
    }
  }
  return sum;
}

double PtexBilinear(const float* texels, int rx, int ry, double s, double t) {
  const double x = std::clamp(s * rx - 0.5, 0.0, rx - 1.0);
  const double y = std::clamp(t * ry - 0.5, 0.0, ry - 1.0);
  const int x0 = static_cast<int>(x);
  const int y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, rx - 1);
  const int y1 = std::min(y0 + 1, ry - 1);
  const double fx = x - x0;
  const double fy = y - y0;
  auto at = [&](int i, int j) { return static_cast<double>(texels[j * rx + i]); };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
         fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
}

double ReferenceReadBackError(const std::vector<float>& texels, int rx, int ry,
                              const std::vector<float>& samples, int nx, int ny) {
  double worst = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double value = PtexBilinear(texels.data(), rx, ry, (i + 0.5) / nx, (j + 0.5) / ny);
      worst = std::max(worst, std::fabs(value - samples[j * nx + i]));
    }
  }
  return worst;
}

std::vector<double> ToDouble(const std::vector<float>& x) {
  return {x.begin(), x.end()};
}

std::vector<float> ToFloat(const std::vector<double>& x) {
  std::vector<float> out(x.size());
  std::transform(x.begin(), x.end(), out.begin(), [](double v) { return static_cast<float>(v); });
  return out;
}

std::vector<float> UniformNoise(int count, float amplitude, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(-amplitude, amplitude);
  std::vector<float> out(count);
  for (float& v : out) v = dist(rng);
  return out;
}

}  // namespace dispex::spectral_test
