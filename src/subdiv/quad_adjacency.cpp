#include "subdiv/quad_adjacency.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/first_touch.h"

namespace dispex::subdiv {
namespace {

using Range = tbb::blocked_range<std::size_t>;

// How far ahead the scattered reads are prefetched (vertices, half-edges).
constexpr std::size_t kAhead = 16;

std::uint32_t Load(std::uint32_t& slot) {
  return std::atomic_ref<std::uint32_t>(slot).load(std::memory_order_relaxed);
}

// The lowest index for which `bad` holds, or `none`.
template <class Bad>
std::size_t LowestWhere(std::size_t count, std::size_t none, Bad bad) {
  tbb::combinable<std::size_t> lowest([none] { return none; });
  tbb::parallel_for(Range(0, count, 4096), [&](const Range& r) {
    std::size_t& mine = lowest.local();
    for (std::size_t i = r.begin(); i < r.end() && i < mine; ++i) {
      if (bad(i)) {
        mine = i;
        break;
      }
    }
  });
  return lowest.combine([](std::size_t a, std::size_t b) { return std::min(a, b); });
}

// Fails for the lowest quad that uses a vertex twice.
Status CheckNoVertexTwice(const Mesh& mesh) {
  const std::size_t num_faces = mesh.num_faces();
  const std::int32_t* start = mesh.face_indices.data();
  const std::size_t repeating = LowestWhere(num_faces, num_faces, [&](std::size_t f) {
    const std::int32_t* q = start + 4 * f;
    return q[0] == q[1] || q[0] == q[2] || q[0] == q[3] || q[1] == q[2] || q[1] == q[3] ||
           q[2] == q[3];
  });
  if (repeating == num_faces) return Status::Ok();
  const std::int32_t* q = start + 4 * repeating;
  const std::int32_t twice = (q[0] == q[1] || q[0] == q[2] || q[0] == q[3]) ? q[0]
                             : (q[1] == q[2] || q[1] == q[3])               ? q[1]
                                                                            : q[2];
  return Status::Error(
      fmt::format("{}: face {} uses vertex {} twice", mesh.source, repeating, twice));
}

// Half-edges bucketed by their start vertex, in order: bucket[v] spans [first[v],
// first[v + 1]). The half-edges are cut in two halves, each counted into its own array (the
// second one's in `second`) and filled from its own cursors, so that no thread reads every
// half-edge; tasks also own ranges of vertices, so that the scattered updates need no atomics
// (which would serialise the cache misses of a sculpt numbered at random). The vertices are
// bucketed and resolved in passes of at most `bucket_entries` half-edges (a vertex with more
// is a pass of its own), one bucket re-used by each: fresh memory is most of what this costs.
class HalfEdgeBuckets {
 public:
  explicit HalfEdgeBuckets(const Mesh& mesh);

  // Counts the half-edges leaving each vertex; fails for the lowest vertex no face uses.
  Status Count(const std::string& source);
  // Turns the counts into cursors and cuts the vertices into passes; allocates the bucket.
  void PlanPasses(std::size_t bucket_entries);
  std::size_t num_passes() const { return pass_starts_.size() - 1; }
  // Buckets the half-edges of pass `pass`'s vertices and resolves the edges at them into
  // `out`, keeping the lowest half-edge of a bad edge in `lowest_bad`.
  void ResolvePass(std::size_t pass, QuadAdjacency& out,
                   tbb::combinable<std::uint32_t>& lowest_bad);
  void ReleaseSecondHalf() { std::vector<std::uint32_t>().swap(second_); }
  // After the passes: per vertex, the lowest half-edge leaving it.
  std::vector<std::uint32_t> TakeFirstHalfEdges() {
    first_.pop_back();
    return std::move(first_);
  }

