// Step 3 of MatchRefinedSculpt (correspondence.cpp): per base component, the labelling of
// each Ptex face's (0,0) cell, from a seed vertex and the sculpt vertices nearest it.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "core/check.h"
#include "core/first_touch.h"
#include "subdiv/correspondence_matcher.h"

namespace dispex::subdiv::matching {
namespace {

// Sculpt vertices tried per component as the image of its seed vertex, nearest first.
constexpr int kCandidates = 8;
// Labellings are ranked by their offsets at base vertices, the part along the limit normal
// weighing this much: sculpting moves vertices mostly along the normal, while a labelling
// shifted by some cells (a symmetry of tori and tubes, whose refinements have no
// extraordinary vertex to pin them) moves them across it.
constexpr double kAlongNormalWeight = 1.0 / 16;

}  // namespace

// The limit point of every base vertex a face with a surface uses, from its first corner.
Status Matcher::EvaluateBaseVertices() {
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
                        Status st = Evaluator().EvaluatePoints(PtexFaceId(ptex), uv, xyz, normals);
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
void Matcher::IndexSculptVertexClasses() {
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

// From cell `from` to cell `to` of one grid, along u first; stuck_ keeps the cell it could
// not leave and the edge it could not cross.
Label Matcher::Walk(Label label, GridPoint from, GridPoint to) {
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

Label Matcher::Stuck(Label label, int edge) {
  stuck_ = {label, edge};
  return kNoLabel;
}

// Face `label` / 4 in Ptex face `ptex` has no neighbour across the cell's edge `edge`.
std::string Matcher::NoNeighbourMessage(Label label, int edge, int ptex) const {
  const int n = cage_.grid_size(ptex);
  return fmt::format(
      "{}: face {} does not fit the grid of Ptex face {} ({}x{}): it has no neighbour across "
      "its edge {}-{}, where the refined base has one",
      where_, label / 4, ptex, n, n, VertexAt(label, edge), VertexAt(label, edge + 1));
}

std::string Matcher::NoNeighbourMessage(int ptex) const {
  return NoNeighbourMessage(stuck_.label, stuck_.edge, ptex);
}

// Labels a Ptex face's (0,0) cell and checks the base vertex at its (0,0) corner; false stops
// the attempt (attempt.failure set, or attempt.pruned).
bool Matcher::SeedFace(int p, Label label, double prune_above, SeedAttempt& attempt) {
  seeds_[p] = label;
  queue_.push_back(p);
  ++attempt.seeded;
  const int w = cage_.CornerVertex(p, 0);
  const std::int32_t x = VertexAt(label, 0);
  if (adjacency_.valence[x] != cage_.valence(w) ||
      (adjacency_.boundary[x] != 0) != cage_.boundary(w)) {
    attempt.failure = Status::Error(fmt::format(
        "{}: vertex {} has valence {}{} where base vertex {} has {}{} (Ptex face {})", where_, x,
        adjacency_.valence[x], adjacency_.boundary[x] ? " on a boundary" : "", w, cage_.valence(w),
        cage_.boundary(w) ? " on a boundary" : "", p));
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
  if (met_log_ != nullptr) {  // the positions are judged once every labelling is logged
    met_log_->met_w.push_back(w);
    met_log_->met_x.push_back(x);
    return true;
  }
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
}

// The labelling with `start` in Ptex face p0's cell at `corner`, spread over the component
// breadth first through the Ptex faces' edges.
SeedAttempt Matcher::TrySeed(const BaseComponent& component, int p0, int corner, Label start,
                             double prune_above) {
  SeedAttempt attempt;
  for (int p : component.faces) seeds_[p] = kNoLabel;
  for (int w : component.vertices) base_sculpt_[w] = -1;
  centre_sculpt_.assign(static_cast<std::size_t>(s_.num_base_faces()), -1);
  const auto fail = [&](std::string message) {
    attempt.failure = Status::Error(std::move(message));
    return attempt;
  };

  queue_.clear();
  const int n0 = cage_.grid_size(p0);
  const Label origin0 = Walk(start, CornerCell(n0, corner), {0, 0});
  if (origin0 == kNoLabel) return fail(NoNeighbourMessage(p0));
  if (!SeedFace(p0, origin0, prune_above, attempt)) return attempt;
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
      if (!SeedFace(across.face, origin, prune_above, attempt)) return attempt;
    }
  }
  DISPEX_CHECK_EQ(attempt.seeded, component.faces.size());
  attempt.complete = CheckFarCorners(component, attempt);
  return attempt;
}

// The far corner (n, n) of every grid: base vertex 2 of a quad, or the centre of an n-gon,
// which its n sub-faces share. A labelling that only the (0,0) corners agree with -- a vector
// sculpt's overhangs can move vertices so far that one ranks first -- fails here (false, with
// attempt.failure set).
bool Matcher::CheckFarCorners(const BaseComponent& component, SeedAttempt& attempt) {
  for (int p : component.faces) {
    const int n = cage_.grid_size(p);
    const Label far = Walk(seeds_[p], {0, 0}, {n - 1, n - 1});
    if (far == kNoLabel) {
      attempt.failure = Status::Error(NoNeighbourMessage(p));
      return false;
    }
    const std::int32_t x = VertexAt(far, 2);
    const int w = cage_.CornerVertex(p, 2);
    const int base_face = s_.ptex_base[p];
    const int valence = w >= 0 ? cage_.valence(w) : s_.face_size(base_face);
    std::int32_t& known = w >= 0 ? base_sculpt_[w] : centre_sculpt_[base_face];
    if (adjacency_.valence[x] != valence || (known >= 0 && known != x)) {
      attempt.failure = Status::Error(fmt::format(
          "{}: face {} does not fit the grid of Ptex face {}: its far corner, vertex {}, is "
          "not the {} of the refined base",
          where_, far / 4, p, x, w >= 0 ? fmt::format("base vertex {}", w) : "face centre"));
      return false;
    }
    known = x;
  }
  return true;
}

// The half-edges leaving sculpt vertex x, one per quad around it (one fan).
std::vector<std::uint32_t> Matcher::HalfEdgesAround(std::uint32_t x) const {
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
double Matcher::SeedScore(std::int32_t x, int w) const {
  const Vec3d offset = Position(x) - base_limit_[w];
  const double along = Dot(offset, base_normal_[w]);
  return Dot(offset, offset) - (1 - kAlongNormalWeight) * along * along;
}

std::vector<std::uint32_t> Matcher::ClassVertices(int vertex_class, std::uint64_t cells) const {
  // From its bucket, or (one component) a scan of every vertex in blocks, joined in order.
  if (!class_vertices_.empty()) {
    const std::uint32_t* begin = class_vertices_.data() + class_offsets_[vertex_class];
    std::vector<std::uint32_t> out(begin, begin + ClassSize(vertex_class));
    if (!components_trusted_) {
      std::erase_if(out, [&](std::uint32_t x) {
        const std::uint32_t component = sculpt_component_[adjacency_.first_half_edge[x] / 4];
        return sculpt_component_matched_[component] || sculpt_component_faces_[component] != cells;
      });
    }
    return out;
  }
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  const std::size_t num_vertices = sculpt_.num_vertices();
  std::vector<std::vector<std::uint32_t>> blocks((num_vertices + kBlock - 1) / kBlock);
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t b) {
    for (std::size_t x = b * kBlock; x < std::min(num_vertices, (b + 1) * kBlock); ++x) {
      if (SculptClass(x) == vertex_class) blocks[b].push_back(static_cast<std::uint32_t>(x));
    }
  });
  std::vector<std::uint32_t> out;
  for (const auto& block : blocks) out.insert(out.end(), block.begin(), block.end());
  return out;
}

// Of `class_vertices`, those within the offset limit of base vertex w's limit point, at most
// kCandidates, best SeedScore first (ties by id).
Matcher::CandidateList Matcher::Candidates(std::span<const std::uint32_t> class_vertices,
                                           int w) const {
  using Ranked = std::pair<double, std::uint32_t>;
  const auto keep_best = [](std::vector<Ranked>& list) {
    const std::size_t kept = std::min<std::size_t>(list.size(), kCandidates);
    std::partial_sort(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(kept), list.end());
    list.resize(kept);
  };
  // In blocks (a class may be every vertex), each block's best, then the best of those.
  constexpr std::size_t kBlock = std::size_t{1} << 16;
  const std::size_t blocks = (class_vertices.size() + kBlock - 1) / kBlock;
  std::vector<std::vector<Ranked>> best(blocks);
  std::vector<Ranked> nearest_of(blocks, Ranked{HUGE_VAL, 0});
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t k = b * kBlock; k < std::min(class_vertices.size(), (b + 1) * kBlock); ++k) {
      const std::uint32_t x = class_vertices[k];
      const auto vertex = static_cast<std::int32_t>(x);
      const double d2 = Distance2(Position(vertex), base_limit_[w]);
      nearest_of[b] = std::min(nearest_of[b], Ranked{d2, x});
      if (d2 > offset_limit_ * offset_limit_) continue;
      best[b].emplace_back(SeedScore(vertex, w), x);
    }
    keep_best(best[b]);
  });
  std::vector<Ranked> ranked;
  Ranked nearest{HUGE_VAL, 0};
  for (std::size_t b = 0; b < blocks; ++b) {
    ranked.insert(ranked.end(), best[b].begin(), best[b].end());
    nearest = std::min(nearest, nearest_of[b]);
  }
  keep_best(ranked);
  CandidateList out;
  for (const Ranked& r : ranked) out.vertices.push_back(r.second);
  if (nearest.first < HUGE_VAL) {
    out.nearest = nearest.second;
    out.nearest_distance = std::sqrt(nearest.first);
  }
  return out;
}

