// MatchRefinedSculpt (dispex/correspondence.h). The steps, in the order Run calls them:
//  1. the sculpt's faces are quads, and its face and vertex counts name the level;
//  2. its half-edge adjacency (quad_adjacency.h) and components, which must match the base's
//     (the Ptex faces with a surface, connected through their edges) by size; against a base
//     of one component they are compared only when a later step fails, since step 5 proves
//     a sculpt that passes it connected;
//  3. per base component, a seed: a base vertex of the rarest (valence, boundary) class, the
//     sculpt vertices of that class nearest its limit point, and for each quad around them
//     the labelling that puts it in the corner cell of a Ptex face there. A breadth-first walk
//     over the component's Ptex faces then finds each face's (0,0) cell, checking on the way
//     the valence and the position of the sculpt vertex at each base vertex it meets; the
//     labelling with the least sum of squared offsets wins (the refinement's symmetries are
//     told apart by positions only);
//  4. per Ptex face, in parallel, the grid filled row by row from its (0,0) cell, each quad's
//     corners checked against the grid points already set;
//  5. every sculpt quad in exactly one cell, and equal grid points wherever Ptex faces meet
//     (along edges and at base vertices). With equal counts this makes the sculpt the
//     refinement, face for face and vertex for vertex;
//  6. each vertex's home, and the position check on a lattice of grid lines.
//
// A cell's label is the sculpt half-edge along its bottom edge, from its (i, j) corner to
// (i+1, j): the quad is label / 4 and its corner label % 4 sits at (i, j); the cell's edge e
// (0: bottom, 1: right, 2: top, 3: left) is the quad's half-edge from corner label + e.
#include "dispex/correspondence.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <tuple>
#include <utility>

#include "core/check.h"
#include "core/first_error.h"
#include "core/first_touch.h"
#include "core/parallel.h"
#include "core/system.h"
#include "core/vec3.h"
#include "subdiv/quad_adjacency.h"
#include "subdiv/refined_cage.h"
#include "subdiv/surface_impl.h"

