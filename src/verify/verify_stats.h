// What verify.cpp and edge_steps.cpp share: the statistics of a set of errors and the scratch
// of limit points with their frames.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "dispex/subdiv.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"

namespace dispex::verify {

// Statistics of absolute values; sums in index order, so the result is deterministic.
inline ErrorStats Summarise(std::vector<float>& values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  double sum = 0, sum_sq = 0;
  for (float v : values) {
    sum += v;
    sum_sq += double(v) * v;
  }
  s.mean = sum / double(values.size());
  s.rms = std::sqrt(sum_sq / double(values.size()));
  std::size_t k = static_cast<std::size_t>(std::ceil(0.99 * double(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  s.p99 = values[k];
  s.max = *std::max_element(values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return s;
}

// Limit points with their frames, 3 floats per point in each array.
struct FrameScratch {
  std::vector<float> uv, p, nrm, du, dv;
  void Resize(std::size_t points) {
    for (auto* v : {&p, &nrm, &du, &dv}) v->resize(3 * points);
  }
  LimitEvaluator::Frames Frames() { return {p, nrm, du, dv}; }
  SurfaceFrame At(std::size_t j) const {
    return {{du[3 * j], du[3 * j + 1], du[3 * j + 2]},
            {dv[3 * j], dv[3 * j + 1], dv[3 * j + 2]},
            {nrm[3 * j], nrm[3 * j + 1], nrm[3 * j + 2]}};
  }
};

}  // namespace dispex::verify