 private:
  template <class Visit>
  void ForEachTask(std::size_t pass_lo, std::size_t pass_hi, std::uint32_t* bucket,
                   std::uint32_t base, Visit&& visit);
  void ResolveVertices(std::size_t lo, std::size_t hi, std::uint32_t bucket_base,
                       QuadAdjacency& out, tbb::combinable<std::uint32_t>& lowest_bad) const;

  const std::int32_t* start_;  // the start vertex of each half-edge (the face indices)
  std::size_t num_vertices_, num_half_edges_;
  std::size_t halves_, vertex_parts_;
  std::vector<std::uint32_t> first_, second_;
  std::uint32_t* counts_[2];  // per half: first_, second_
  std::vector<std::size_t> pass_starts_;
  std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>> storage_;  // the bucket
};

HalfEdgeBuckets::HalfEdgeBuckets(const Mesh& mesh)
    : start_(mesh.face_indices.data()),
      num_vertices_(mesh.num_vertices()),
      num_half_edges_(4 * mesh.num_faces()) {
  const std::size_t concurrency =
      static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  halves_ = concurrency >= 2 ? 2 : 1;
  vertex_parts_ = std::max<std::size_t>(1, concurrency / halves_);
  AssignTouched(first_, num_vertices_ + 1, 0u);
  AssignTouched(second_, halves_ == 2 ? num_vertices_ : 0, 0u);
  counts_[0] = first_.data();
  counts_[1] = second_.data();
}

// visit(slot, h) for each half-edge h starting at a vertex of [pass_lo, pass_hi), slot its
// start vertex's entry in the array of its half. Filling (`bucket` given), the slots are
// cursors into the bucket, whose entry 0 is cursor `base`, fetched ahead too.
template <class Visit>
void HalfEdgeBuckets::ForEachTask(std::size_t pass_lo, std::size_t pass_hi, std::uint32_t* bucket,
                                  std::uint32_t base, Visit&& visit) {
  const std::int32_t* const start = start_;
  const std::size_t num_vertices = num_vertices_, num_half_edges = num_half_edges_;
  const std::size_t halves = halves_, vertex_parts = vertex_parts_;
  tbb::parallel_for(std::size_t{0}, halves * vertex_parts, [&](std::size_t task) {
    const std::size_t half = task % halves, part = task / halves;
    std::uint32_t* const slots = counts_[half];
    const auto lo =
        static_cast<std::uint32_t>(std::max(pass_lo, num_vertices * part / vertex_parts));
    const auto hi =
        static_cast<std::uint32_t>(std::min(pass_hi, num_vertices * (part + 1) / vertex_parts));
    if (lo >= hi) return;
    const std::size_t from = num_half_edges * half / halves;
    const std::size_t to = num_half_edges * (half + 1) / halves;
    for (std::size_t h = from; h < to; ++h) {
      // The scattered slots of half-edges ahead, fetched early: the slot far ahead, then
      // (filling) the bucket entry it names nearer.
      if (h + 4 * kAhead < to) {
        const auto w = static_cast<std::uint32_t>(start[h + 4 * kAhead]);
        if (w - lo < hi - lo) __builtin_prefetch(&slots[w], 1);
      }
      if (bucket != nullptr && h + 2 * kAhead < to) {
        const auto w = static_cast<std::uint32_t>(start[h + 2 * kAhead]);
        if (w - lo < hi - lo) __builtin_prefetch(&bucket[slots[w] - base], 1);
      }
      const auto v = static_cast<std::uint32_t>(start[h]);
      if (v - lo < hi - lo) visit(slots[v], h);
    }
  });
}

Status HalfEdgeBuckets::Count(const std::string& source) {
  ForEachTask(0, num_vertices_, nullptr, 0, [](std::uint32_t& count, std::size_t) { ++count; });
  const std::size_t unused = LowestWhere(num_vertices_, num_vertices_, [&](std::size_t v) {
    return first_[v] == 0 && (halves_ == 1 || second_[v] == 0);
  });
  if (unused == num_vertices_) return Status::Ok();
  return Status::Error(fmt::format("{}: vertex {} is used by no face", source, unused));
}

// Counts into cursors: the first half's half-edges of v from its bucket's start, the second
// half's after them. The passes start at `pass_starts_`. Out of line, and on locals, so that
// the loop over the vertices keeps its values in registers (inlined into BuildQuadAdjacency,
// GCC 12 spills them: 4 more instructions per vertex).
[[gnu::noinline]] void HalfEdgeBuckets::PlanPasses(std::size_t bucket_entries) {
  const std::size_t num_vertices = num_vertices_, halves = halves_;
  std::uint32_t* const counts[2] = {counts_[0], counts_[1]};
  std::vector<std::size_t> pass_starts;
  std::uint32_t sum = 0, pass_sum = 0, largest_pass = 0;
  for (std::size_t v = 0; v < num_vertices; ++v) {
    std::uint32_t count = 0;
    for (std::size_t half = 0; half < halves; ++half) count += counts[half][v];
    if (pass_starts.empty() || (pass_sum > 0 && pass_sum + count > bucket_entries)) {
      pass_starts.push_back(v);
      pass_sum = 0;
    }
    pass_sum += count;
    largest_pass = std::max(largest_pass, pass_sum);
    for (std::size_t half = 0; half < halves; ++half) {
      const std::uint32_t in_half = counts[half][v];
      counts[half][v] = sum;
      sum += in_half;
    }
  }
  counts[0][num_vertices] = sum;
  pass_starts.push_back(num_vertices);
  pass_starts_ = std::move(pass_starts);
  ReserveTouched(storage_, largest_pass);
  storage_.resize(largest_pass);
}

void HalfEdgeBuckets::ResolvePass(std::size_t pass, QuadAdjacency& out,
                                  tbb::combinable<std::uint32_t>& lowest_bad) {
  const std::size_t lo = pass_starts_[pass], hi = pass_starts_[pass + 1];
  const std::uint32_t bucket_base = first_[lo];
  std::uint32_t* const bucket = storage_.data();
  // Every entry of the pass is written: no need to clear it first.
  ForEachTask(lo, hi, bucket, bucket_base,
              [bucket, bucket_base](std::uint32_t& cursor, std::size_t h) {
                bucket[cursor++ - bucket_base] = static_cast<std::uint32_t>(h);
              });
  // The cursors of the last half stopped at their bucket's end, the next bucket's start.
  std::uint32_t* const first = first_.data();
  if (halves_ == 2) {
    const std::uint32_t* bucket_ends = counts_[1];
    tbb::parallel_for(Range(lo + 1, std::max(lo + 1, hi), 1 << 14), [&](const Range& r) {
      for (std::size_t v = r.begin(); v < r.end(); ++v) first[v] = bucket_ends[v - 1];
    });
  } else {
    for (std::size_t v = hi; v-- > lo + 1;) first[v] = first[v - 1];
  }
  first[lo] = bucket_base;
  ResolveVertices(lo, hi, bucket_base, out, lowest_bad);
  // The lowest half-edge leaving each vertex: the first of its bucket, in place of the
  // bucket's start (the next pass reads only its own vertices' starts, and first[hi]).
  tbb::parallel_for(Range(lo, hi, 1 << 14), [&](const Range& r) {
    for (std::size_t v = r.begin(); v < r.end(); ++v) first[v] = bucket[first[v] - bucket_base];
  });
}

// Around vertex a, the quads of its half-edges a -> b_k (its bucket) also hold the half-edges
// c_k -> a that end there (each one's previous), so its bucket alone answers every question
// about the edges at a: the half-edges a -> b (same way) and b -> a (other way; the opposite
// when each is one). The lowest half-edge a -> b with two or more the same way, or with a < b
// and two or more the other way, names the error. A vertex is on a boundary when a half-edge
// leaving it or ending there has no opposite: as many end there as leave, and the opposites
// pair those that do, so it is enough to look at those leaving.
void HalfEdgeBuckets::ResolveVertices(std::size_t lo, std::size_t hi, std::uint32_t bucket_base,
                                      QuadAdjacency& out,
                                      tbb::combinable<std::uint32_t>& lowest_bad) const {
  const std::int32_t* const start = start_;
  const std::uint32_t* const first = first_.data();
  const std::uint32_t* const bucket = storage_.data();
  tbb::parallel_for(Range(lo, hi, 2048), [&](const Range& r) {
    std::uint32_t& bad = lowest_bad.local();
    std::vector<std::int32_t> ends, ins;  // b_k, c_k
    for (std::size_t a = r.begin(); a < r.end(); ++a) {
      // The quads of a vertex some way ahead, fetched while this one waits for its own.
      if (a + kAhead < r.end()) {
        for (std::uint32_t k = first[a + kAhead]; k < first[a + kAhead + 1]; ++k) {
          __builtin_prefetch(start + (bucket[k - bucket_base] & ~3u));
        }
      }
      const std::uint32_t* around = &bucket[first[a] - bucket_base];
      const std::uint32_t count = first[a + 1] - first[a];
      ends.resize(count);
      ins.resize(count);
      for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t h = around[k];
        ends[k] = start[QuadAdjacency::Next(h)];
        ins[k] = start[QuadAdjacency::Prev(h)];
      }
      bool border = false;
      for (std::uint32_t k = 0; k < count; ++k) {
        const std::int32_t b = ends[k];
        int same_way = 0, other_way = 0;
        std::uint32_t g = kNoHalfEdge;
        for (std::uint32_t j = 0; j < count; ++j) {
          same_way += ends[j] == b;
          if (ins[j] == b) {
            ++other_way;
            g = QuadAdjacency::Prev(around[j]);
          }
        }
        const std::uint32_t h = around[k];
        if (same_way > 1 || (b > static_cast<std::int32_t>(a) && other_way > 1)) {
          bad = std::min(bad, h);
        }
        const bool paired = same_way == 1 && other_way == 1;
        out.opposite[h] = paired ? g : kNoHalfEdge;
        border |= !paired;
      }
      out.valence[a] = static_cast<std::uint16_t>(std::min<std::uint32_t>(count, 65535));
      out.boundary[a] = border ? 1 : 0;
    }
  });
}

// The error of half-edge `bad` (ResolveVertices), once the buckets are gone: the faces along
// its edge, from every half-edge.
Status BadEdgeError(const Mesh& mesh, std::uint32_t bad) {
  const std::int32_t* start = mesh.face_indices.data();
  auto end = [start](std::size_t h) { return start[QuadAdjacency::Next(h)]; };
  const std::size_t num_half_edges = 4 * mesh.num_faces();
  const std::int32_t a = start[bad], b = end(bad);
  std::vector<std::uint32_t> same_way, other_way;
  for (std::uint32_t h = 0; h < num_half_edges; ++h) {
    if (start[h] == a && end(h) == b) same_way.push_back(h / 4);
    if (start[h] == b && end(h) == a) other_way.push_back(h / 4);
  }
  if (same_way.size() + other_way.size() > 2) {
    std::vector<std::uint32_t> faces = same_way;
    faces.insert(faces.end(), other_way.begin(), other_way.end());
    std::sort(faces.begin(), faces.end());
    return Status::Error(fmt::format("{}: edge {}-{} has more than two faces ({})", mesh.source, a,
                                     b, fmt::join(faces, ", ")));
  }
  return Status::Error(
      fmt::format("{}: faces {} and {} both run edge {}-{} from {} to {} (their windings disagree)",
                  mesh.source, same_way[0], same_way[1], a, b, a, b));
}

}  // namespace