namespace dispex {
namespace {

using subdiv::GridPoint;
using subdiv::kNoHalfEdge;
using subdiv::PtexEdgePlace;
using subdiv::QuadAdjacency;
using subdiv::RefinedCage;

using Label = std::uint32_t;
constexpr Label kNoLabel = kNoHalfEdge;
constexpr int kMaxLevels = 7;
// Sculpt vertices tried per component as the image of its seed vertex, nearest first.
constexpr int kCandidates = 8;
// The position check reads every grid point of grids up to this size, and on larger ones the
// points on every (n / kCheckedLines)-th row and column (the borders included): on level 6 of
// a 941-quad cage (3.9M vertices, one core) 23% of the vertices in 0.06 s, where all of them
// take 0.40 s, a third of the whole match.
constexpr int kCheckedLines = 8;
// Valences above this share one class when picking seeds (they are still compared exactly).
constexpr int kMaxClassValence = 1023;
constexpr double kDefaultOffsetFraction = 0.15;
// Labellings are ranked by their offsets at base vertices, the part along the limit normal
// weighing this much: sculpting moves vertices mostly along the normal, while a labelling
// shifted by some cells (a symmetry of tori and tubes, whose refinements have no
// extraordinary vertex to pin them) moves them across it.
constexpr double kAlongNormalWeight = 1.0 / 16;

int VertexClass(int valence, bool boundary) {
  return 2 * std::min(valence, kMaxClassValence) + (boundary ? 1 : 0);
}

GridPoint CornerCell(int n, int corner) {
  static constexpr int kAt[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  return {kAt[corner][0] * (n - 1), kAt[corner][1] * (n - 1)};
}

GridPoint CornerPoint(int n, int corner) {
  static constexpr int kAt[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  return {kAt[corner][0] * n, kAt[corner][1] * n};
}

// Edge-connected Ptex faces with a surface.
struct BaseComponent {
  std::vector<int> faces;     // ascending
  std::vector<int> vertices;  // base vertices at their corners, ascending
  std::uint64_t cells = 0;
};

// One labelling tried as a component's seed (Matcher::TrySeed).
struct SeedAttempt {
  bool complete = false;   // every Ptex face of the component seeded, all checks passed
  bool pruned = false;     // stopped: already worse than the best complete one
  std::size_t seeded = 0;  // Ptex faces seeded before it stopped
  double score = 0;        // SeedScore summed over the base vertices met
  Status failure;
};

class Matcher {
 public:
  Matcher(const LimitSurface& surface, const Mesh& sculpt, const MatchOptions& options)
      : surface_(surface),
        s_(SurfaceImpl(surface)),
        sculpt_(sculpt),
        options_(options),
        where_(sculpt.source.empty() ? std::string("sculpt") : sculpt.source) {}

  StatusOr<SculptCorrespondence> Run() {
    Stopwatch clock;
    Status status = RunSteps();
    // One base component: the sculpt's components were taken on trust (MatchComponents);
    // where a later step failed, a sculpt of other components is named as such.
    if (!status.ok() && components_trusted_) {
      Status components = CompareComponents();
      if (!components.ok()) {
        labelling_ = false;
        return components;
      }
    }
    DISPEX_RETURN_IF_ERROR(status);
    out_.components = components_.size();
    out_.seconds = clock.seconds();
    return std::move(out_);
  }

  // Whether Run got as far as labelling the quads: then a failure may be a sculpt whose faces
  // all wind the other way, which the counts, edges and components cannot tell.
  bool labelling() const { return labelling_; }

 private:
  Status RunSteps() {
    DISPEX_RETURN_IF_ERROR(CheckInputs());
    DISPEX_RETURN_IF_ERROR(FindLevel());
    DISPEX_ASSIGN_OR_RETURN(adjacency_, subdiv::BuildQuadAdjacency(sculpt_));
    DISPEX_RETURN_IF_ERROR(MatchComponents());
    DISPEX_RETURN_IF_ERROR(EvaluateBaseVertices());
    IndexSculptVertexClasses();
    labelling_ = true;
    for (const BaseComponent& component : components_) {
      DISPEX_RETURN_IF_ERROR(SeedComponent(component));
    }
    sculpt_component_ = {};
    class_vertices_ = {};
    DISPEX_RETURN_IF_ERROR(FillGrids());
    adjacency_ = {};
    DISPEX_RETURN_IF_ERROR(CheckFaces());
    DISPEX_RETURN_IF_ERROR(CheckSeams());
    DISPEX_RETURN_IF_ERROR(FindHomes());
    return CheckPositions();
  }

  // ---- 1. Inputs and level ------------------------------------------------------------------

  Status CheckInputs() {
    if (options_.max_levels < 0 || options_.max_levels > kMaxLevels) {
      return Status::Error(
          fmt::format("max_levels = {}: must be 0..{}", options_.max_levels, kMaxLevels));
    }
    if (!(std::isfinite(options_.max_offset) && options_.max_offset >= 0)) {
      return Status::Error(
          fmt::format("max_offset = {}: must be a finite length >= 0", options_.max_offset));
    }
    if (options_.threads < 0) {
      return Status::Error(fmt::format("threads = {}: must be >= 0", options_.threads));
    }
    if (sculpt_.num_faces() == 0) return Status::Error(where_ + ": the sculpt has no faces");
    for (std::size_t f = 0; !sculpt_.all_quads() && f < sculpt_.num_faces(); ++f) {
      if (sculpt_.face_size(f) != 4) {
        return Status::Error(
            fmt::format("{}: face {} has {} vertices: a refined cage has only quads", where_, f,
                        sculpt_.face_size(f)));
      }
    }
    if (sculpt_.num_faces() >= (std::size_t{1} << 30)) {
      return Status::Error(fmt::format("{}: {} faces: more than matching handles (2^30)", where_,
                                       sculpt_.num_faces()));
    }
    if (s_.stats.ptex_faces == s_.stats.hole_ptex_faces) {
      return Status::Error(s_.source + ": no face of the cage has a surface");
    }
    DISPEX_ASSIGN_OR_RETURN(cage_, RefinedCage::Build(s_));
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (std::size_t k = 0; k < s_.positions.size(); ++k) {
      lo[k % 3] = std::min(lo[k % 3], s_.positions[k]);
      hi[k % 3] = std::max(hi[k % 3], s_.positions[k]);
    }
    const double diagonal =
        std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
    offset_limit_ =
        options_.max_offset > 0 ? options_.max_offset : kDefaultOffsetFraction * diagonal;
    out_.offset_limit = offset_limit_;
    return Status::Ok();
  }

  Status FindLevel() {
    const std::uint64_t faces = sculpt_.num_faces(), vertices = sculpt_.num_vertices();
    const auto gap = [&](int level) {
      const std::uint64_t f = cage_.CountFaces(level);
      return f > faces ? f - faces : faces - f;
    };
    int nearest = -1;
    for (int level = 0; level <= options_.max_levels; ++level) {
      const std::uint64_t level_faces = cage_.CountFaces(level);
      if (level_faces == 0) continue;
      if (level_faces == faces) {
        const std::uint64_t level_vertices = cage_.CountVertices(level);
        if (level_vertices != vertices) {
          return Status::Error(fmt::format(
              "{}: counts fit no level of {}: {} faces are level {}'s, but {} vertices are not "
              "its {}",
              where_, s_.source, faces, level, vertices, level_vertices));
        }
        cage_.SetLevels(level);
        out_.levels = level;
        return Status::Ok();
      }
      if (nearest < 0 || gap(level) < gap(nearest)) nearest = level;
    }
    if (nearest < 0) {
      return Status::Error(fmt::format(
          "{}: counts fit no level of {}: it has faces other than quads, so no level 0, and "
          "max_levels is 0",
          where_, s_.source));
    }
    return Status::Error(fmt::format(
        "{}: counts fit no level of {} (0..{}): {} faces and {} vertices; the nearest, level "
        "{}, has {} faces and {} vertices",
        where_, s_.source, options_.max_levels, faces, vertices, nearest, cage_.CountFaces(nearest),
        cage_.CountVertices(nearest)));
  }

  // ---- 2. Components ------------------------------------------------------------------------

  Status MatchComponents() {
    const int num_ptex = cage_.num_ptex_faces();
    std::vector<int> component_of(num_ptex, -1);
    std::vector<int> queue;
    for (int start = 0; start < num_ptex; ++start) {
      if (cage_.is_hole(start) || component_of[start] >= 0) continue;
      const int id = static_cast<int>(components_.size());
      BaseComponent& component = components_.emplace_back();
      queue.assign(1, start);
      component_of[start] = id;
      for (std::size_t next = 0; next < queue.size(); ++next) {
        const int p = queue[next];
        const int n = cage_.grid_size(p);
        component.cells += static_cast<std::uint64_t>(n) * n;
        for (int corner = 0; corner < 4; ++corner) {
          const int w = cage_.CornerVertex(p, corner);
          if (w >= 0) component.vertices.push_back(w);
        }
        for (int edge = 0; edge < 4; ++edge) {
          const int q = cage_.Across(p, edge, 0, true).face;
          if (q >= 0 && component_of[q] < 0) {
            component_of[q] = id;
            queue.push_back(q);
          }
        }
      }
      component.faces = queue;
      std::sort(component.faces.begin(), component.faces.end());
      std::sort(component.vertices.begin(), component.vertices.end());
      component.vertices.erase(std::unique(component.vertices.begin(), component.vertices.end()),
                               component.vertices.end());
    }
    ptex_component_ = std::move(component_of);
    // With one base component, every quad of a sculpt of the right count must lie in its
    // grids, which the fill and face checks prove: the sculpt's components are compared only
    // where a step fails (Run), sparing a pass over the quads.
    if (components_.size() == 1) {
      components_trusted_ = true;
      return Status::Ok();
    }
    return CompareComponents();
  }

  // The sculpt's connected components against the base's, by size. Needs adjacency_, which
  // it builds again once FillGrids released it.
  Status CompareComponents() {
    if (adjacency_.opposite.empty()) {
      DISPEX_ASSIGN_OR_RETURN(adjacency_, subdiv::BuildQuadAdjacency(sculpt_));
    }
    std::uint32_t count = 0;
    sculpt_component_ = subdiv::QuadComponents(adjacency_, count);
    sculpt_component_faces_.assign(count, 0);
    for (std::uint32_t c : sculpt_component_) ++sculpt_component_faces_[c];
    sculpt_component_matched_.assign(count, 0);

    std::vector<std::uint64_t> base_sizes, sculpt_sizes = sculpt_component_faces_;
    for (const BaseComponent& c : components_) base_sizes.push_back(c.cells);
    std::sort(base_sizes.begin(), base_sizes.end());
    std::sort(sculpt_sizes.begin(), sculpt_sizes.end());
    if (base_sizes != sculpt_sizes) {
      const auto describe = [](const std::vector<std::uint64_t>& sizes) {
        constexpr std::size_t kShown = 6;
        return fmt::format(
            "{} connected component{} of {}{} faces", sizes.size(), sizes.size() == 1 ? "" : "s",
            fmt::join(sizes.begin(), sizes.begin() + std::min(sizes.size(), kShown), ", "),
            sizes.size() > kShown ? ", ..." : "");
      };
      return Status::Error(fmt::format(
          "{}: the components differ: the sculpt has {}; {} refined {} times has {}", where_,
          describe(sculpt_sizes), s_.source, out_.levels, describe(base_sizes)));
    }
    return Status::Ok();
  }

  // ---- 3. Seeds -----------------------------------------------------------------------------

  LimitEvaluator& Evaluator() {
    auto& slot = evaluators_.local();
    if (!slot) slot = std::make_unique<LimitEvaluator>(surface_);
    return *slot;
  }

  // The limit point of every base vertex a face with a surface uses, from its first corner.
  Status EvaluateBaseVertices() {
    struct Request {
      int ptex, corner, vertex;
    };
    std::vector<Request> requests;
    for (int w = 0; w < cage_.num_vertices(); ++w) {
      if (cage_.corners_begin(w) == cage_.corners_end(w)) continue;
      requests.push_back({cage_.corners_begin(w)->ptex, cage_.corners_begin(w)->corner, w});
    }
    std::sort(requests.begin(), requests.end(),
              [](const Request& a, const Request& b) { return a.ptex < b.ptex; });
    std::vector<std::size_t> starts;
    for (std::size_t k = 0; k < requests.size(); ++k) {
      if (k == 0 || requests[k].ptex != requests[k - 1].ptex) starts.push_back(k);
    }
    starts.push_back(requests.size());
    base_limit_.assign(cage_.num_vertices(), Vec3d{});
    base_normal_.assign(cage_.num_vertices(), Vec3d{});
    FirstError error;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, starts.size() - 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<float> uv, xyz, normals;
                        for (std::size_t g = r.begin(); g < r.end(); ++g) {
                          uv.clear();
                          for (std::size_t k = starts[g]; k < starts[g + 1]; ++k) {
                            const GridPoint at = CornerPoint(1, requests[k].corner);
                            uv.push_back(static_cast<float>(at.i));
                            uv.push_back(static_cast<float>(at.j));
                          }
                          xyz.resize(uv.size() / 2 * 3);
                          normals.resize(xyz.size());
                          const int ptex = requests[starts[g]].ptex;
                          Status st =
                              Evaluator().EvaluatePoints(PtexFaceId(ptex), uv, xyz, normals);
                          if (!st.ok()) {
                            error.Record(ptex, st);
                            continue;
                          }
                          for (std::size_t k = starts[g]; k < starts[g + 1]; ++k) {
                            const float* p = &xyz[3 * (k - starts[g])];
                            const float* n = &normals[3 * (k - starts[g])];
                            base_limit_[requests[k].vertex] = Vec3d{p[0], p[1], p[2]};
                            base_normal_[requests[k].vertex] = Vec3d{n[0], n[1], n[2]};
                          }
                        }
                      });
    return error.failed() ? error.status() : Status::Ok();
  }

  // Sculpt vertices counted by VertexClass, for the seed's class, and bucketed by it for the
  // candidates when there are several components (one needs a single scan of the vertices).
  void IndexSculptVertexClasses() {
    const int num_classes = VertexClass(kMaxClassValence, true) + 1;
    const std::size_t num_vertices = sculpt_.num_vertices();
    tbb::combinable<std::vector<std::uint32_t>> counts(
        [num_classes] { return std::vector<std::uint32_t>(num_classes + 1, 0); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_vertices, 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<std::uint32_t>& mine = counts.local();
                        for (std::size_t x = r.begin(); x < r.end(); ++x) {
                          ++mine[SculptClass(x) + 1];
                        }
                      });
    class_offsets_.assign(num_classes + 1, 0);
    counts.combine_each([&](const std::vector<std::uint32_t>& mine) {
      for (int c = 0; c <= num_classes; ++c) class_offsets_[c] += mine[c];
    });
    for (int c = 0; c < num_classes; ++c) class_offsets_[c + 1] += class_offsets_[c];
    if (components_.size() == 1) return;
    std::vector<std::uint32_t> next(class_offsets_.begin(), class_offsets_.end() - 1);
    AssignTouched(class_vertices_, num_vertices, 0u);
    for (std::size_t x = 0; x < num_vertices; ++x) {
      class_vertices_[next[SculptClass(x)]++] = static_cast<std::uint32_t>(x);
    }
  }
  int SculptClass(std::size_t x) const {
    return VertexClass(adjacency_.valence[x], adjacency_.boundary[x] != 0);
  }
  std::size_t ClassSize(int vertex_class) const {
    return class_offsets_[vertex_class + 1] - class_offsets_[vertex_class];
  }

  Label Cross(Label label, int edge, int their_edge) const {
    const std::uint32_t g = adjacency_.opposite[(label & ~3u) | ((label + edge) & 3u)];
    if (g == kNoHalfEdge) return kNoLabel;
    return (g & ~3u) | ((g - static_cast<std::uint32_t>(their_edge)) & 3u);
  }
  Label Step(Label label, int edge) const { return Cross(label, edge, (edge + 2) & 3); }
  // From cell `from` to cell `to` of one grid, along u first; stuck_ keeps the cell it could
  // not leave and the edge it could not cross.
  Label Walk(Label label, GridPoint from, GridPoint to) {
    for (int i = from.i; i != to.i; i += to.i > i ? 1 : -1) {
      const int edge = to.i > i ? 1 : 3;
      const Label next = Step(label, edge);
      if (next == kNoLabel) return Stuck(label, edge);
      label = next;
    }
    for (int j = from.j; j != to.j; j += to.j > j ? 1 : -1) {
      const int edge = to.j > j ? 2 : 0;
      const Label next = Step(label, edge);
      if (next == kNoLabel) return Stuck(label, edge);
      label = next;
    }
    return label;
  }
  Label Stuck(Label label, int edge) {
    stuck_ = {label, edge};
    return kNoLabel;
  }
  std::int32_t VertexAt(Label label, int corner) const {
    return sculpt_.face_indices[(label & ~3u) | ((label + corner) & 3u)];
  }
  Vec3d Position(std::int32_t vertex) const { return ToVec3d(sculpt_.positions[vertex]); }

  // Face `label` / 4 in Ptex face `ptex` has no neighbour across the cell's edge `edge`.
  std::string NoNeighbourMessage(Label label, int edge, int ptex) const {
    const int n = cage_.grid_size(ptex);
    return fmt::format(
        "{}: face {} does not fit the grid of Ptex face {} ({}x{}): it has no neighbour across "
        "its edge {}-{}, where the refined base has one",
        where_, label / 4, ptex, n, n, VertexAt(label, edge), VertexAt(label, edge + 1));
  }
  std::string NoNeighbourMessage(int ptex) const {
    return NoNeighbourMessage(stuck_.label, stuck_.edge, ptex);
  }

  // The labelling with `start` in Ptex face p0's cell at `corner`, spread over the component.
  SeedAttempt TrySeed(const BaseComponent& component, int p0, int corner, Label start,
                      double prune_above) {
    SeedAttempt attempt;
    for (int p : component.faces) seeds_[p] = kNoLabel;
    for (int w : component.vertices) base_sculpt_[w] = -1;
    centre_sculpt_.assign(static_cast<std::size_t>(s_.num_base_faces()), -1);
    const auto fail = [&](std::string message) {
      attempt.failure = Status::Error(std::move(message));
      return attempt;
    };
    // Labels a Ptex face's (0,0) cell and checks the base vertex at its (0,0) corner.
    const auto seed = [&](int p, Label label) -> bool {
      seeds_[p] = label;
      queue_.push_back(p);
      ++attempt.seeded;
      const int w = cage_.CornerVertex(p, 0);
      const std::int32_t x = VertexAt(label, 0);
      if (adjacency_.valence[x] != cage_.valence(w) ||
          (adjacency_.boundary[x] != 0) != cage_.boundary(w)) {
        attempt.failure = Status::Error(fmt::format(
            "{}: vertex {} has valence {}{} where base vertex {} has {}{} (Ptex face {})", where_,
            x, adjacency_.valence[x], adjacency_.boundary[x] ? " on a boundary" : "", w,
            cage_.valence(w), cage_.boundary(w) ? " on a boundary" : "", p));
        return false;
      }
      if (base_sculpt_[w] >= 0) {
        if (base_sculpt_[w] == x) return true;
        attempt.failure = Status::Error(fmt::format(
            "{}: face {} does not fit the grid of Ptex face {}: its corner at base vertex {} is "
            "vertex {}, where another grid has vertex {}",
            where_, label / 4, p, w, x, base_sculpt_[w]));
        return false;
      }
      base_sculpt_[w] = x;
      const double d2 = Distance2(Position(x), base_limit_[w]);
      if (d2 > offset_limit_ * offset_limit_) {
        attempt.failure = Status::Error(fmt::format(
            "{}: the position check failed: vertex {} is {:.6g} from its home at base vertex {} "
            "(Ptex face {}), more than max_offset {:.6g}",
            where_, x, std::sqrt(d2), w, p, offset_limit_));
        return false;
      }
      attempt.score += SeedScore(x, w);
      if (attempt.score > prune_above) {
        attempt.pruned = true;
        return false;
      }
      return true;
    };

    queue_.clear();
    const int n0 = cage_.grid_size(p0);
    const Label origin0 = Walk(start, CornerCell(n0, corner), {0, 0});
    if (origin0 == kNoLabel) return fail(NoNeighbourMessage(p0));
    if (!seed(p0, origin0)) return attempt;
    for (std::size_t next = 0; next < queue_.size(); ++next) {
      const int p = queue_[next];
      const int n = cage_.grid_size(p);
      for (int edge = 0; edge < 4; ++edge) {
        // The cell of this edge nearest (0,0).
        const int position = edge >= 2 ? n - 1 : 0;
        const PtexEdgePlace across = cage_.Across(p, edge, position, true);
        if (across.face < 0 || seeds_[across.face] != kNoLabel) continue;
        const Label here = Walk(seeds_[p], {0, 0}, RefinedCage::OnEdge(n, edge, position, true));
        if (here == kNoLabel) return fail(NoNeighbourMessage(p));
        const Label there = Cross(here, edge, across.edge);
        if (there == kNoLabel) {
          return fail(
              fmt::format("{} (in Ptex face {})", NoNeighbourMessage(here, edge, p), across.face));
        }
        const int m = cage_.grid_size(across.face);
        const Label origin =
            Walk(there, RefinedCage::OnEdge(m, across.edge, across.position, true), {0, 0});
        if (origin == kNoLabel) return fail(NoNeighbourMessage(across.face));
        if (!seed(across.face, origin)) return attempt;
      }
    }
    DISPEX_CHECK_EQ(attempt.seeded, component.faces.size());
    // The far corner (n, n) of every grid: base vertex 2 of a quad, or the centre of an n-gon,
    // which its n sub-faces share. A labelling that only the (0,0) corners agree with -- a
    // vector sculpt's overhangs can move vertices so far that one ranks first -- fails here.
    for (int p : component.faces) {
      const int n = cage_.grid_size(p);
      const Label far = Walk(seeds_[p], {0, 0}, {n - 1, n - 1});
      if (far == kNoLabel) return fail(NoNeighbourMessage(p));
      const std::int32_t x = VertexAt(far, 2);
      const int w = cage_.CornerVertex(p, 2);
      const int base_face = s_.ptex_base[p];
      const int valence = w >= 0 ? cage_.valence(w) : s_.face_size(base_face);
      std::int32_t& known = w >= 0 ? base_sculpt_[w] : centre_sculpt_[base_face];
      if (adjacency_.valence[x] != valence || (known >= 0 && known != x)) {
        return fail(fmt::format(
            "{}: face {} does not fit the grid of Ptex face {}: its far corner, vertex {}, is "
            "not the {} of the refined base",
            where_, far / 4, p, x, w >= 0 ? fmt::format("base vertex {}", w) : "face centre"));
      }
      known = x;
    }
    attempt.complete = true;
    return attempt;
  }

  // The half-edges leaving sculpt vertex x, one per quad around it (one fan).
  std::vector<std::uint32_t> HalfEdgesAround(std::uint32_t x) const {
    const std::uint32_t first = adjacency_.first_half_edge[x];
    const std::size_t most = adjacency_.valence[x];
    std::vector<std::uint32_t> out{first};
    std::uint32_t h = first;
    bool closed = false;
    while (out.size() < most) {
      const std::uint32_t g = adjacency_.opposite[QuadAdjacency::Prev(h)];
      if (g == kNoHalfEdge) break;
      if (g == first) {
        closed = true;
        break;
      }
      out.push_back(g);
      h = g;
    }
    h = first;
    while (!closed && out.size() < most) {
      const std::uint32_t g = adjacency_.opposite[h];
      if (g == kNoHalfEdge) break;
      h = QuadAdjacency::Next(g);
      if (h == first) break;
      out.push_back(h);
    }
    return out;
  }

  // How far sculpt vertex x is from the limit point of base vertex w, for ranking labellings.
  double SeedScore(std::int32_t x, int w) const {
    const Vec3d offset = Position(x) - base_limit_[w];
    const double along = Dot(offset, base_normal_[w]);
    return Dot(offset, offset) - (1 - kAlongNormalWeight) * along * along;
  }

  struct CandidateList {
    std::vector<std::uint32_t> vertices;  // best SeedScore first (ties by id)
    std::int64_t nearest = -1;            // the nearest of the class, for messages
    double nearest_distance = HUGE_VAL;
  };

  // The sculpt vertices of `vertex_class` in unmatched components of `cells` quads within
  // the offset limit of base vertex w's limit point, at most kCandidates.
  CandidateList Candidates(int vertex_class, int w, std::uint64_t cells) const {
    using Ranked = std::pair<double, std::uint32_t>;
    struct Found {
      std::vector<Ranked> best;
      Ranked nearest{HUGE_VAL, 0};
    };
    const auto keep_best = [](std::vector<Ranked>& list) {
      std::sort(list.begin(), list.end());
      if (list.size() > kCandidates) list.resize(kCandidates);
    };
    tbb::combinable<Found> found;
    // The class's vertices: from its bucket, or (one component) all vertices of the class.
    const bool bucketed = !class_vertices_.empty();
    const std::uint32_t* begin =
        bucketed ? class_vertices_.data() + class_offsets_[vertex_class] : nullptr;
    const std::size_t count = bucketed ? ClassSize(vertex_class) : sculpt_.num_vertices();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        Found& mine = found.local();
                        for (std::size_t k = r.begin(); k < r.end(); ++k) {
                          const auto x = bucketed ? begin[k] : static_cast<std::uint32_t>(k);
                          if (!bucketed && SculptClass(x) != vertex_class) continue;
                          if (!components_trusted_) {
                            const std::uint32_t component =
                                sculpt_component_[adjacency_.first_half_edge[x] / 4];
                            if (sculpt_component_matched_[component] ||
                                sculpt_component_faces_[component] != cells) {
                              continue;
                            }
                          }
                          const auto vertex = static_cast<std::int32_t>(x);
                          const double d2 = Distance2(Position(vertex), base_limit_[w]);
                          mine.nearest = std::min(mine.nearest, Ranked{d2, x});
                          if (d2 > offset_limit_ * offset_limit_) continue;
                          mine.best.emplace_back(SeedScore(vertex, w), x);
                          if (mine.best.size() >= 4 * kCandidates) keep_best(mine.best);
                        }
                      });
    std::vector<Ranked> all;
    Ranked nearest{HUGE_VAL, 0};
    found.combine_each([&](const Found& list) {
      all.insert(all.end(), list.best.begin(), list.best.end());
      nearest = std::min(nearest, list.nearest);
    });
    keep_best(all);
    CandidateList out;
    for (const Ranked& ranked : all) out.vertices.push_back(ranked.second);
    if (nearest.first < HUGE_VAL) {
      out.nearest = nearest.second;
      out.nearest_distance = std::sqrt(nearest.first);
    }
    return out;
  }

