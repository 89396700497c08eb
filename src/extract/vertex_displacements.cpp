#include "extract/vertex_displacements.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace dispex::extract {

Status GridDisplacements::Evaluate(PtexFaceId face, int m, std::span<const VertexId> vertices,
                                   const Mesh& sculpt, LimitEvaluator& evaluator, bool normals) {
  if (face.value == face_ && m == m_ && (normals_ || !normals)) return Status::Ok();
  face_ = -1;
  DISPEX_CHECK_GT(m, 0);
  const auto side = static_cast<std::size_t>(m) + 1;
  const std::size_t count = side * side;
  DISPEX_CHECK_EQ(vertices.size(), count);
  uv_.resize(2 * count);
  for (std::size_t b = 0; b < side; ++b) {
    for (std::size_t a = 0; a < side; ++a) {
      uv_[2 * (b * side + a)] = static_cast<float>(a) / static_cast<float>(m);  // exact: m = 2^k
      uv_[2 * (b * side + a) + 1] = static_cast<float>(b) / static_cast<float>(m);
    }
  }
  positions_.resize(3 * count);
  limit_normals_.resize(normals ? 3 * count : 0);
  DISPEX_RETURN_IF_ERROR(evaluator.EvaluatePoints(face, uv_, positions_, limit_normals_));
  d_.resize(3 * count);
  h_.resize(normals ? count : 0);
  for (std::size_t k = 0; k < count; ++k) {
    const Float3& s = sculpt.positions[static_cast<std::size_t>(vertices[k].value)];
    const double d[3] = {double(s.x) - positions_[3 * k], double(s.y) - positions_[3 * k + 1],
                         double(s.z) - positions_[3 * k + 2]};
    std::copy(d, d + 3, &d_[3 * k]);
    if (normals) {
      h_[k] = d[0] * limit_normals_[3 * k] + d[1] * limit_normals_[3 * k + 1] +
              d[2] * limit_normals_[3 * k + 2];
    }
  }
  face_ = face.value;
  m_ = m;
  normals_ = normals;
  return Status::Ok();
}

GridDisplacements::Cell GridDisplacements::CellAt(double u, double v) const {
  const double x = std::clamp(u, 0.0, 1.0) * m_, y = std::clamp(v, 0.0, 1.0) * m_;
  Cell c;
  c.i = std::min(static_cast<int>(x), m_ - 1);
  c.j = std::min(static_cast<int>(y), m_ - 1);
  c.s = x - c.i;
  c.t = y - c.j;
  return c;
}

void GridDisplacements::DisplacementAt(double u, double v, double out[3]) const {
  const Cell c = CellAt(u, v);
  const auto side = static_cast<std::size_t>(m_) + 1;
  const std::size_t k00 = static_cast<std::size_t>(c.j) * side + static_cast<std::size_t>(c.i);
  const std::size_t k10 = k00 + 1, k01 = k00 + side, k11 = k01 + 1;
  const double w00 = (1 - c.s) * (1 - c.t), w10 = c.s * (1 - c.t), w01 = (1 - c.s) * c.t,
               w11 = c.s * c.t;
  for (std::size_t a = 0; a < 3; ++a) {
    out[a] = w00 * d_[3 * k00 + a] + w10 * d_[3 * k10 + a] + w01 * d_[3 * k01 + a] +
             w11 * d_[3 * k11 + a];
  }
}

double GridDisplacements::HeightAt(double u, double v) const {
  DISPEX_CHECK(normals_);
  const Cell c = CellAt(u, v);
  const auto side = static_cast<std::size_t>(m_) + 1;
  const std::size_t k00 = static_cast<std::size_t>(c.j) * side + static_cast<std::size_t>(c.i);
  return (1 - c.s) * (1 - c.t) * h_[k00] + c.s * (1 - c.t) * h_[k00 + 1] +
         (1 - c.s) * c.t * h_[k00 + side] + c.s * c.t * h_[k00 + side + 1];
}

}  // namespace dispex::extract
