// MatchRefinedSculpt (dispex/correspondence.h). The steps, in the order Run calls them:
//  1. the sculpt's faces are quads, and its face and vertex counts name the level;
//  2. its half-edge adjacency (quad_adjacency.h; or the one MatchOptions::cache_dir keeps,
//     adjacency_cache.h) and components, which must match the base's
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
//
// The steps are members of Matcher (correspondence_matcher.h): 1 and 2 are here, 3 in
// correspondence_seeds.cpp, 4 to 6 in correspondence_grids.cpp.
#include "dispex/correspondence.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "core/check.h"
#include "core/parallel.h"
#include "core/system.h"
#include "dispex/version.h"
#include "subdiv/adjacency_cache.h"
#include "subdiv/correspondence_matcher.h"

namespace dispex::subdiv::matching {
namespace {

constexpr int kMaxLevels = 7;
constexpr double kDefaultOffsetFraction = 0.15;

}  // namespace

StatusOr<SculptCorrespondence> Matcher::Run() {
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

Status Matcher::RunSteps() {
  DISPEX_RETURN_IF_ERROR(CheckInputs());
  DISPEX_RETURN_IF_ERROR(FindLevel());
  FindBaseComponents();
  if (std::optional<MatchRecord> kept = KeptMatch()) {
    labelling_ = true;
    out_.labelling_from_cache = true;
    GridsFromCells(std::move(kept->cell_labels));
    if (options_.vertex_homes) DISPEX_RETURN_IF_ERROR(FindHomes());
    DISPEX_RETURN_IF_ERROR(CheckPositions(&kept->checks));
    KeepMatchAgain(*kept);
    return Status::Ok();
  }
  DISPEX_ASSIGN_OR_RETURN(adjacency_, subdiv::CachedQuadAdjacency(
                                          sculpt_, options_.cache_dir, out_.adjacency_from_cache,
                                          options_.cache_dir.empty() ? nullptr : &faces_key_));
  DISPEX_RETURN_IF_ERROR(MatchComponents());
  if (base_limit_.empty()) DISPEX_RETURN_IF_ERROR(EvaluateBaseVertices());
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
  DISPEX_RETURN_IF_ERROR(CheckPositions(nullptr));
  KeepMatch();
  if (!options_.vertex_homes) out_.vertex_faces = {};
  return Status::Ok();
}

// ---- A match kept in the cache folder ----------------------------------------------------

// What the kept match depends on besides the sculpt's positions: the sculpt's faces; the cage's
// topology, Ptex faces and limit surface (positions, tags, scheme and approximation options),
// and the limit points and normals of its vertices (the seeds' scores); the level, the offset
// limit, and the version (the rules).
Hash128 Matcher::MatchKey() const {
  Hasher h;
  h.Add(std::string_view("dispex match record 2")).Add(std::string_view(Version()));
  h.Add(faces_key_).Add(out_.levels).Add(offset_limit_);
  h.AddArray(std::span<const std::int32_t>(s_.first_ptex));
  h.AddArray(std::span<const std::uint8_t>(s_.ptex_hole));
  h.AddArray(std::span<const PtexAdjacency>(s_.adjacency));
  h.AddArray(std::span<const double>(s_.positions));
  const auto& level = s_.refiner->GetLevel(0);
  for (int f = 0; f < s_.num_base_faces(); ++f) {
    const auto vertices = level.GetFaceVertices(f);
    h.AddArray(std::span<const int>(&vertices[0], static_cast<std::size_t>(vertices.size())));
  }
  for (int e = 0; e < level.GetNumEdges(); ++e) h.Add(level.GetEdgeSharpness(e));
  for (int v = 0; v < level.GetNumVertices(); ++v) h.Add(level.GetVertexSharpness(v));
  const auto scheme = s_.refiner->GetSchemeOptions();
  h.Add(static_cast<int>(scheme.GetVtxBoundaryInterpolation()))
      .Add(static_cast<int>(scheme.GetCreasingMethod()))
      .Add(static_cast<int>(scheme.GetTriangleSubdivision()));
  h.Add(s_.options.approx_level_smooth)
      .Add(s_.options.approx_level_sharp)
      .Add(s_.options.regular_fast_path);
  h.AddArray(std::span<const Vec3d>(base_limit_)).AddArray(std::span<const Vec3d>(base_normal_));
  return h.Digest();
}

std::optional<MatchRecord> Matcher::KeptMatch() {
  if (options_.cache_dir.empty() || !sculpt_.all_quads()) return std::nullopt;
  // A cage whose limit points cannot be evaluated fails where a match without a cache does.
  if (!EvaluateBaseVertices().ok()) {
    base_limit_.clear();
    return std::nullopt;
  }
  faces_key_ = SculptFacesKey(sculpt_);
  match_key_ = MatchKey();
  logging_ = true;
  std::optional<MatchRecord> kept = ReadMatchRecord(MatchRecordPath(options_.cache_dir, match_key_),
                                                    match_key_, sculpt_.num_faces());
  if (!kept || !SeedsStillChosen(*kept) || !ChecksFitTheGrids(kept->checks)) return std::nullopt;
  return kept;
}

// Kept when every component's seeding was logged (a match that failed a seeding and found its
// labelling again without the logs keeps nothing).
void Matcher::KeepMatch() const {
  if (!logging_ || seed_logs_.size() != components_.size()) return;
  WriteMatchRecord(MatchRecordPath(options_.cache_dir, match_key_), match_key_, out_.levels,
                   out_.cell_labels, seed_logs_, checks_);
}

void Matcher::KeepMatchAgain(MatchRecord& kept) {
  if (16 * out_.faces_checked_again <= static_cast<std::size_t>(cage_.num_ptex_faces())) return;
  checks_.own = std::move(kept.checks.own);
  WriteMatchRecord(MatchRecordPath(options_.cache_dir, match_key_), match_key_, out_.levels,
                   out_.cell_labels, kept.components, checks_);
}

// ---- 1. Inputs and level ------------------------------------------------------------------

Status Matcher::CheckInputs() {
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
      return Status::Error(fmt::format("{}: face {} has {} vertices: a refined cage has only quads",
                                       where_, f, sculpt_.face_size(f)));
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
  offset_limit_ = options_.max_offset > 0 ? options_.max_offset : kDefaultOffsetFraction * diagonal;
  out_.offset_limit = offset_limit_;
  return Status::Ok();
}

Status Matcher::FindLevel() {
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

void Matcher::FindBaseComponents() {
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
}

Status Matcher::MatchComponents() {
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
Status Matcher::CompareComponents() {
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
    return Status::Error(
        fmt::format("{}: the components differ: the sculpt has {}; {} refined {} times has {}",
                    where_, describe(sculpt_sizes), s_.source, out_.levels, describe(base_sizes)));
  }
  return Status::Ok();
}

}  // namespace dispex::subdiv::matching

namespace dispex {

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
      subdiv::matching::Matcher matcher(surface, sculpt, options);
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
    auto mirrored = subdiv::matching::Matcher(surface, reversed, options).Run();
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
