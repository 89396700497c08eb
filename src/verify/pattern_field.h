// h and D over the base's limit surface for one MakeSculpt run, in one place for every pattern:
// the closed-form patterns of the position (EvaluatePattern, EvaluatePatternVector) and the
// image pattern of the point's place on the base (Ptex face, u, v) through the cage's UVs
// (dispex/uv_charts.h, height_image.h).
// make_sculpt.cpp evaluates it at the sculpt's vertices and at its faces' centres.
#pragma once

#include <cmath>
#include <optional>

#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/uv_charts.h"
#include "dispex/verify.h"
#include "verify/height_image.h"

namespace dispex::verify {

class PatternField {
 public:
  // For Pattern::kImage, reads the image and the cage's UVs (errors name the file); the
  // cage must be the surface's.
  static StatusOr<PatternField> Create(Pattern pattern, const std::string& image_path,
                                       const PatternFrame& frame, const Mesh& cage,
                                       const LimitSurface& surface);

  // h at the limit point `position` of Ptex face `face` at (u, v) (D.N for the vector
  // patterns). Safe from any number of threads; no allocation.
  double operator()(PtexFaceId face, float u, float v, const float position[3]) const {
    if (pattern_ != Pattern::kImage) return EvaluatePattern(pattern_, frame_, position);
    double uv[2];
    charts_->Evaluate(face, u, v, uv);
    return frame_.amplitude * (2 * image_->Sample(uv[0], uv[1]) - 1);
  }

  // D there, the limit normal there being `normal`: h N for the scalar patterns (h exactly as
  // operator() gives it), the vector patterns' own D.
  void Displacement(PtexFaceId face, float u, float v, const float position[3],
                    const float normal[3], double d[3]) const {
    if (IsVectorPattern(pattern_))
      return EvaluatePatternVector(pattern_, frame_, position, normal, d);
    const double h = (*this)(face, u, v, position);
    for (int i = 0; i < 3; ++i) d[i] = h * normal[i];
  }

  // D there as Displacement gives it, and h = D.N: for the scalar patterns the pattern's h
  // itself (D = h N). `*tangential`: |D - h N|.
  double HeightAndDisplacement(PtexFaceId face, float u, float v, const float position[3],
                               const float normal[3], double d[3], double* tangential) const {
    double h;
    if (vector()) {
      EvaluatePatternVector(pattern_, frame_, position, normal, d);
      h = d[0] * normal[0] + d[1] * normal[1] + d[2] * normal[2];
    } else {
      h = (*this)(face, u, v, position);
      for (int i = 0; i < 3; ++i) d[i] = h * normal[i];
    }
    double t2 = 0;
    for (int i = 0; i < 3; ++i) t2 += (d[i] - h * normal[i]) * (d[i] - h * normal[i]);
    *tangential = std::sqrt(t2);
    return h;
  }

  bool vector() const { return IsVectorPattern(pattern_); }

 private:
  Pattern pattern_ = Pattern::kNone;
  PatternFrame frame_;
  std::optional<PtexUvCharts> charts_;
  std::optional<HeightImage> image_;
};

}  // namespace dispex::verify