  Status SeedComponent(const BaseComponent& component) {
    seeds_.resize(cage_.num_ptex_faces(), kNoLabel);
    base_sculpt_.resize(cage_.num_vertices(), -1);
    // The seed vertex: manifold, of the class rarest in the sculpt, lowest id.
    int seed_vertex = -1;
    for (int w : component.vertices) {
      const auto rank = [&](int v) {
        return std::make_pair(cage_.non_manifold(v),
                              ClassSize(VertexClass(cage_.valence(v), cage_.boundary(v))));
      };
      if (seed_vertex < 0 || rank(w) < rank(seed_vertex)) seed_vertex = w;
    }
    const int id = static_cast<int>(&component - components_.data());
    const RefinedCage::Corner* place = cage_.corners_begin(seed_vertex);
    while (ptex_component_[place->ptex] != id) ++place;
    const int valence = cage_.valence(seed_vertex);
    const bool boundary = cage_.boundary(seed_vertex);
    const CandidateList candidates =
        Candidates(VertexClass(valence, boundary), seed_vertex, component.cells);
    if (candidates.nearest < 0) {
      return Status::Error(fmt::format(
          "{}: no {} vertex of valence {} like base vertex {} (Ptex face {}) in a component of "
          "{} faces",
          where_, boundary ? "boundary" : "interior", valence, seed_vertex, place->ptex,
          component.cells));
    }
    if (candidates.vertices.empty()) {
      return Status::Error(fmt::format(
          "{}: the position check failed: no {} vertex of valence {} is within max_offset "
          "{:.6g} of base vertex {}'s limit point (Ptex face {}); the nearest, vertex {}, is "
          "{:.6g} away",
          where_, boundary ? "boundary" : "interior", valence, offset_limit_, seed_vertex,
          place->ptex, candidates.nearest, candidates.nearest_distance));
    }

    std::optional<SeedAttempt> best, furthest_failure;
    std::vector<Label> best_seeds;
    for (std::uint32_t x : candidates.vertices) {
      for (std::uint32_t h : HalfEdgesAround(x)) {
        const Label start = (h & ~3u) | ((h - static_cast<std::uint32_t>(place->corner)) & 3u);
        const double prune_above = best ? best->score : HUGE_VAL;
        SeedAttempt attempt = TrySeed(component, place->ptex, place->corner, start, prune_above);
        if (attempt.complete) {
          if (!best || attempt.score < best->score) {
            best = attempt;
            best_seeds.clear();
            for (int p : component.faces) best_seeds.push_back(seeds_[p]);
          }
        } else if (!attempt.pruned &&
                   (!furthest_failure || attempt.seeded > furthest_failure->seeded)) {
          furthest_failure = std::move(attempt);
        }
      }
    }
    if (!best) {
      DISPEX_CHECK(furthest_failure.has_value());
      return furthest_failure->failure;
    }
    for (std::size_t k = 0; k < component.faces.size(); ++k) {
      seeds_[component.faces[k]] = best_seeds[k];
    }
    if (!components_trusted_) sculpt_component_matched_[sculpt_component_[best_seeds[0] / 4]] = 1;
    return Status::Ok();
  }

