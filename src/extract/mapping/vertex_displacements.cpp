#include "extract/mapping/vertex_displacements.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/check.h"

namespace dispex::extract {

namespace {

// Point (x, y) of face `face`'s grid (half-cell units), beyond its edge `edge`, in the grid
// that holds it: across the edge, and across one more edge where a quad's edge meets two
// sub-faces and its crossing leads into the one that holds the other half. False where no
// grid is laid out there.
bool Locate(const GridSource& source, int face, int edge, int x, int y, int& g, int& gx, int& gy) {
  const SculptMapping::Crossing* c = &source.crossing(face, edge);
  for (int hop = 0; hop < 2; ++hop) {
    if (!c->leads()) return false;
    const std::array<int, 2> p = SculptMapping::CrossEdge(*c, x, y);
    gx = p[0], gy = p[1];
    g = c->to;
    const int size = 2 * source.grid_size(g);
    const int beyond = gy < 0 ? 0 : gx > size ? 1 : gy > size ? 2 : gx < 0 ? 3 : -1;
    if (beyond < 0) return true;
    c = &source.crossing(g, beyond);
    x = gx, y = gy;
  }
  return false;
}

}  // namespace

void ApronVertices(const GridSource& source, int face, const Mesh& sculpt,
                   std::vector<ApronVertex>& out) {
  out.clear();
  const int m = source.grid_size(face);
  const int side = m + 1;
  for (int edge = 0; edge < 4; ++edge) {
    for (int k = 1; k < m; ++k) {
      // Edge e runs from corner e to corner e + 1: (0, 0), (m, 0), (m, m), (0, m).
      int a = 0, b = 0, da = 0, db = 0;
      switch (edge) {
        case 0:
          a = k, b = 0, db = -1;
          break;
        case 1:
          a = m, b = k, da = 1;
          break;
        case 2:
          a = k, b = m, db = 1;
          break;
        default:
          a = 0, b = k, da = -1;
          break;
      }
      // The apron vertex, one cell outward, lies inside the neighbour that holds the edge
      // vertex beside it. A corner of the neighbour's grid (the middle of an n-gon's edge, a
      // corner of its sub-faces) keeps D, as it does there.
      int g = -1, x = 0, y = 0, eg = -1, ex = 0, ey = 0;
      if (!Locate(source, face, edge, 2 * (a + da), 2 * (b + db), g, x, y) ||
          !Locate(source, face, edge, 2 * a + da, 2 * b + db, eg, ex, ey) || eg != g) {
        continue;
      }
      const int size = 2 * source.grid_size(g);
      const int vx = x - 2 * (x - ex), vy = y - 2 * (y - ey);  // the edge vertex in g
      if ((vx == 0 || vx == size) && (vy == 0 || vy == size)) continue;
      if ((x & 1) || (y & 1)) continue;
      out.push_back({b * side + a, g, x / 2, y / 2, source.vertex(g, x / 2, y / 2, sculpt)});
    }
  }
}

void FaceFieldVertices(const GridSource& source, int face, const Mesh& sculpt,
                       std::vector<VertexId>& vertices, std::vector<int>& apron_faces) {
  vertices.clear();
  apron_faces.clear();
  if (source.grid_size(face) == 0) return;
  source.grid(face, sculpt, vertices);
  std::vector<ApronVertex> apron;
  ApronVertices(source, face, sculpt, apron);
  for (const ApronVertex& v : apron) {
    vertices.push_back(v.id);
    apron_faces.push_back(v.face);
  }
  std::sort(apron_faces.begin(), apron_faces.end());
  apron_faces.erase(std::unique(apron_faces.begin(), apron_faces.end()), apron_faces.end());
}

Status GridDisplacements::Evaluate(PtexFaceId face, const GridSource& source, const Mesh& sculpt,
                                   LimitEvaluator& evaluator, bool normals) {
  const int m = source.grid_size(face.value);
  if (face.value == face_ && m == m_ && (normals_ || !normals)) return Status::Ok();
  face_ = -1;
  DISPEX_CHECK_GT(m, 0);
  source.grid(face.value, sculpt, vertices_);
  const auto side = static_cast<std::size_t>(m) + 1;
  const std::size_t count = side * side;
  DISPEX_CHECK_EQ(vertices_.size(), count);
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
    const Float3& s = sculpt.positions[static_cast<std::size_t>(vertices_[k].value)];
    const double d[3] = {double(s.x) - positions_[3 * k], double(s.y) - positions_[3 * k + 1],
                         double(s.z) - positions_[3 * k + 2]};
    std::copy(d, d + 3, &d_[3 * k]);
    if (normals) {
      h_[k] = d[0] * limit_normals_[3 * k] + d[1] * limit_normals_[3 * k + 1] +
              d[2] * limit_normals_[3 * k + 2];
    }
  }
  m_ = m;
  normals_ = normals;
  ApronVertices(source, face.value, sculpt, apron_);
  DISPEX_RETURN_IF_ERROR(EvaluateApron(source, sculpt, evaluator));
  Bend();
  face_ = face.value;
  return Status::Ok();
}

