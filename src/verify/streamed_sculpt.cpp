// WriteStreamedRefinement (streamed_sculpt.h).
#include "verify/streamed_sculpt.h"

#include <fmt/format.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

namespace dispex::verify {
namespace {

constexpr float kCornerUv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

// Where every vertex of the refinement goes in the file: the used cage vertices first, then
// each base edge's n - 1 inner points from its lower vertex, then each base face's (n - 1)^2
// inner points row by row. A point is evaluated once, on one of the faces around it (a job).
class StreamLayout {
 public:
  StreamLayout(const Mesh& cage, int n) : cage_(cage), n_(n) {
    const std::size_t faces = cage.num_faces();
    corner_slot_.assign(cage.num_vertices(), -1);
    std::vector<std::uint64_t> edges;
    edges.reserve(4 * faces);
    for (std::size_t f = 0; f < faces; ++f) {
      auto c = cage.face(f);
      for (int k = 0; k < 4; ++k) {
        corner_slot_[std::size_t(c[k])] = 0;
        edges.push_back(EdgeKey(c[k], c[(k + 1) % 4]));
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    face_edges_.resize(4 * faces);
    for (std::size_t f = 0; f < faces; ++f) {
      auto c = cage.face(f);
      for (int k = 0; k < 4; ++k) {
        const auto at = std::lower_bound(edges.begin(), edges.end(), EdgeKey(c[k], c[(k + 1) % 4]));
        face_edges_[4 * f + std::size_t(k)] = static_cast<std::int32_t>(at - edges.begin());
      }
    }
    std::int64_t next = 0;
    for (std::int32_t& slot : corner_slot_) {
      if (slot == 0) slot = static_cast<std::int32_t>(next++);
    }
    corners_ = next;
    edges_ = static_cast<std::int64_t>(edges.size());
    const std::int64_t inner = n - 1;
    edge_first_ = corners_;
    face_first_ = edge_first_ + edges_ * inner;
    vertices_ = face_first_ + std::int64_t(faces) * inner * inner;
  }

  std::int64_t vertices() const { return vertices_; }
  std::int64_t corners() const { return corners_; }
  std::int64_t edges() const { return edges_; }
  std::int64_t edge_first() const { return edge_first_; }
  std::int64_t face_first() const { return face_first_; }
  std::int32_t corner_slot(std::int32_t vertex) const { return corner_slot_[std::size_t(vertex)]; }
  std::int32_t face_edge(std::size_t face, int k) const { return face_edges_[4 * face + k]; }

  // Grid point (i, j) of base face f, i along its first edge, j along its last one reversed.
  std::int32_t Slot(std::size_t f, int i, int j) const {
    auto c = cage_.face(f);
    const bool u_side = i == 0 || i == n_, v_side = j == 0 || j == n_;
    if (u_side && v_side)
      return corner_slot_[std::size_t(c[j == 0 ? (i == 0 ? 0 : 1) : (i == 0 ? 3 : 2)])];
    if (u_side || v_side) {
      int k, t;  // edge k of the face, step t from its corner k
      if (j == 0) {
        k = 0, t = i;
      } else if (i == n_) {
        k = 1, t = j;
      } else if (j == n_) {
        k = 2, t = n_ - i;
      } else {
        k = 3, t = n_ - j;
      }
      const int step = c[k] < c[(k + 1) % 4] ? t : n_ - t;
      return static_cast<std::int32_t>(edge_first_ + std::int64_t(face_edge(f, k)) * (n_ - 1) +
                                       (step - 1));
    }
    return static_cast<std::int32_t>(face_first_ + std::int64_t(f) * (n_ - 1) * (n_ - 1) +
                                     std::int64_t(j - 1) * (n_ - 1) + (i - 1));
  }

  static std::uint64_t EdgeKey(std::int32_t a, std::int32_t b) {
    return std::uint64_t(std::uint32_t(std::min(a, b))) << 32 | std::uint32_t(std::max(a, b));
  }

 private:
  const Mesh& cage_;
  int n_;
  std::vector<std::int32_t> corner_slot_;  // per cage vertex; -1 where no face uses it
  std::vector<std::int32_t> face_edges_;   // 4 per face: its edges' ranks by EdgeKey
  std::int64_t corners_ = 0, edges_ = 0, edge_first_ = 0, face_first_ = 0, vertices_ = 0;
};

// A run of consecutive slots evaluated on one face: a cage vertex at corner k, the inner points
// of the face's edge k (from its lower vertex), or the face's inner points.
struct Job {
  enum Kind : std::uint8_t { kCorner, kEdge, kInner };
  std::int32_t face = 0;
  Kind kind = kInner;
  std::uint8_t k = 0;
  std::int64_t first = 0;  // slot
  std::int64_t count = 0;
};

std::vector<Job> PlanJobs(const Mesh& cage, const StreamLayout& layout, int n) {
  std::vector<Job> jobs(std::size_t(layout.corners() + layout.edges()) + cage.num_faces());
  std::vector<bool> edge_seen(std::size_t(layout.edges()), false);
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    auto c = cage.face(f);
    for (int k = 0; k < 4; ++k) {
      // A cage vertex is evaluated once, on the last face around it.
      const std::int32_t slot = layout.corner_slot(c[k]);
      jobs[std::size_t(slot)] = {static_cast<std::int32_t>(f), Job::kCorner, std::uint8_t(k), slot,
                                 1};
      const std::int32_t edge = layout.face_edge(f, k);
      if (!edge_seen[std::size_t(edge)]) {
        edge_seen[std::size_t(edge)] = true;
        jobs[std::size_t(layout.corners() + edge)] = {
            static_cast<std::int32_t>(f), Job::kEdge, std::uint8_t(k),
            layout.edge_first() + std::int64_t(edge) * (n - 1), n - 1};
      }
    }
    jobs[std::size_t(layout.corners() + layout.edges()) + f] = {
        static_cast<std::int32_t>(f), Job::kInner, 0,
        layout.face_first() + std::int64_t(f) * (n - 1) * (n - 1), std::int64_t(n - 1) * (n - 1)};
  }
  return jobs;
}

// Every face's inner points' (u, v), row by row (exact: n is a power of two).
std::vector<float> InnerUvs(int n) {
  std::vector<float> uv;
  uv.reserve(2 * std::size_t(n - 1) * std::size_t(n - 1));
  for (int j = 1; j < n; ++j) {
    for (int i = 1; i < n; ++i) uv.insert(uv.end(), {float(i) / float(n), float(j) / float(n)});
  }
  return uv;
}

// The job's points' (u, v) on its face, in slot order: `inner` for a face's inner points, else
// written to `scratch`.
std::span<const float> JobUvs(const Mesh& cage, const Job& job, int n,
                              const std::vector<float>& inner, std::vector<float>& scratch) {
  if (job.kind == Job::kInner) return inner;
  scratch.resize(2 * std::size_t(job.count));
  const float* a = kCornerUv[job.k];
  if (job.kind == Job::kCorner) {
    scratch[0] = a[0], scratch[1] = a[1];
    return scratch;
  }
  auto c = cage.face(std::size_t(job.face));
  const float* b = kCornerUv[(job.k + 1) % 4];
  const bool from_corner = c[job.k] < c[(job.k + 1) % 4];
  for (int s = 1; s < n; ++s) {
    const float t = float(from_corner ? s : n - s) / float(n);
    scratch[2 * std::size_t(s - 1)] = a[0] + t * (b[0] - a[0]);
    scratch[2 * std::size_t(s - 1) + 1] = a[1] + t * (b[1] - a[1]);
  }
  return scratch;
}

}  // namespace

StatusOr<StreamedSculpt> WriteStreamedRefinement(const Mesh& cage, const LimitSurface& surface,
                                                 int levels, const PatternField& pattern,
                                                 const std::string& path,
                                                 std::string_view comment) {
  const std::string name = cage.source.empty() ? "cage" : cage.source;
  if (cage.num_faces() == 0) return Status::Error(fmt::format("{}: no faces", name));
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    if (cage.face_size(int(f)) != 4) {
      return Status::Error(fmt::format(
          "{}: face {} has {} corners: a streamed sculpt needs a cage of quads only (refine it "
          "once first)",
          name, f + 1, cage.face_size(f)));
    }
  }
  if (surface.num_ptex_faces() != int(cage.num_faces())) {
    return Status::Error(fmt::format("{}: the limit surface is not this cage's", name));
  }
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    if (surface.is_hole(PtexFaceId(f))) {
      return Status::Error(fmt::format(
          "{}: face {} is a hole (no limit surface): a streamed sculpt needs every face", name,
          f + 1));
    }
  }
  const int n = 1 << levels;
  const StreamLayout layout(cage, n);
  const std::int64_t faces = std::int64_t(cage.num_faces()) * n * n;
  if (layout.vertices() > std::numeric_limits<std::int32_t>::max() ||
      faces > std::numeric_limits<std::int32_t>::max()) {
    return Status::Error(fmt::format(
        "{} refined {} times: {} vertices and {} faces, more than a PLY's 32-bit indices hold",
        name, levels, layout.vertices(), faces));
  }
  const std::vector<Job> jobs = PlanJobs(cage, layout, n);
  DISPEX_ASSIGN_OR_RETURN(PlyStreamWriter out,
                          PlyStreamWriter::Create(path, std::size_t(layout.vertices()),
                                                  std::size_t(faces), 4, comment));

