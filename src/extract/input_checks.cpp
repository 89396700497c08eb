#include "extract/input_checks.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::extract {

namespace {

constexpr int kUnknowns = 7;  // t (3), w (3), s
using Row = std::array<double, kUnknowns>;

// Least squares over rows added one by one: (A^T A) x = A^T b, with the sum of b^2 kept.
class Normal {
 public:
  void Add(const Row& a, double b) {
    for (int i = 0; i < kUnknowns; ++i) {
      for (int j = 0; j < kUnknowns; ++j) ata_[i][j] += a[i] * a[j];
      atb_[i] += a[i] * b;
    }
    btb_ += b * b;
  }
  // x, and the fraction of sum b^2 that A x accounts for. A direction the rows do not see (a
  // plane's slide along itself, seen along its normal) gets the least-norm answer's 0, from a
  // ridge of 1e-9 of the trace.
  Row Solve(double& explained) const {
    std::array<std::array<double, kUnknowns + 1>, kUnknowns> m{};
    double trace = 0;
    for (int i = 0; i < kUnknowns; ++i) trace += ata_[i][i];
    for (int i = 0; i < kUnknowns; ++i) {
      for (int j = 0; j < kUnknowns; ++j) m[i][j] = ata_[i][j];
      m[i][i] += 1e-9 * trace / kUnknowns + 1e-300;
      m[i][kUnknowns] = atb_[i];
    }
    for (int c = 0; c < kUnknowns; ++c) {
      int pivot = c;
      for (int r = c + 1; r < kUnknowns; ++r) {
        if (std::abs(m[r][c]) > std::abs(m[pivot][c])) pivot = r;
      }
      std::swap(m[c], m[pivot]);
      for (int r = c + 1; r < kUnknowns; ++r) {
        const double f = m[r][c] / m[c][c];
        for (int k = c; k <= kUnknowns; ++k) m[r][k] -= f * m[c][k];
      }
    }
    Row x{};
    for (int r = kUnknowns - 1; r >= 0; --r) {
      double v = m[r][kUnknowns];
      for (int k = r + 1; k < kUnknowns; ++k) v -= m[r][k] * x[k];
      x[r] = v / m[r][r];
    }
    // |b - A x|^2 = b.b - 2 x.A^T b + x.A^T A x.
    double xatb = 0, xatax = 0;
    for (int i = 0; i < kUnknowns; ++i) {
      xatb += x[i] * atb_[i];
      for (int j = 0; j < kUnknowns; ++j) xatax += x[i] * ata_[i][j] * x[j];
    }
    const double residual = std::max(0.0, btb_ - 2 * xatb + xatax);
    explained = btb_ > 0 ? 1 - residual / btb_ : 0;
    return x;
  }

 private:
  double ata_[kUnknowns][kUnknowns] = {};
  double atb_[kUnknowns] = {};
  double btb_ = 0;
};

// The fit in the units of the points: r was divided by `length` for the rows.
PlacementFit Finish(const Normal& normal, double length, std::span<const Vec3d> p,
                    const Vec3d& centre) {
  PlacementFit fit;
  const Row x = normal.Solve(fit.explained);
  fit.translation = {x[0], x[1], x[2]};
  fit.rotation = Vec3d{x[3], x[4], x[5]} * (1 / length);
  fit.scale = x[6] / length;
  fit.points = p.size();
  for (const Vec3d& point : p) {
    const Vec3d r = point - centre;
    const Vec3d move = fit.translation + Cross(fit.rotation, r) + r * fit.scale;
    fit.largest_move = std::max(fit.largest_move, Length(move));
  }
  return fit;
}

double Extent(std::span<const Vec3d> p, const Vec3d& centre) {
  double length = 0;
  for (const Vec3d& point : p) length = std::max(length, Length(point - centre));
  return length > 0 ? length : 1;
}

}  // namespace