  // ---- 4. Grids -----------------------------------------------------------------------------

  Status FillGrids() {
    const int num_ptex = cage_.num_ptex_faces();
    out_.grid_sizes.resize(num_ptex);
    out_.grid_offsets.assign(num_ptex + 1, 0);
    cell_offsets_.assign(num_ptex + 1, 0);
    for (int p = 0; p < num_ptex; ++p) {
      const std::int64_t n = cage_.grid_size(p);
      out_.grid_sizes[p] = static_cast<std::int32_t>(n);
      out_.grid_offsets[p + 1] = out_.grid_offsets[p] + (n ? (n + 1) * (n + 1) : 0);
      cell_offsets_[p + 1] = cell_offsets_[p] + n * n;
    }
    DISPEX_CHECK_EQ(static_cast<std::size_t>(cell_offsets_.back()), sculpt_.num_faces());
    AssignTouched(cells_, sculpt_.num_faces(), Label{0});  // all written when FillGrids succeeds
    AssignTouched(out_.grid_vertices, static_cast<std::size_t>(out_.grid_offsets.back()),
                  VertexId());
    FirstError error;
    tbb::parallel_for(tbb::blocked_range<int>(0, num_ptex), [&](const tbb::blocked_range<int>& r) {
      for (int p = r.begin(); p < r.end(); ++p) {
        if (cage_.grid_size(p) > 0) FillGrid(p, error);
      }
    });
    return error.failed() ? error.status() : Status::Ok();
  }