  // Jobs a chunk of about 4M points at a time: evaluated in parallel, written in order.
  constexpr std::int64_t kChunkPoints = std::int64_t(1) << 22;
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<std::vector<float>> uv_scratch, normal_scratch;
  tbb::combinable<StreamedSculpt> ranges;
  const std::vector<float> inner_uvs = InnerUvs(n);
  std::atomic<bool> failed{false};
  std::vector<float> points;
  for (std::size_t begin = 0; begin < jobs.size();) {
    std::size_t end = begin;
    while (
        end < jobs.size() &&
        (end == begin || jobs[end].first + jobs[end].count - jobs[begin].first <= kChunkPoints)) {
      ++end;
    }
    const std::int64_t chunk_first = jobs[begin].first;
    points.resize(3 * std::size_t(jobs[end - 1].first + jobs[end - 1].count - chunk_first));
    tbb::parallel_for(begin, end, [&](std::size_t j) {
      const Job& job = jobs[j];
      auto& evaluator = evaluators.local();
      if (!evaluator) evaluator.emplace(surface);
      const std::span<const float> uv = JobUvs(cage, job, n, inner_uvs, uv_scratch.local());
      std::vector<float>& normals = normal_scratch.local();
      normals.resize(3 * std::size_t(job.count));
      std::span<float> p(&points[3 * std::size_t(job.first - chunk_first)],
                         3 * std::size_t(job.count));
      if (!evaluator->EvaluatePoints(PtexFaceId(job.face), uv, p, normals).ok()) {
        failed = true;
        return;
      }
      StreamedSculpt& range = ranges.local();
      for (std::int64_t v = 0; v < job.count; ++v) {
        float* xyz = &p[3 * std::size_t(v)];
        double d[3], tangential;
        const double h = pattern.HeightAndDisplacement(
            PtexFaceId(job.face), uv[2 * std::size_t(v)], uv[2 * std::size_t(v) + 1], xyz,
            &normals[3 * std::size_t(v)], d, &tangential);
        for (int i = 0; i < 3; ++i) xyz[i] = static_cast<float>(xyz[i] + d[i]);
        range.h_min = std::min(range.h_min, h);
        range.h_max = std::max(range.h_max, h);
        range.max_displacement =
            std::max(range.max_displacement, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
        range.max_tangential = std::max(range.max_tangential, tangential);
      }
    });
    if (failed) {
      return Status::Error(
          fmt::format("{}: evaluating the limit surface at a sculpt vertex failed", name));
    }
    for (std::size_t i = 0; i < points.size(); i += 3) {
      DISPEX_RETURN_IF_ERROR(out.AddVertex(points[i], points[i + 1], points[i + 2]));
    }
    begin = end;
  }
  std::array<std::int32_t, 4> quad;
  for (std::size_t f = 0; f < cage.num_faces(); ++f) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        quad = {layout.Slot(f, i, j), layout.Slot(f, i + 1, j), layout.Slot(f, i + 1, j + 1),
                layout.Slot(f, i, j + 1)};
        DISPEX_RETURN_IF_ERROR(out.AddFace(quad));
      }
    }
  }
  DISPEX_RETURN_IF_ERROR(out.Commit());

  StreamedSculpt result = ranges.combine([](StreamedSculpt a, const StreamedSculpt& b) {
    a.h_min = std::min(a.h_min, b.h_min);
    a.h_max = std::max(a.h_max, b.h_max);
    a.max_displacement = std::max(a.max_displacement, b.max_displacement);
    a.max_tangential = std::max(a.max_tangential, b.max_tangential);
    return a;
  });
  result.vertices = std::size_t(layout.vertices());
  result.faces = std::size_t(faces);
  return result;
}

}  // namespace dispex::verify