PlacementFit FitPlacement(std::span<const Vec3d> p, std::span<const Vec3d> d, const Vec3d& centre) {
  const double length = Extent(p, centre);
  Normal normal;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3d r = (p[i] - centre) * (1 / length);
    // d = t + w x r + s r, a row per component.
    normal.Add({1, 0, 0, 0, r.z, -r.y, r.x}, d[i].x);
    normal.Add({0, 1, 0, -r.z, 0, r.x, r.y}, d[i].y);
    normal.Add({0, 0, 1, r.y, -r.x, 0, r.z}, d[i].z);
  }
  return Finish(normal, length, p, centre);
}

PlacementFit FitPlacementAlongNormals(std::span<const Vec3d> p, std::span<const Vec3d> n,
                                      std::span<const double> h, const Vec3d& centre) {
  const double length = Extent(p, centre);
  // h = n.(t + w x r + s r) = n.t + w.(r x n) + s r.n.
  auto row = [&](std::size_t i) {
    const Vec3d r = (p[i] - centre) * (1 / length);
    const Vec3d rn = Cross(r, n[i]);
    return Row{n[i].x, n[i].y, n[i].z, rn.x, rn.y, rn.z, Dot(r, n[i])};
  };
  Normal normal;
  for (std::size_t i = 0; i < p.size(); ++i) normal.Add(row(i), h[i]);
  // Rays can meet another part of the sculpt (across a thin part, past a fold): such hits are
  // far off any fit, and are left out of a second fit (residual over 3 x the first's RMS).
  double explained = 0;
  const Row x = normal.Solve(explained);
  std::vector<double> residual(p.size());
  double sum = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Row a = row(i);
    double fitted = 0;
    for (int k = 0; k < kUnknowns; ++k) fitted += a[k] * x[k];
    residual[i] = h[i] - fitted;
    sum += residual[i] * residual[i];
  }
  const double limit = 3 * std::sqrt(sum / double(std::max<std::size_t>(1, p.size())));
  Normal inliers;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (std::abs(residual[i]) <= limit) inliers.Add(row(i), h[i]);
  }
  return Finish(inliers, length, p, centre);
}

