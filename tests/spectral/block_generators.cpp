#include "block_generators.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dispex::spectral_test {

std::vector<float> CosineBlock(int nx, int ny, const std::vector<CosineTerm>& terms) {
  std::vector<float> out(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      out[j * nx + i] = static_cast<float>(CosineValue(terms, (i + 0.5) / nx, (j + 0.5) / ny));
    }
  }
  return out;
}

double CosineValue(const std::vector<CosineTerm>& terms, double s, double t) {
  double sum = 0;
  for (const CosineTerm& c : terms) {
    sum +=
        c.amplitude * std::cos(std::numbers::pi * s * c.u) * std::cos(std::numbers::pi * t * c.v);
  }
  return sum;
}

std::string BlockKindName(BlockKind kind) {
  switch (kind) {
    case BlockKind::kSmooth:
      return "smooth";
    case BlockKind::kStep:
      return "step";
    case BlockKind::kRidge:
      return "ridge";
    case BlockKind::kSpike:
      return "spike";
    case BlockKind::kGaussians:
      return "gaussians";
    case BlockKind::kNoise:
      return "noise";
    case BlockKind::kSmoothPlusDetail:
      return "smooth+detail";
  }
  return "?";
}

namespace {

double Uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// A smooth field: a few low-frequency waves with random phases and directions.
double SmoothAt(double s, double t, const std::vector<double>& p) {
  double sum = 0;
  for (std::size_t k = 0; k + 4 < p.size(); k += 5) {
    sum += p[k] * std::sin(2 * std::numbers::pi * (p[k + 1] * s + p[k + 2] * t) + p[k + 3]) +
           p[k + 4] * s * t;
  }
  return sum;
}

}  // namespace

std::vector<float> RandomBlock(BlockKind kind, int nx, int ny, double amplitude,
                               std::mt19937& rng) {
  std::vector<float> out(static_cast<std::size_t>(nx) * ny);
  std::vector<double> smooth;
  for (int k = 0; k < 3; ++k) {
    smooth.insert(smooth.end(),
                  {Uniform(rng, -1, 1), Uniform(rng, -1.5, 1.5), Uniform(rng, -1.5, 1.5),
                   Uniform(rng, 0, 6.3), Uniform(rng, -0.5, 0.5)});
  }
  // A random line through the face: n . (s, t) = c.
  const double angle = Uniform(rng, 0, 2 * std::numbers::pi);
  const double lnx = std::cos(angle), lny = std::sin(angle);
  const double c = lnx * Uniform(rng, 0.1, 0.9) + lny * Uniform(rng, 0.1, 0.9);
  const double width = Uniform(rng, 0.01, 0.2);
  const int spike_i = std::uniform_int_distribution<int>(0, nx - 1)(rng);
  const int spike_j = std::uniform_int_distribution<int>(0, ny - 1)(rng);
  struct Bump {
    double s, t, sigma, height;
  };
  std::vector<Bump> bumps(std::uniform_int_distribution<int>(1, 4)(rng));
  for (Bump& b : bumps) {
    b = {Uniform(rng, 0, 1), Uniform(rng, 0, 1), Uniform(rng, 0.02, 0.3), Uniform(rng, -1, 1)};
  }
  const double offset = Uniform(rng, -2, 2);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double s = (i + 0.5) / nx, t = (j + 0.5) / ny;
      const double d = lnx * s + lny * t - c;
      double value = 0;
      switch (kind) {
        case BlockKind::kSmooth:
          value = SmoothAt(s, t, smooth);
          break;
        case BlockKind::kStep:
          value = d > 0 ? 1.0 : -0.5;
          break;
        case BlockKind::kRidge:
          value = std::max(0.0, 1.0 - std::fabs(d) / width);
          break;
        case BlockKind::kSpike:
          value = (i == spike_i && j == spike_j) ? 1.0 : 0.0;
          break;
        case BlockKind::kGaussians:
        case BlockKind::kSmoothPlusDetail:
          for (const Bump& b : bumps) {
            const double r2 = (s - b.s) * (s - b.s) + (t - b.t) * (t - b.t);
            value += b.height * std::exp(-r2 / (2 * b.sigma * b.sigma));
          }
          if (kind == BlockKind::kSmoothPlusDetail) value = SmoothAt(s, t, smooth) + 0.2 * value;
          break;
        case BlockKind::kNoise:
          value = noise(rng);
          break;
      }
      out[j * nx + i] = static_cast<float>(amplitude * (offset + value));
    }
  }
  return out;
}

}  // namespace dispex::spectral_test
