#include "view/surface_grid.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <optional>

#include "dispex/ptex_sampler.h"

namespace dispex::view {

std::vector<std::uint16_t> FaceQuads(const LimitSurface& surface, int grid) {
  std::vector<std::uint16_t> quads(static_cast<std::size_t>(surface.num_ptex_faces()), 0);
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    const PtexFaceId face(f);
    if (surface.is_hole(face)) continue;
    const bool sub_face = surface.num_ptex_faces(surface.base_face(face)) != 1;
    quads[static_cast<std::size_t>(f)] = static_cast<std::uint16_t>(sub_face ? grid / 2 : grid);
  }
  return quads;
}

std::int64_t GridPoints(std::span<const std::uint16_t> quads) {
  std::int64_t points = 0;
  for (std::uint16_t n : quads) {
    if (n > 0) points += std::int64_t(n + 1) * (n + 1);
  }
  return points;
}

namespace {

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) {
    std::iota(parent.begin(), parent.end(), std::uint32_t{0});
  }
  std::uint32_t Find(std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  // The smaller root stays, so the result does not depend on the order of the unions.
  void Join(std::uint32_t a, std::uint32_t b) {
    a = Find(a), b = Find(b);
    if (a < b) {
      parent[b] = a;
    } else if (b < a) {
      parent[a] = b;
    }
  }
};

struct Scratch {
  std::vector<float> uv, p, n, du, dv, d, value;
};

}  // namespace

