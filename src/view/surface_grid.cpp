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

// Every face's grid points, face after face from start[f]: P, D, the value.
struct GridSamples {
  std::vector<std::size_t> start;  // per face, and one past the last
  std::vector<Float3> p, d;
  std::vector<float> value;
  std::size_t slots() const { return start.back(); }
};

// Where each face's points begin: (n + 1)^2 points for a face of n > 0 quads a side.
std::vector<std::size_t> FaceStarts(std::span<const std::uint16_t> quads) {
  std::vector<std::size_t> start(quads.size() + 1, 0);
  for (std::size_t f = 0; f < quads.size(); ++f) {
    const std::size_t n = quads[f];
    start[f + 1] = start[f] + (n > 0 ? (n + 1) * (n + 1) : 0);
  }
  return start;
}

// Every face's grid, evaluated and displaced; the error of the lowest face that fails.
Status EvaluateFaces(const LimitSurface& surface, std::span<const std::uint16_t> quads,
                     const MapDisplacement& map, GridSamples& out) {
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<Scratch> scratches;
  std::mutex mutex;
  Status error;
  int error_face = -1;
  tbb::parallel_for(std::size_t{0}, quads.size(), [&](std::size_t f) {
    const int n = quads[f];
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
    const std::size_t at = out.start[f];
    for (std::size_t j = 0; j < points; ++j) {
      out.p[at + j] = {s.p[3 * j], s.p[3 * j + 1], s.p[3 * j + 2]};
      out.d[at + j] = {s.d[3 * j], s.d[3 * j + 1], s.d[3 * j + 2]};
      out.value[at + j] = s.value[j];
    }
  });
  return error;
}

// An error naming the first face whose D or value is not finite.
Status CheckFinite(const GridSamples& samples, const std::string& map_name) {
  const std::vector<Float3>& d = samples.d;
  for (std::size_t j = 0; j < samples.slots(); ++j) {
    if (!std::isfinite(d[j].x) || !std::isfinite(d[j].y) || !std::isfinite(d[j].z) ||
        !std::isfinite(samples.value[j])) {
      std::size_t f =
          static_cast<std::size_t>(std::upper_bound(samples.start.begin(), samples.start.end(), j) -
                                   samples.start.begin() - 1);
      return Status::Error(
          fmt::format("{}: face {} holds values that are not finite", map_name, f));
    }
  }
  return Status::Ok();
}

// The points faces share: along every edge between two faces, each point of one side that
// is a point of the other's grid.
DisjointSets SharedPoints(std::span<const PtexFaceInfo> faces, std::span<const std::uint16_t> quads,
                          std::span<const std::size_t> start) {
  const std::size_t num_faces = quads.size();
  auto on_edge = [&](std::size_t f, int edge, double t) {
    const int n = quads[f];
    double u = 0, v = 0;
    PtexEdgePoint(edge, t, u, v);
    const auto i = static_cast<std::size_t>(std::lround(u * n));
    const auto j = static_cast<std::size_t>(std::lround(v * n));
    return static_cast<std::uint32_t>(start[f] + j * std::size_t(n + 1) + i);
  };
  DisjointSets sets(start[num_faces]);
  for (std::size_t f = 0; f < num_faces; ++f) {
    const int n = quads[f];
    if (n == 0) continue;
    for (int edge = 0; edge < 4; ++edge) {
      for (int k = 0; k <= n; ++k) {
        const double t = double(k) / n;
        PtexEdgeSide other;
        if (!PtexAcrossEdge(faces, PtexFaceId(static_cast<std::int32_t>(f)), edge, t, other)) {
          continue;
        }
        const auto g = static_cast<std::size_t>(other.face.value);
        if (g >= num_faces || quads[g] == 0) continue;
        const double at = other.t * quads[g];
        const double r = std::round(at);
        if (std::fabs(at - r) > 1e-6) continue;
        sets.Join(on_edge(f, edge, t), on_edge(g, other.edge, r / quads[g]));
      }
    }
  }
  return sets;
}

// Vertex ids: interior points first, then each border point's set once, as the mean of the
// points in it (out.limit, displacement, value, border, shared_points).
void NumberVertices(const GridSamples& samples, DisjointSets& sets, SurfaceGrid& out) {
  const std::vector<std::size_t>& start = samples.start;
  const std::size_t num_faces = out.quads.size();
  auto border_point = [&](std::size_t f, std::size_t j) {
    const std::size_t n = out.quads[f], x = j % (n + 1), y = j / (n + 1);
    return x == 0 || y == 0 || x == n || y == n;
  };
  std::size_t interior = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::size_t n = out.quads[f];
    if (n > 1) interior += (n - 1) * (n - 1);
  }
  std::vector<std::uint32_t> id(samples.slots(), UINT32_MAX);
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
      const Float3& p = samples.p[slot];
      const Float3& d = samples.d[slot];
      if (!border_point(f, j)) {
        id[slot] = static_cast<std::uint32_t>(next_interior);
        out.limit[next_interior] = p;
        out.displacement[next_interior] = d;
        out.value[next_interior] = samples.value[slot];
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
      s[0] += p.x, s[1] += p.y, s[2] += p.z;
      s[3] += d.x, s[4] += d.y, s[5] += d.z;
      s[6] += samples.value[slot];
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
}

}  // namespace

StatusOr<SurfaceGrid> BuildSurfaceGrid(const LimitSurface& surface,
                                       std::span<const PtexFaceInfo> faces, int grid,
                                       const MapDisplacement& map, const std::string& map_name) {
  SurfaceGrid out;
  out.grid = grid;
  out.quads = FaceQuads(surface, grid);
  for (std::uint16_t n : out.quads) out.triangles += 2 * std::int64_t(n) * std::int64_t(n);
  GridSamples samples;
  samples.start = FaceStarts(out.quads);
  const std::size_t slots = samples.slots();
  if (slots >= (std::size_t{1} << 31)) {
    return Status::Error(fmt::format("{} grid points: too many for a page", slots));
  }
  samples.p.resize(slots), samples.d.resize(slots), samples.value.resize(slots);
  DISPEX_RETURN_IF_ERROR(EvaluateFaces(surface, out.quads, map, samples));
  DISPEX_RETURN_IF_ERROR(CheckFinite(samples, map_name));
  DisjointSets sets = SharedPoints(faces, out.quads, samples.start);
  NumberVertices(samples, sets, out);
  return out;
}

}  // namespace dispex::view
