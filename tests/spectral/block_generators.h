// Test blocks with known content: sums of DCT basis functions (known spectrum) and the
// smooth, sharp and noisy shapes a sculpt produces (seeded, deterministic).
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace dispex::spectral_test {

struct CosineTerm {
  int u = 0;
  int v = 0;
  double amplitude = 0;  // the term's peak value in object units
};

// sample(i,j) = sum amplitude cos(pi(2i+1)u/2nx) cos(pi(2j+1)v/2ny): its orthonormal DCT has
// F(u,v) = amplitude / (a(u) a(v)) and nothing else.
std::vector<float> CosineBlock(int nx, int ny, const std::vector<CosineTerm>& terms);

// The same sum at texture coordinates (s, t) (sample (i,j) is at ((i+0.5)/nx, (j+0.5)/ny)).
double CosineValue(const std::vector<CosineTerm>& terms, double s, double t);

// A random block of one of the kinds below, values of order `amplitude`.
enum class BlockKind { kSmooth, kStep, kRidge, kSpike, kGaussians, kNoise, kSmoothPlusDetail };
inline constexpr int kBlockKinds = 7;
std::string BlockKindName(BlockKind kind);
std::vector<float> RandomBlock(BlockKind kind, int nx, int ny, double amplitude, std::mt19937& rng);

}  // namespace dispex::spectral_test