// Manifold, of the class rarest in the sculpt, lowest id.
std::pair<int, const RefinedCage::Corner*> Matcher::SeedVertex(
    const BaseComponent& component) const {
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
  return {seed_vertex, place};
}

Status Matcher::SeedComponent(const BaseComponent& component) {
  seeds_.resize(cage_.num_ptex_faces(), kNoLabel);
  base_sculpt_.resize(cage_.num_vertices(), -1);
  const auto [seed_vertex, place] = SeedVertex(component);
  const int valence = cage_.valence(seed_vertex);
  const bool boundary = cage_.boundary(seed_vertex);
  const std::vector<std::uint32_t> class_vertices =
      ClassVertices(VertexClass(valence, boundary), component.cells);
  const CandidateList candidates = Candidates(class_vertices, seed_vertex);
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
  if (logging_) {
    ComponentSeeds log;
    log.seed_vertex = seed_vertex;
    log.class_vertices = class_vertices;
    log.candidates = candidates.vertices;
    SeedComponentLogged(component, place, candidates, log);
    if (log.chosen >= 0) {
      seed_logs_.push_back(std::move(log));
      return Status::Ok();
    }
    // No labelling fits: the match fails. Tried again as without a cache folder, for the
    // failure it names.
    logging_ = false;
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

void Matcher::SeedComponentLogged(const BaseComponent& component, const RefinedCage::Corner* place,
                                  const CandidateList& candidates, ComponentSeeds& log) {
  std::vector<Label> starts;
  for (std::uint32_t x : candidates.vertices) {
    for (std::uint32_t h : HalfEdgesAround(x)) {
      starts.push_back((h & ~3u) | ((h - static_cast<std::uint32_t>(place->corner)) & 3u));
      met_log_ = &log;
      const SeedAttempt attempt =
          TrySeed(component, place->ptex, place->corner, starts.back(), HUGE_VAL);
      met_log_ = nullptr;
      log.walk_complete.push_back(attempt.complete ? 1 : 0);
      log.met_end.push_back(static_cast<std::uint32_t>(log.met_w.size()));
    }
  }
  log.chosen = ChosenLabelling(log);
  if (log.chosen < 0) return;
  // The chosen labelling walked once more, for its seeds.
  const SeedAttempt chosen = TrySeed(component, place->ptex, place->corner,
                                     starts[static_cast<std::size_t>(log.chosen)], HUGE_VAL);
  DISPEX_CHECK(chosen.complete);
  if (!components_trusted_) {
    sculpt_component_matched_[sculpt_component_[seeds_[component.faces[0]] / 4]] = 1;
  }
}

int Matcher::ChosenLabelling(const ComponentSeeds& log) const {
  int best = -1;
  double best_score = 0;
  std::uint32_t begin = 0;
  for (std::size_t a = 0; a < log.walk_complete.size(); ++a) {
    const std::uint32_t end = log.met_end[a];
    const double prune_above = best >= 0 ? best_score : HUGE_VAL;
    double score = 0;
    bool stopped = false;
    for (std::uint32_t k = begin; k < end && !stopped; ++k) {
      const std::int32_t w = log.met_w[k], x = log.met_x[k];
      stopped = Distance2(Position(x), base_limit_[w]) > offset_limit_ * offset_limit_;
      if (stopped) break;
      score += SeedScore(x, w);
      stopped = score > prune_above;
    }
    begin = end;
    if (stopped || !log.walk_complete[a]) continue;
    if (best < 0 || score < best_score) {
      best = static_cast<int>(a);
      best_score = score;
    }
  }
  return best;
}

// Whether every component's seeding, re-run on the kept logs with these positions, ranks the
// same candidates and chooses the same labelling.
bool Matcher::SeedsStillChosen(const MatchRecord& kept) const {
  if (kept.levels != out_.levels || kept.components.size() != components_.size()) return false;
  for (std::size_t k = 0; k < components_.size(); ++k) {
    const ComponentSeeds& log = kept.components[k];
    if (log.seed_vertex < 0 || log.seed_vertex >= cage_.num_vertices()) return false;
    for (std::uint32_t x : log.class_vertices) {
      if (x >= sculpt_.num_vertices()) return false;
    }
    for (std::int32_t w : log.met_w) {
      if (w < 0 || w >= cage_.num_vertices()) return false;
    }
    for (std::int32_t x : log.met_x) {
      if (x < 0 || static_cast<std::size_t>(x) >= sculpt_.num_vertices()) return false;
    }
    if (Candidates(log.class_vertices, log.seed_vertex).vertices != log.candidates ||
        ChosenLabelling(log) != log.chosen) {
      return false;
    }
  }
  return true;
}

}  // namespace dispex::subdiv::matching