StatusOr<QuadAdjacency> BuildQuadAdjacency(const Mesh& mesh, std::size_t bucket_entries) {
  DISPEX_CHECK(mesh.all_quads());
  const std::size_t num_vertices = mesh.num_vertices();
  const std::size_t num_half_edges = 4 * mesh.num_faces();
  DISPEX_CHECK_LT(num_half_edges, std::size_t{kNoHalfEdge});
  DISPEX_RETURN_IF_ERROR(CheckNoVertexTwice(mesh));

  HalfEdgeBuckets buckets(mesh);
  DISPEX_RETURN_IF_ERROR(buckets.Count(mesh.source));
  buckets.PlanPasses(bucket_entries);
  QuadAdjacency out;
  ReserveTouched(out.opposite, num_half_edges);
  out.opposite.resize(num_half_edges);
  AssignTouched(out.valence, num_vertices, std::uint16_t{0});
  AssignTouched(out.boundary, num_vertices, std::uint8_t{0});
  tbb::combinable<std::uint32_t> lowest_bad([] { return kNoHalfEdge; });
  for (std::size_t pass = 0; pass < buckets.num_passes(); ++pass) {
    buckets.ResolvePass(pass, out, lowest_bad);
  }
  buckets.ReleaseSecondHalf();
  const std::uint32_t bad =
      lowest_bad.combine([](std::uint32_t x, std::uint32_t y) { return std::min(x, y); });
  if (bad != kNoHalfEdge) return BadEdgeError(mesh, bad);
  out.first_half_edge = buckets.TakeFirstHalfEdges();
  return out;
}

