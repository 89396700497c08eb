// Displacement patterns with known values, for ground-truth sculpts. Each but the image is a
// closed-form function of the position (the vector patterns also of the limit normal), so the
// exact displacement at any point is known; the image pattern (pattern_field.cpp) is a
// closed-form function of the point's place on the base.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "core/enum_names.h"
#include "dispex/verify.h"

namespace dispex {

namespace {

// "image" alone is refused (ParsePattern): the pattern needs a file, image:FILE.png
// (ParsePatternArgument).
constexpr auto kPatternNames = EnumTable<Pattern>({
    {Pattern::kSmooth, "smooth"},
    {Pattern::kDetail, "detail"},
    {Pattern::kRidges, "ridges"},
    {Pattern::kNoise, "noise"},
    {Pattern::kNone, "none"},
    {Pattern::kSideways, "sideways"},
    {Pattern::kOverhang, "overhang"},
    {Pattern::kImage, "image"},
});

constexpr double kTwoPi = 6.283185307179586;

struct Wave {
  double dir[3];
  double wavelength;
  double phase;
  double weight;
};

double Dot(const double d[3], const double p[3]) {
  return d[0] * p[0] + d[1] * p[1] + d[2] * p[2];
}

double Smooth(const double p[3], double diagonal) {
  static const double d1[3] = {0.6, 0.64, 0.48}, d2[3] = {-0.48, 0.6, 0.64},
                      d3[3] = {0.64, -0.48, 0.6};
  return 0.5 * std::sin(kTwoPi * Dot(d1, p) / (0.6 * diagonal) + 0.3) +
         0.3 * std::sin(kTwoPi * Dot(d2, p) / (0.35 * diagonal) + 1.1) +
         0.2 * std::sin(kTwoPi * Dot(d3, p) / (0.25 * diagonal) + 2.0);
}

double SmoothStep(double edge0, double edge1, double x) {
  double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

const std::array<Wave, 24>& NoiseWaves(std::uint32_t seed, double edge) {
  thread_local std::uint32_t cached_seed = 0;
  thread_local double cached_edge = -1;
  thread_local std::array<Wave, 24> waves;
  if (cached_seed != seed || cached_edge != edge) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (Wave& w : waves) {
      double z = 2 * unit(rng) - 1, a = kTwoPi * unit(rng), r = std::sqrt(1 - z * z);
      w.dir[0] = r * std::cos(a);
      w.dir[1] = r * std::sin(a);
      w.dir[2] = z;
      w.wavelength = edge * (6 + 18 * unit(rng));
      w.phase = kTwoPi * unit(rng);
      w.weight = 1.0 / std::sqrt(double(waves.size()));
    }
    cached_seed = seed;
    cached_edge = edge;
  }
  return waves;
}

// The vector patterns (include/dispex/verify.h).
constexpr double kSidewaysAxis1[3] = {0.6, 0.64, 0.48};
constexpr double kSidewaysAxis2[3] = {-0.48, 0.6, 0.64};
constexpr double kSidewaysWave2[3] = {0.64, -0.48, 0.6};
constexpr double kOverhangAxis[3] = {0.8, 0.48, 0.36};

// t(a) = a - (a.n) n.
void TangentialAxis(const double a[3], const double n[3], double t[3]) {
  const double an = Dot(a, n);
  for (int i = 0; i < 3; ++i) t[i] = a[i] - an * n[i];
}

struct OverhangWave {
  double k, theta;
};
OverhangWave Overhang(const double p[3], const PatternFrame& f) {
  const double wavelength = std::max(4 * f.amplitude, 16 * f.edge);
  const double k = kTwoPi / wavelength;
  return {k, k * Dot(kOverhangAxis, p) + 0.7};
}

}  // namespace

std::string_view PatternName(Pattern pattern) {
  return EnumName(kPatternNames, pattern);
}

StatusOr<Pattern> ParsePattern(std::string_view name) {
  DISPEX_ASSIGN_OR_RETURN(const Pattern pattern, ParseEnum(kPatternNames, "pattern", name));
  if (pattern == Pattern::kImage) {
    return Status::Error("pattern 'image' needs a height image: image:FILE.png");
  }
  return pattern;
}

bool IsVectorPattern(Pattern pattern) {
  return pattern == Pattern::kSideways || pattern == Pattern::kOverhang;
}

StatusOr<PatternArgument> ParsePatternArgument(std::string_view text) {
  constexpr std::string_view kImagePrefix = "image:";
  PatternArgument argument;
  if (text.substr(0, kImagePrefix.size()) == kImagePrefix) {
    argument.pattern = Pattern::kImage;
    argument.image_path = std::string(text.substr(kImagePrefix.size()));
    if (argument.image_path.empty()) {
      return Status::Error("pattern 'image:' names no file (expected image:FILE.png)");
    }
    return argument;
  }
  DISPEX_ASSIGN_OR_RETURN(argument.pattern, ParsePattern(text));
  return argument;
}

double EvaluatePattern(Pattern pattern, const PatternFrame& f, const float point[3]) {
  const double p[3] = {double(point[0]) - f.center[0], double(point[1]) - f.center[1],
                       double(point[2]) - f.center[2]};
  const double D = f.diagonal, A = f.amplitude;
  switch (pattern) {
    case Pattern::kSmooth:
      return A * Smooth(p, D);
    case Pattern::kDetail: {
      // Two balls of fine bumps, fading out smoothly over their outer third.
      static const double axis[3] = {0.8, 0.36, 0.48};
      double weight = 0;
      for (double side : {-1.0, 1.0}) {
        double q[3] = {p[0] - side * 0.2 * D * axis[0], p[1] - side * 0.2 * D * axis[1],
                       p[2] - side * 0.2 * D * axis[2]};
        double r = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        weight += 1 - SmoothStep(0.15 * D, 0.22 * D, r);
      }
      double k = kTwoPi / (8 * f.edge);
      double bumps = std::sin(k * p[0]) * std::sin(k * p[1]) * std::sin(k * p[2]);
      // A few sharp ridges: tents of half-width 0.01 D on parallel planes 0.25 D apart, with
      // kinks (C0) at the crest and at both feet.
      static const double normal[3] = {0.36, 0.48, 0.8};
      double s = Dot(normal, p) / (0.25 * D);
      double from_plane = std::abs(s - std::round(s)) * 0.25 * D;
      double ridge = std::max(0.0, 1 - from_plane / (0.01 * D));
      return A * (Smooth(p, D) + 0.5 * std::min(weight, 1.0) * bumps + 0.3 * ridge);
    }
    case Pattern::kRidges: {
      static const double d[3] = {0.36, 0.48, 0.8};
      double s = Dot(d, p) / (0.12 * D);
      double tri = 2 * std::abs(s - std::floor(s) - 0.5);  // 0..1, kinks at integers and halves
      return A * (0.5 * Smooth(p, D) + (tri - 0.5));
    }
    case Pattern::kNoise: {
      double h = 0;
      for (const Wave& w : NoiseWaves(f.seed, f.edge)) {
        h += w.weight * std::sin(kTwoPi * Dot(w.dir, p) / w.wavelength + w.phase);
      }
      return A * h;
    }
    case Pattern::kNone:
    case Pattern::kSideways:
      return 0;
    case Pattern::kOverhang:
      return A * std::sin(Overhang(p, f).theta);
    case Pattern::kImage:
      return std::numeric_limits<double>::quiet_NaN();
  }
  return 0;
}

void EvaluatePatternVector(Pattern pattern, const PatternFrame& f, const float point[3],
                           const float normal[3], double d[3]) {
  const double n[3] = {normal[0], normal[1], normal[2]};
  if (!IsVectorPattern(pattern)) {
    const double h = EvaluatePattern(pattern, f, point);
    for (int i = 0; i < 3; ++i) d[i] = h * n[i];
    return;
  }
  const double p[3] = {double(point[0]) - f.center[0], double(point[1]) - f.center[1],
                       double(point[2]) - f.center[2]};
  const double D = f.diagonal, A = f.amplitude;
  double t1[3], t2[3];
  if (pattern == Pattern::kSideways) {
    TangentialAxis(kSidewaysAxis1, n, t1);
    TangentialAxis(kSidewaysAxis2, n, t2);
    const double s1 = 0.6 * A * std::sin(kTwoPi * Dot(kSidewaysAxis1, p) / (0.3 * D) + 0.5);
    const double s2 = 0.4 * A * std::sin(kTwoPi * Dot(kSidewaysWave2, p) / (0.15 * D) + 1.7);
    for (int i = 0; i < 3; ++i) d[i] = s1 * t1[i] + s2 * t2[i];
    return;
  }
  const OverhangWave w = Overhang(p, f);
  TangentialAxis(kOverhangAxis, n, t1);
  // D = A sin(theta) N + (2 / k) sin(theta) t(a): finite (0) at A = 0 too.
  const double s = std::sin(w.theta);
  for (int i = 0; i < 3; ++i) d[i] = A * s * n[i] + (2 / w.k) * s * t1[i];
}

}  // namespace dispex