  void FillGrid(int p, FirstError& error) {
    const int n = cage_.grid_size(p);
    Label* cells = &cells_[cell_offsets_[p]];
    VertexId* grid = &out_.grid_vertices[out_.grid_offsets[p]];
    Label row = seeds_[p];
    for (int j = 0; j < n; ++j) {
      if (j > 0) {
        const Label up = Step(row, 2);
        if (up == kNoLabel) {
          error.Record(cell_offsets_[p] + (j - 1) * n,
                       Status::Error(NoNeighbourMessage(row, 2, p)));
          return;
        }
        row = up;
      }
      Label label = row;
      for (int i = 0; i < n; ++i) {
        if (i > 0) {
          const Label right = Step(label, 1);
          if (right == kNoLabel) {
            error.Record(cell_offsets_[p] + j * n + i - 1,
                         Status::Error(NoNeighbourMessage(label, 1, p)));
            return;
          }
          label = right;
        }
        cells[j * n + i] = label;
        for (int corner = 0; corner < 4; ++corner) {
          const int gi = i + (corner == 1 || corner == 2), gj = j + (corner >= 2);
          VertexId& slot = grid[gj * (n + 1) + gi];
          const VertexId vertex(VertexAt(label, corner));
          if (!slot.valid()) {
            slot = vertex;
          } else if (slot != vertex) {
            error.Record(cell_offsets_[p] + j * n + i,
                         Status::Error(fmt::format(
                             "{}: face {} does not fit the grid of Ptex face {} ({}x{}): as cell "
                             "({}, {}) it puts vertex {} at grid point ({}, {}), which holds "
                             "vertex {}",
                             where_, label / 4, p, n, n, i, j, vertex.value, gi, gj, slot.value)));
            return;
          }
        }
      }
    }
  }