std::vector<std::uint32_t> QuadComponents(const QuadAdjacency& adjacency,
                                          std::uint32_t& num_components) {
  const std::size_t num_faces = adjacency.opposite.size() / 4;
  std::vector<std::uint32_t> parent;
  AssignTouched(parent, num_faces, 0u);
  // Union-find with links from the larger root to the smaller, so that every root is the
  // lowest quad of its component whatever the order of the unions.
  auto find = [&](std::uint32_t x) {
    for (;;) {
      const std::uint32_t p = Load(parent[x]);
      if (p == x) return x;
      const std::uint32_t grand = Load(parent[p]);
      std::atomic_ref<std::uint32_t>(parent[x]).store(grand, std::memory_order_relaxed);
      x = grand;
    }
  };
  tbb::parallel_for(Range(0, num_faces, 1 << 14), [&](const Range& r) {
    for (std::size_t f = r.begin(); f < r.end(); ++f) parent[f] = static_cast<std::uint32_t>(f);
  });
  tbb::parallel_for(Range(0, num_faces, 1 << 12), [&](const Range& r) {
    for (std::size_t f = r.begin(); f < r.end(); ++f) {
      if (f + kAhead < r.end()) {  // the neighbours' parents some way ahead
        for (int k = 0; k < 4; ++k) {
          const std::uint32_t g = adjacency.opposite[4 * (f + kAhead) + k];
          if (g != kNoHalfEdge) __builtin_prefetch(&parent[g / 4]);
        }
      }
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t g = adjacency.opposite[4 * f + k];
        if (g == kNoHalfEdge || g / 4 < f) continue;
        std::uint32_t a = static_cast<std::uint32_t>(f), b = g / 4;
        for (;;) {
          a = find(a);
          b = find(b);
          if (a == b) break;
          if (a < b) std::swap(a, b);
          std::uint32_t expected = a;
          if (std::atomic_ref<std::uint32_t>(parent[a]).compare_exchange_strong(
                  expected, b, std::memory_order_relaxed)) {
            break;
          }
        }
      }
    }
  });
  tbb::parallel_for(Range(0, num_faces, 1 << 14), [&](const Range& r) {
    for (std::size_t f = r.begin(); f < r.end(); ++f) {
      std::atomic_ref<std::uint32_t>(parent[f]).store(find(static_cast<std::uint32_t>(f)),
                                                      std::memory_order_relaxed);
    }
  });
  // Roots precede their members, so one pass in order renumbers them.
  num_components = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    parent[f] = parent[f] == f ? num_components++ : parent[parent[f]];
  }
  return parent;
}

}  // namespace dispex::subdiv