StatusOr<PlacementFit> MeasurePlacement(const ExtractInputs& inputs, const GridSource* grids,
                                        const ExtractSettings* settings) {
  const LimitSurface& surface = inputs.surface;
  const int faces = surface.num_ptex_faces();
  const int stride = std::max(1, faces / kPlacementProbeFaces);
  std::vector<int> probed;
  for (int f = 0; f < faces; f += stride) {
    if (!surface.is_hole(PtexFaceId(f))) probed.push_back(f);
  }
  constexpr int kPoints = 9;  // 3 x 3 a face
  const std::size_t count = probed.size() * kPoints;
  std::vector<Vec3d> p(count), d(count), n(count);
  std::vector<double> h(count, std::nan(""));
  std::vector<Status> errors(probed.size());
  tbb::enumerable_thread_specific<LimitEvaluator> evaluators(
      [&] { return LimitEvaluator(surface); });
  tbb::parallel_for(std::size_t{0}, probed.size(), [&](std::size_t k) {
    const int f = probed[k];
    LimitEvaluator& evaluator = evaluators.local();
    float uv[2 * kPoints], xyz[3 * kPoints], normals[3 * kPoints];
    int m = 0;
    if (grids != nullptr) m = grids->grid_size(f);
    for (int q = 0; q < kPoints; ++q) {
      const int i = q % 3, j = q / 3;
      if (grids != nullptr) {  // grid vertices: the corners and the middle of the grid
        uv[2 * q] = static_cast<float>(i * m / 2) / static_cast<float>(m);
        uv[2 * q + 1] = static_cast<float>(j * m / 2) / static_cast<float>(m);
      } else {
        uv[2 * q] = static_cast<float>(2 * i + 1) / 6.0f;
        uv[2 * q + 1] = static_cast<float>(2 * j + 1) / 6.0f;
      }
    }
    errors[k] = evaluator.EvaluatePoints(PtexFaceId(f), uv, xyz, normals);
    if (!errors[k].ok()) return;
    for (int q = 0; q < kPoints; ++q) {
      const std::size_t at = k * kPoints + static_cast<std::size_t>(q);
      p[at] = {xyz[3 * q], xyz[3 * q + 1], xyz[3 * q + 2]};
      n[at] = {normals[3 * q], normals[3 * q + 1], normals[3 * q + 2]};
      if (grids != nullptr) {
        const int i = q % 3, j = q / 3;
        const VertexId v = grids->vertex(f, i * m / 2, j * m / 2, inputs.sculpt);
        const Float3& s = inputs.sculpt.positions[static_cast<std::size_t>(v.value)];
        d[at] = Vec3d{s.x, s.y, s.z} - p[at];
      }
    }
  });
  for (const Status& s : errors) DISPEX_RETURN_IF_ERROR(s);
  const BoundingBox bounds = ComputeBounds(inputs.base);
  const Vec3d centre{0.5 * (double(bounds.min.x) + bounds.max.x),
                     0.5 * (double(bounds.min.y) + bounds.max.y),
                     0.5 * (double(bounds.min.z) + bounds.max.z)};
  if (grids != nullptr) return FitPlacement(p, d, centre);
  // Along the normals: the rays' hits; misses are left out.
  std::vector<Float3> origins(count), directions(count);
  for (std::size_t i = 0; i < count; ++i) {
    origins[i] = {float(p[i].x), float(p[i].y), float(p[i].z)};
    directions[i] = {float(n[i].x), float(n[i].y), float(n[i].z)};
  }
  std::vector<float> t(count);
  std::vector<std::uint8_t> flags(count);
  TraceCounters counters;
  inputs.tracer->TraceNormals(origins, directions, settings->query, NormalHits{t, {}, flags},
                              counters);
  std::vector<Vec3d> hit_p, hit_n;
  std::vector<double> hit_h;
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(t[i])) continue;
    hit_p.push_back(p[i]);
    hit_n.push_back(n[i]);
    hit_h.push_back(t[i]);
  }
  return FitPlacementAlongNormals(hit_p, hit_n, hit_h, centre);
}

Status CheckFaceCounts(const Mesh& base, const Mesh& sculpt) {
  if (sculpt.num_faces() >= base.num_faces()) return Status::Ok();
  return Status::Error(
      StatusCode::kMismatch,
      fmt::format(
          "{} has {} faces, fewer than the base {} ({}): base and sculpt swapped? The base is the "
          "low-resolution cage, the sculpt the detailed mesh made from it; extract with "
          "check_inputs off if this is meant",
          sculpt.source, sculpt.num_faces(), base.source, base.num_faces()));
}

Status CheckPlacement(const PlacementFit& fit, double diagonal, const std::string& sculpt) {
  const double move = fit.largest_move / diagonal;
  const bool moved =
      (fit.explained >= 0.9 && move >= 0.015) || (fit.explained >= 0.75 && move >= 0.03);
  if (!moved) return Status::Ok();
  const double turn = Length(fit.rotation) * 180 / std::numbers::pi;
  return Status::Error(
      StatusCode::kMismatch,
      fmt::format(
          "{}: the sculpt looks moved against its base, not sculpted: a move by ({:.4g}, {:.4g}, "
          "{:.4g}) ({:.2g}% of the base's diagonal), a scale by {:.4g} and a turn by {:.2g} "
          "degrees "
          "explain {:.0f}% of its displacement (another unit, axis or pivot at export?); put it "
          "back "
          "on its base, or extract with check_inputs off if the displacement is meant",
          sculpt, fit.translation.x, fit.translation.y, fit.translation.z,
          100 * Length(fit.translation) / diagonal, 1 + fit.scale, turn, 100 * fit.explained));
}

}  // namespace dispex::extract
