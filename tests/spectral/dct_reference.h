// Test-only references for the spectral module, written from the definitions with no shared
// code: the orthonormal 2-D DCT-II as a direct O(N^4) sum and as a separable O(N^3) product,
// its inverse, the truncation bound as a direct sum, and Ptex's clamped bilinear lookup at one
// point. All in double.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace dispex::spectral_test {

// a_N(k): sqrt(1/N) for k = 0, sqrt(2/N) otherwise.
double Alpha(int k, int n);

// F(u,v) = a(u) a(v) sum_ij x(i,j) cos(pi(2i+1)u/2nx) cos(pi(2j+1)v/2ny), the direct O(N^4) sum.
std::vector<double> NaiveDct(const std::vector<double>& x, int nx, int ny);
// x(i,j) = sum_uv a(u) a(v) F(u,v) cos(...) cos(...), the direct O(N^4) sum.
std::vector<double> NaiveInverseDct(const std::vector<double>& f, int nx, int ny);
// The same DCT-II as NaiveDct, one direction at a time (O(N^3)).
std::vector<double> SeparableDct(const std::vector<double>& x, int nx, int ny);

// The continuous series of F at texture coordinates (s, t) in [0,1]^2: sample (i, j) sits at
// ((i+0.5)/nx, (j+0.5)/ny). Only coefficients with u < keep_u, v < keep_v are summed.
double EvaluateSeries(const std::vector<double>& f, int nx, int ny, int keep_u, int keep_v,
                      double s, double t);

// sum over u >= rx or v >= ry of a(u) a(v) |F(u,v)|.
double DirectBound(const std::vector<double>& f, int nx, int ny, int rx, int ry);

// Ptex's bilinear lookup in one face of rx x ry texels at (s, t): texel centres at
// ((k+0.5)/r), coordinates clamped to the outermost centres.
double PtexBilinear(const float* texels, int rx, int ry, double s, double t);

// max |PtexBilinear(texels) - sample| over the nx x ny sample positions.
double ReferenceReadBackError(const std::vector<float>& texels, int rx, int ry,
                              const std::vector<float>& samples, int nx, int ny);

std::vector<double> ToDouble(const std::vector<float>& x);
std::vector<float> ToFloat(const std::vector<double>& x);
std::vector<float> UniformNoise(int count, float amplitude, std::uint32_t seed);

}  // namespace dispex::spectral_test