  // ---- 5. Faces, seams ----------------------------------------------------------------------

  // Where cell `cell` (an index into cells_) is: its Ptex face and (i, j).
  std::tuple<int, int, int> CellPlace(std::int64_t cell) const {
    const int p =
        static_cast<int>(std::upper_bound(cell_offsets_.begin(), cell_offsets_.end(), cell) -
                         cell_offsets_.begin() - 1);
    const int n = cage_.grid_size(p);
    const std::int64_t local = cell - cell_offsets_[p];
    return {p, static_cast<int>(local % n), static_cast<int>(local / n)};
  }

  // Each quad claims its slot (its face_ptex entry, or its bit when there are no per-face
  // tables); a quad claimed twice fails, named by a slower pass that finds the lowest cell
  // holding a quad an earlier cell holds too. The cells then become cell_labels.
  Status CheckFaces() {
    const std::size_t num_faces = sculpt_.num_faces();
    std::vector<std::uint64_t> claimed;
    if (options_.face_tables) {
      AssignTouched(out_.face_ptex, num_faces, PtexFaceId());
      AssignTouched(out_.face_cell, num_faces, std::int32_t{-1});
      AssignTouched(out_.face_rotation, num_faces, std::uint8_t{0});
    } else {
      AssignTouched(claimed, (num_faces + 63) / 64, std::uint64_t{0});
    }
    std::atomic<bool> twice{false};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, cage_.num_ptex_faces()), [&](const tbb::blocked_range<int>& r) {
          for (int p = r.begin(); p < r.end(); ++p) {
            const std::int64_t begin = cell_offsets_[p], end = cell_offsets_[p + 1];
            for (std::int64_t c = begin; c < end; ++c) {
              const std::uint32_t face = cells_[c] / 4;
              if (!options_.face_tables) {
                const std::uint64_t bit = std::uint64_t{1} << (face % 64);
                if (std::atomic_ref<std::uint64_t>(claimed[face / 64])
                        .fetch_or(bit, std::memory_order_relaxed) &
                    bit) {
                  twice.store(true, std::memory_order_relaxed);
                }
                continue;
              }
              std::int32_t unclaimed = -1;
              if (!std::atomic_ref<std::int32_t>(out_.face_ptex[face].value)
                       .compare_exchange_strong(unclaimed, p, std::memory_order_relaxed)) {
                twice.store(true, std::memory_order_relaxed);
                continue;
              }
              out_.face_cell[face] = static_cast<std::int32_t>(c - begin);
              out_.face_rotation[face] = static_cast<std::uint8_t>(cells_[c] & 3);
            }
          }
        });
    if (twice.load()) return FaceInTwoCells();
    out_.cell_labels = std::move(cells_);
    cells_ = {};
    return Status::Ok();
  }

  Status FaceInTwoCells() const {
    const std::size_t num_faces = sculpt_.num_faces();
    std::vector<std::uint32_t> first_cell(num_faces, std::numeric_limits<std::uint32_t>::max());
    for (std::size_t c = 0; c < num_faces; ++c) {
      std::uint32_t& first = first_cell[cells_[c] / 4];
      if (first != std::numeric_limits<std::uint32_t>::max()) {
        const auto [p0, i0, j0] = CellPlace(first);
        const auto [p1, i1, j1] = CellPlace(static_cast<std::int64_t>(c));
        return Status::Error(fmt::format(
            "{}: face {} does not fit the grid of Ptex face {}: it is cell ({}, {}) there and "
            "cell ({}, {}) of Ptex face {}",
            where_, cells_[c] / 4, p1, i1, j1, i0, j0, p0));
      }
      first = static_cast<std::uint32_t>(c);
    }
    DISPEX_CHECK(false);
    return Status::Ok();
  }

  VertexId GridVertex(int p, GridPoint at) const {
    const int n = out_.grid_sizes[p];
    return out_
        .grid_vertices[out_.grid_offsets[p] + static_cast<std::int64_t>(at.j) * (n + 1) + at.i];
  }

  // Grid points shared by two Ptex faces hold one vertex: along their common edges, and at
  // every base vertex (whose faces need not be connected through edges around it).
  Status CheckSeams() {
    FirstError error;
    tbb::parallel_for(tbb::blocked_range<int>(0, cage_.num_ptex_faces()),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int p = r.begin(); p < r.end(); ++p) CheckSeamsOf(p, error);
                      });
    if (error.failed()) return error.status();
    tbb::parallel_for(tbb::blocked_range<int>(0, cage_.num_vertices()),
                      [&](const tbb::blocked_range<int>& r) {
                        for (int w = r.begin(); w < r.end(); ++w) CheckBaseVertex(w, error);
                      });
    return error.failed() ? error.status() : Status::Ok();
  }

  void CheckSeamsOf(int p, FirstError& error) const {
    const int n = cage_.grid_size(p);
    for (int edge = 0; edge < 4 && n > 0; ++edge) {
      for (int position = 0; position <= n; ++position) {
        const PtexEdgePlace across = cage_.Across(p, edge, position, false);
        if (across.face < 0) continue;
        const GridPoint here = RefinedCage::OnEdge(n, edge, position, false);
        const GridPoint there =
            RefinedCage::OnEdge(cage_.grid_size(across.face), across.edge, across.position, false);
        const VertexId a = GridVertex(p, here), b = GridVertex(across.face, there);
        if (a == b) continue;
        error.Record(
            p, Status::Error(fmt::format(
                   "{}: the grids of Ptex faces {} and {} disagree where they meet: "
                   "vertex {} at ({}, {}) of the first, vertex {} at ({}, {}) of the "
                   "second",
                   where_, p, across.face, a.value, here.i, here.j, b.value, there.i, there.j)));
        return;
      }
    }
  }

  void CheckBaseVertex(int w, FirstError& error) const {
    const RefinedCage::Corner* first = cage_.corners_begin(w);
    for (const RefinedCage::Corner* c = first; c != cage_.corners_end(w); ++c) {
      const VertexId a =
          GridVertex(first->ptex, CornerPoint(cage_.grid_size(first->ptex), first->corner));
      const VertexId b = GridVertex(c->ptex, CornerPoint(cage_.grid_size(c->ptex), c->corner));
      if (a == b) continue;
      error.Record(w,
                   Status::Error(fmt::format(
                       "{}: vertices {} and {} both sit at base vertex {} (corners of Ptex faces "
                       "{} and {}): the sculpt is not the base refined",
                       where_, a.value, b.value, w, first->ptex, c->ptex)));
      return;
    }
  }

  // ---- 6. Homes and positions ---------------------------------------------------------------

  // A vertex inside a Ptex face is on that grid only; one on a border takes the lowest of the
  // faces whose grids hold it.
  Status FindHomes() {
    const std::size_t num_vertices = sculpt_.num_vertices();
    constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::max();
    AssignTouched(out_.vertex_faces, num_vertices, PtexFaceId(kNone));
    AssignTouched(out_.vertex_uvs, 2 * num_vertices, 0.0f);
    // Row by row; with `borders_only`, the points on the grid's border only.
    const auto each_grid_point = [&](bool borders_only, auto&& visit) {
      tbb::parallel_for(tbb::blocked_range<int>(0, cage_.num_ptex_faces()),
                        [&](const tbb::blocked_range<int>& r) {
                          for (int p = r.begin(); p < r.end(); ++p) {
                            const int n = out_.grid_sizes[p];
                            for (int j = 0; j <= n && n > 0; ++j) {
                              const bool border_row = j == 0 || j == n;
                              const int step = borders_only && !border_row ? n : 1;
                              for (int i = 0; i <= n; i += step) {
                                const bool border = border_row || i == 0 || i == n;
                                visit(p, n, i, j, border, GridVertex(p, {i, j}).value);
                              }
                            }
                          }
                        });
    };
    const auto set_uv = [&](int n, int i, int j, std::int32_t v) {
      out_.vertex_uvs[2 * static_cast<std::size_t>(v)] = static_cast<float>(i) / n;
      out_.vertex_uvs[2 * static_cast<std::size_t>(v) + 1] = static_cast<float>(j) / n;
    };
    each_grid_point(false, [&](int p, int n, int i, int j, bool border, std::int32_t v) {
      std::atomic_ref<std::int32_t> home(out_.vertex_faces[v].value);
      if (!border) {
        home.store(p, std::memory_order_relaxed);
        set_uv(n, i, j, v);
        return;
      }
      std::int32_t current = home.load(std::memory_order_relaxed);
      while (p < current && !home.compare_exchange_weak(current, p, std::memory_order_relaxed)) {
      }
    });
    each_grid_point(true, [&](int p, int n, int i, int j, bool border, std::int32_t v) {
      if (border && out_.vertex_faces[v].value == p) set_uv(n, i, j, v);
    });
    for (std::size_t v = 0; v < num_vertices; ++v) {
      if (out_.vertex_faces[v].value == kNone) {
        return Status::Error(fmt::format(
            "{}: vertex {} is on no grid: other vertices sit at two grid points", where_, v));
      }
    }
    return Status::Ok();
  }

  struct FaceOffsets {
    double max = -1, sum_squares = 0;
    std::int32_t worst = -1;
    std::size_t count = 0;
  };

  Status CheckPositions() {
    const int num_ptex = cage_.num_ptex_faces();
    std::vector<FaceOffsets> offsets(num_ptex);
    FirstError error;
    tbb::parallel_for(tbb::blocked_range<int>(0, num_ptex), [&](const tbb::blocked_range<int>& r) {
      std::vector<float> uv, xyz;
      std::vector<std::int32_t> vertices;
      for (int p = r.begin(); p < r.end(); ++p) {
        const int n = cage_.grid_size(p);
        if (n == 0) continue;
        const int step = n <= kCheckedLines ? 1 : n / kCheckedLines;
        uv.clear();
        vertices.clear();
        for (int j = 0; j <= n; ++j) {
          for (int i = 0; i <= n; i += (j % step == 0) ? 1 : step) {
            const VertexId v = GridVertex(p, {i, j});
            if (out_.vertex_faces[v.value].value != p) continue;
            vertices.push_back(v.value);
            uv.push_back(static_cast<float>(i) / n);
            uv.push_back(static_cast<float>(j) / n);
          }
        }
        if (vertices.empty()) continue;
        xyz.resize(3 * vertices.size());
        Status st = Evaluator().EvaluatePoints(PtexFaceId(p), uv, xyz, {});
        if (!st.ok()) {
          error.Record(p, st);
          continue;
        }
        FaceOffsets& mine = offsets[p];
        for (std::size_t k = 0; k < vertices.size(); ++k) {
          const Vec3d limit{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
          const double d2 = Distance2(Position(vertices[k]), limit);
          mine.sum_squares += d2;
          if (d2 > mine.max) {
            mine.max = d2;
            mine.worst = vertices[k];
          }
        }
        mine.count = vertices.size();
      }
    });
    if (error.failed()) return error.status();
    double max = -1, sum_squares = 0;
    std::int32_t worst = -1;
    for (const FaceOffsets& face : offsets) {
      out_.checked_vertices += face.count;
      sum_squares += face.sum_squares;
      if (face.max > max) {
        max = face.max;
        worst = face.worst;
      }
    }
    out_.max_offset = std::sqrt(std::max(max, 0.0));
    out_.rms_offset = out_.checked_vertices ? std::sqrt(sum_squares / out_.checked_vertices) : 0;
    out_.worst_vertex = VertexId(worst);
    if (out_.max_offset > offset_limit_) {
      const PtexFaceId home = out_.vertex_faces[worst];
      return Status::Error(fmt::format(
          "{}: the position check failed: vertex {} is {:.6g} from its home on Ptex face {} at "
          "({}, {}), more than max_offset {:.6g} (is the cage the one the sculpt was refined "
          "from, with the same tags?)",
          where_, worst, out_.max_offset, home.value, out_.vertex_uvs[2 * worst],
          out_.vertex_uvs[2 * worst + 1], offset_limit_));
    }
    return Status::Ok();
  }

  bool labelling_ = false;
  const LimitSurface& surface_;
  const LimitSurface::Impl& s_;
  const Mesh& sculpt_;
  const MatchOptions options_;
  const std::string where_;
  double offset_limit_ = 0;

  RefinedCage cage_;
  QuadAdjacency adjacency_;
  std::vector<BaseComponent> components_;
  std::vector<int> ptex_component_;              // per Ptex face, -1 for holes
  bool components_trusted_ = false;              // see MatchComponents
  std::vector<std::uint32_t> sculpt_component_;  // per sculpt quad
  std::vector<std::uint64_t> sculpt_component_faces_;
  std::vector<std::uint8_t> sculpt_component_matched_;
  std::vector<Vec3d> base_limit_, base_normal_;  // per base vertex
  std::vector<std::uint32_t> class_offsets_, class_vertices_;
  tbb::enumerable_thread_specific<std::unique_ptr<LimitEvaluator>> evaluators_;

  // Seeding state: per Ptex face the label of its (0,0) cell, per base vertex the sculpt vertex
  // met there; the walk's queue.
  std::vector<Label> seeds_;
  std::vector<std::int32_t> base_sculpt_;
  std::vector<std::int32_t> centre_sculpt_;  // per base face: the sculpt vertex at its centre
  std::vector<int> queue_;
  struct {
    Label label = kNoLabel;
    int edge = 0;
  } stuck_;

  std::vector<std::int64_t> cell_offsets_;  // per Ptex face, into cells_
  std::vector<Label> cells_;

  SculptCorrespondence out_;
};

}  // namespace