// D (and h) of the apron vertices, at their own limit points, one evaluation per neighbour.
Status GridDisplacements::EvaluateApron(const GridSource& source, const Mesh& sculpt,
                                        LimitEvaluator& evaluator) {
  outer_d_.resize(3 * apron_.size());
  outer_h_.resize(normals_ ? apron_.size() : 0);
  for (std::size_t first = 0; first < apron_.size();) {
    const int g = apron_[first].face;
    std::size_t last = first;
    while (last < apron_.size() && apron_[last].face == g) ++last;
    const std::size_t count = last - first;
    const float mg = static_cast<float>(source.grid_size(g));
    uv_.resize(2 * count);
    for (std::size_t k = 0; k < count; ++k) {
      uv_[2 * k] = static_cast<float>(apron_[first + k].a) / mg;
      uv_[2 * k + 1] = static_cast<float>(apron_[first + k].b) / mg;
    }
    positions_.resize(3 * count);
    limit_normals_.resize(normals_ ? 3 * count : 0);
    DISPEX_RETURN_IF_ERROR(
        evaluator.EvaluatePoints(PtexFaceId(g), uv_, positions_, limit_normals_));
    for (std::size_t k = 0; k < count; ++k) {
      const Float3& s = sculpt.positions[static_cast<std::size_t>(apron_[first + k].id.value)];
      double* d = &outer_d_[3 * (first + k)];
      d[0] = double(s.x) - positions_[3 * k];
      d[1] = double(s.y) - positions_[3 * k + 1];
      d[2] = double(s.z) - positions_[3 * k + 2];
      if (normals_) {
        outer_h_[first + k] = d[0] * limit_normals_[3 * k] + d[1] * limit_normals_[3 * k + 1] +
                              d[2] * limit_normals_[3 * k + 2];
      }
    }
    first = last;
  }
  return Status::Ok();
}

// L at every vertex with four neighbours: inside the grid, and on an edge with its apron
// vertex; 0 elsewhere.
void GridDisplacements::Bend() {
  const int side = m_ + 1;
  const auto count = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  bend_d_.assign(3 * count, 0.0);
  bend_h_.assign(normals_ ? count : 0, 0.0);
  outer_of_.assign(count, -1);
  for (std::size_t e = 0; e < apron_.size(); ++e) {
    outer_of_[static_cast<std::size_t>(apron_[e].inner)] = static_cast<int>(e);
  }
  for (int b = 0; b < side; ++b) {
    for (int a = 0; a < side; ++a) {
      const auto k = static_cast<std::size_t>(b * side + a);
      const int outer = outer_of_[k];
      const bool edge = a == 0 || b == 0 || a == m_ || b == m_;
      if (edge && outer < 0) continue;  // a corner, an open border, no neighbour laid out
      double* bend = &bend_d_[3 * k];
      double bend_h = 0;
      if (outer >= 0) {
        for (int c = 0; c < 3; ++c) bend[c] = outer_d_[3 * static_cast<std::size_t>(outer) + c];
        if (normals_) bend_h = outer_h_[static_cast<std::size_t>(outer)];
      }
      const int neighbours[4][2] = {{a - 1, b}, {a + 1, b}, {a, b - 1}, {a, b + 1}};
      for (const auto& [na, nb] : neighbours) {
        if (na < 0 || nb < 0 || na > m_ || nb > m_) continue;
        const auto n = static_cast<std::size_t>(nb * side + na);
        for (int c = 0; c < 3; ++c) bend[c] += d_[3 * n + c];
        if (normals_) bend_h += h_[n];
      }
      for (int c = 0; c < 3; ++c) bend[c] -= 4 * d_[3 * k + c];
      if (normals_) bend_h_[k] = bend_h - 4 * h_[k];
    }
  }
}

void GridDisplacements::SetSampling(int n) {
  const double sharpen = n > 0 && n >= m_ ? double(m_) / (4.0 * n) : 0.0;
  read_d_.resize(d_.size());
  for (std::size_t k = 0; k < d_.size(); ++k) read_d_[k] = d_[k] - sharpen * bend_d_[k];
  read_h_.resize(h_.size());
  for (std::size_t k = 0; k < h_.size(); ++k) read_h_[k] = h_[k] - sharpen * bend_h_[k];
}

GridDisplacements::Cell GridDisplacements::CellAt(double u, double v) const {
  const double x = std::clamp(u, 0.0, 1.0) * m_, y = std::clamp(v, 0.0, 1.0) * m_;
  const int i = std::min(static_cast<int>(x), m_ - 1), j = std::min(static_cast<int>(y), m_ - 1);
  const double s = x - i, t = y - j;
  const std::size_t side = static_cast<std::size_t>(m_) + 1;
  const std::size_t k00 = static_cast<std::size_t>(j) * side + static_cast<std::size_t>(i);
  return {{k00, k00 + 1, k00 + side, k00 + side + 1},
          {(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t}};
}

void GridDisplacements::DisplacementAt(double u, double v, double out[3]) const {
  const Cell c = CellAt(u, v);
  for (std::size_t a = 0; a < 3; ++a) {
    double sum = 0;
    for (int q = 0; q < 4; ++q) sum += c.w[q] * read_d_[3 * c.k[q] + a];
    out[a] = sum;
  }
}

double GridDisplacements::HeightAt(double u, double v) const {
  DISPEX_CHECK(normals_);
  const Cell c = CellAt(u, v);
  double sum = 0;
  for (int q = 0; q < 4; ++q) sum += c.w[q] * read_h_[c.k[q]];
  return sum;
}

}  // namespace dispex::extract