StatusOr<SurfaceGrid> BuildSurfaceGrid(const LimitSurface& surface,
                                       std::span<const PtexFaceInfo> faces, int grid,
                                       const MapDisplacement& map, const std::string& map_name) {
  SurfaceGrid out;
  out.grid = grid;
  out.quads = FaceQuads(surface, grid);
  const std::size_t num_faces = out.quads.size();
  std::vector<std::size_t> start(num_faces + 1, 0);
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::size_t n = out.quads[f];
    start[f + 1] = start[f] + (n > 0 ? (n + 1) * (n + 1) : 0);
    out.triangles += 2 * std::int64_t(n) * std::int64_t(n);
  }
  const std::size_t slots = start[num_faces];
  if (slots >= (std::size_t{1} << 31)) {
    return Status::Error(fmt::format("{} grid points: too many for a page", slots));
  }
  std::vector<Float3> p(slots), d(slots);
  std::vector<float> value(slots);

  // Every face's grid, evaluated and displaced.
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<Scratch> scratches;
  std::mutex mutex;
  Status error;
  int error_face = -1;
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    const int n = out.quads[f];
    if (n == 0) return;
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    Scratch& s = scratches.local();
    const std::size_t points = std::size_t(n + 1) * (n + 1);
    s.uv.resize(2 * points);
    for (auto* v : {&s.p, &s.n, &s.du, &s.dv, &s.d}) v->resize(3 * points);
    s.value.resize(points);
    std::size_t i = 0;
    for (int y = 0; y <= n; ++y) {
      for (int x = 0; x <= n; ++x) {
        s.uv[i++] = float(x) / float(n);
        s.uv[i++] = float(y) / float(n);
      }
    }
    const PtexFaceId face(static_cast<std::int32_t>(f));
    LimitEvaluator::Frames frames{s.p, s.n, s.du, s.dv};
    Status st = evaluator->EvaluatePointFrames(face, s.uv, frames);
    if (!st.ok()) {
      std::lock_guard lock(mutex);
      if (error_face < 0 || int(f) < error_face) error = st, error_face = int(f);
      return;
    }
    map.Displace(face, s.uv, frames, s.d, s.value);
    for (std::size_t j = 0; j < points; ++j) {
      p[start[f] + j] = {s.p[3 * j], s.p[3 * j + 1], s.p[3 * j + 2]};
      d[start[f] + j] = {s.d[3 * j], s.d[3 * j + 1], s.d[3 * j + 2]};
      value[start[f] + j] = s.value[j];
    }
  });
  DISPEX_RETURN_IF_ERROR(error);
  for (std::size_t j = 0; j < slots; ++j) {
    if (!std::isfinite(d[j].x) || !std::isfinite(d[j].y) || !std::isfinite(d[j].z) ||
        !std::isfinite(value[j])) {
      std::size_t f = static_cast<std::size_t>(std::upper_bound(start.begin(), start.end(), j) -
                                               start.begin() - 1);
      return Status::Error(
          fmt::format("{}: face {} holds values that are not finite", map_name, f));
    }
  }

  // The points faces share: along every edge between two faces, each point of one side that
  // is a point of the other's grid.
  auto on_edge = [&](std::size_t f, int edge, double t) {
    const int n = out.quads[f];
    double u = 0, v = 0;
    PtexEdgePoint(edge, t, u, v);
    const auto i = static_cast<std::size_t>(std::lround(u * n));
    const auto j = static_cast<std::size_t>(std::lround(v * n));
    return static_cast<std::uint32_t>(start[f] + j * std::size_t(n + 1) + i);
  };
  DisjointSets sets(slots);
  for (std::size_t f = 0; f < num_faces; ++f) {
    const int n = out.quads[f];
    if (n == 0) continue;
    for (int edge = 0; edge < 4; ++edge) {
      for (int k = 0; k <= n; ++k) {
        const double t = double(k) / n;
        PtexEdgeSide other;
        if (!PtexAcrossEdge(faces, PtexFaceId(static_cast<std::int32_t>(f)), edge, t, other)) {
          continue;
        }
        const auto g = static_cast<std::size_t>(other.face.value);
        if (g >= num_faces || out.quads[g] == 0) continue;
        const double at = other.t * out.quads[g];
        const double r = std::round(at);
        if (std::fabs(at - r) > 1e-6) continue;
        sets.Join(on_edge(f, edge, t), on_edge(g, other.edge, r / out.quads[g]));
      }
    }
  }

  // Vertex ids: interior points first, then each border point's set once.
  auto border_point = [&](std::size_t f, std::size_t j) {
    const std::size_t n = out.quads[f], x = j % (n + 1), y = j / (n + 1);
    return x == 0 || y == 0 || x == n || y == n;
  };
  std::size_t interior = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::size_t n = out.quads[f];
    if (n > 1) interior += (n - 1) * (n - 1);
  }
  std::vector<std::uint32_t> id(slots, UINT32_MAX);
  std::vector<std::uint32_t> members;  // per vertex: how many points it is the mean of
  std::size_t next_interior = 0, next_border = interior;
  out.limit.resize(interior);
  out.displacement.resize(interior);
  out.value.resize(interior);
  members.assign(interior, 1);
  std::vector<double> sums;  // per border vertex: P, D, value
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::size_t points = start[f + 1] - start[f];
    for (std::size_t j = 0; j < points; ++j) {
      const std::size_t slot = start[f] + j;
      if (!border_point(f, j)) {
        id[slot] = static_cast<std::uint32_t>(next_interior);
        out.limit[next_interior] = p[slot];
        out.displacement[next_interior] = d[slot];
        out.value[next_interior] = value[slot];
        ++next_interior;
        continue;
      }
      const std::uint32_t root = sets.Find(static_cast<std::uint32_t>(slot));
      if (id[root] == UINT32_MAX) {
        id[root] = static_cast<std::uint32_t>(next_border++);
        members.push_back(0);
        sums.resize(sums.size() + 7, 0.0);
      }
      const std::uint32_t v = id[root];
      id[slot] = v;
      out.border.push_back(v);
      ++members[v];
      double* s = &sums[7 * (v - interior)];
      s[0] += p[slot].x, s[1] += p[slot].y, s[2] += p[slot].z;
      s[3] += d[slot].x, s[4] += d[slot].y, s[5] += d[slot].z;
      s[6] += value[slot];
    }
  }
  const std::size_t borders = next_border - interior;
  out.limit.resize(next_border);
  out.displacement.resize(next_border);
  out.value.resize(next_border);
  for (std::size_t b = 0; b < borders; ++b) {
    const std::size_t v = interior + b;
    const double* s = &sums[7 * b];
    const double m = members[v];
    if (members[v] > 1) ++out.shared_points;
    out.limit[v] = {float(s[0] / m), float(s[1] / m), float(s[2] / m)};
    out.displacement[v] = {float(s[3] / m), float(s[4] / m), float(s[5] / m)};
    out.value[v] = float(s[6] / m);
  }
  return out;
}

}  // namespace dispex::view