Float3 SculptPointAt(const SculptCorrespondence& correspondence, const Mesh& sculpt,
                     PtexFaceId face, float u, float v) {
  const int n = correspondence.grid_size(face);
  DISPEX_CHECK_GT(n, 0);
  const auto clamp = [](float t) { return t > 0 ? (t < 1 ? t : 1.0f) : 0.0f; };  // NaN: 0
  const float x = clamp(u) * n, y = clamp(v) * n;
  const int i = std::min(static_cast<int>(x), n - 1), j = std::min(static_cast<int>(y), n - 1);
  const float s = x - i, t = y - j;
  const Float3& p00 = sculpt.positions[correspondence.vertex(face, i, j).value];
  const Float3& p10 = sculpt.positions[correspondence.vertex(face, i + 1, j).value];
  const Float3& p11 = sculpt.positions[correspondence.vertex(face, i + 1, j + 1).value];
  const Float3& p01 = sculpt.positions[correspondence.vertex(face, i, j + 1).value];
  const float w00 = (1 - s) * (1 - t), w10 = s * (1 - t), w11 = s * t, w01 = (1 - s) * t;
  return {w00 * p00.x + w10 * p10.x + w11 * p11.x + w01 * p01.x,
          w00 * p00.y + w10 * p10.y + w11 * p11.y + w01 * p01.y,
          w00 * p00.z + w10 * p10.z + w11 * p11.z + w01 * p01.z};
}

StatusOr<SculptCorrespondence> MatchRefinedSculpt(const LimitSurface& surface, const Mesh& sculpt,
                                                  const MatchOptions& options) {
  std::optional<StatusOr<SculptCorrespondence>> result;
  RunWithThreads(options.threads, [&] {
    bool labelling = false;
    {
      Matcher matcher(surface, sculpt, options);
      result.emplace(matcher.Run());
      labelling = matcher.labelling();
    }
    if (result->ok() || !labelling) return;
    // Flipped normals: match the sculpt reversed when asked to, else say so rather than which
    // quad the labelling stumbled on.
    Mesh reversed;
    reversed.source = sculpt.source;
    reversed.positions = sculpt.positions;
    reversed.face_offsets = sculpt.face_offsets;
    reversed.face_indices = sculpt.face_indices;
    ReverseWinding(reversed);
    auto mirrored = Matcher(surface, reversed, options).Run();
    if (!mirrored.ok()) return;
    if (options.accept_reversed) {
      mirrored->reversed = true;
      result.emplace(std::move(mirrored));
      return;
    }
    result.emplace(Status::Error(fmt::format(
        "{}: every face winds the other way from the cage's (flipped normals); reversed, it "
        "is the cage refined {} times",
        sculpt.source.empty() ? "sculpt" : sculpt.source, mirrored->levels)));
  });
  return std::move(*result);
}

}  // namespace dispex
