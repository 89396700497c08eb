// The matcher behind MatchRefinedSculpt (dispex/correspondence.h), one instance per sculpt.
// Its steps, and how a cell's label names a sculpt quad, are described in correspondence.cpp;
// they are defined in three files:
//   correspondence.cpp          1. inputs and level, 2. components, and Run
//   correspondence_seeds.cpp    3. seeds: the labelling of each component's (0,0) cells, and
//                               whether a kept match's labelling is still the one chosen
//   correspondence_grids.cpp    4. grids, 5. faces and seams, 6. homes and positions
// The small accessors the grid loops call per cell stay here, inline.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/first_error.h"
#include "core/vec3.h"
#include "dispex/correspondence.h"
#include "dispex/mesh.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "subdiv/match_cache.h"
#include "subdiv/quad_adjacency.h"
#include "subdiv/refined_cage.h"
#include "subdiv/surface_impl.h"

namespace dispex::subdiv::matching {

// A cell's label: the sculpt half-edge along its bottom edge (correspondence.cpp).
using Label = std::uint32_t;
inline constexpr Label kNoLabel = kNoHalfEdge;
// Valences above this share one class when picking seeds (they are still compared exactly).
inline constexpr int kMaxClassValence = 1023;

inline int VertexClass(int valence, bool boundary) {
  return 2 * std::min(valence, kMaxClassValence) + (boundary ? 1 : 0);
}

inline GridPoint CornerCell(int n, int corner) {
  static constexpr int kAt[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  return {kAt[corner][0] * (n - 1), kAt[corner][1] * (n - 1)};
}

inline GridPoint CornerPoint(int n, int corner) {
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

  StatusOr<SculptCorrespondence> Run();

  // Whether Run got as far as labelling the quads: then a failure may be a sculpt whose faces
  // all wind the other way, which the counts, edges and components cannot tell.
  bool labelling() const { return labelling_; }

 private:
  Status RunSteps();

  // ---- 1. Inputs and level (correspondence.cpp) ---------------------------------------------
  Status CheckInputs();
  Status FindLevel();

  // ---- 2. Components (correspondence.cpp) ---------------------------------------------------
  void FindBaseComponents();
  Status MatchComponents();
  Status CompareComponents();

  // ---- A match kept in the cache folder (correspondence.cpp, match_cache.h) -----------------
  Hash128 MatchKey() const;
  // The kept match when it is this sculpt's.
  std::optional<MatchRecord> KeptMatch();
  void KeepMatch() const;
  // After a kept match was taken: written again with the checks as they are now, when more
  // than 1/16 of the faces were measured again (so that edits piling up do not make every
  // later run measure them again).
  void KeepMatchAgain(MatchRecord& kept);

  // ---- 3. Seeds (correspondence_seeds.cpp) --------------------------------------------------
  LimitEvaluator& Evaluator() {
    auto& slot = evaluators_.local();
    if (!slot) slot = std::make_unique<LimitEvaluator>(surface_);
    return *slot;
  }
  Status EvaluateBaseVertices();
  void IndexSculptVertexClasses();
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
  Label Walk(Label label, GridPoint from, GridPoint to);
  Label Stuck(Label label, int edge);
  std::int32_t VertexAt(Label label, int corner) const {
    return sculpt_.face_indices[(label & ~3u) | ((label + corner) & 3u)];
  }
  Vec3d Position(std::int32_t vertex) const { return ToVec3d(sculpt_.positions[vertex]); }
  std::string NoNeighbourMessage(Label label, int edge, int ptex) const;
  std::string NoNeighbourMessage(int ptex) const;

  SeedAttempt TrySeed(const BaseComponent& component, int p0, int corner, Label start,
                      double prune_above);
  bool SeedFace(int p, Label label, double prune_above, SeedAttempt& attempt);
  bool CheckFarCorners(const BaseComponent& component, SeedAttempt& attempt);
  std::vector<std::uint32_t> HalfEdgesAround(std::uint32_t x) const;
  double SeedScore(std::int32_t x, int w) const;

  struct CandidateList {
    std::vector<std::uint32_t> vertices;  // best SeedScore first (ties by id)
    std::int64_t nearest = -1;            // the nearest of the class, for messages
    double nearest_distance = HUGE_VAL;
  };
  // The sculpt vertices of `vertex_class` in unmatched components of `cells` quads, ascending.
  std::vector<std::uint32_t> ClassVertices(int vertex_class, std::uint64_t cells) const;
  CandidateList Candidates(std::span<const std::uint32_t> class_vertices, int w) const;
  // The seed vertex of a component and its corner in the first of its Ptex faces there.
  std::pair<int, const RefinedCage::Corner*> SeedVertex(const BaseComponent& component) const;
  Status SeedComponent(const BaseComponent& component);
  // SeedComponent's rule for which labelling wins, applied to the labellings' logs (the order
  // in which they met base vertices, and the sculpt vertex there) with these positions: the
  // first of the least score among those whose walk completed; one stops at a vertex beyond the
  // offset limit, or once its score passes the best one's. -1: none.
  int ChosenLabelling(const ComponentSeeds& log) const;
  // Seeds the component trying every labelling whole, logged, the positions judged after
  // (ChosenLabelling); log.chosen < 0 when none fits.
  void SeedComponentLogged(const BaseComponent& component, const RefinedCage::Corner* place,
                           const CandidateList& candidates, ComponentSeeds& log);
  bool SeedsStillChosen(const MatchRecord& kept) const;

  // ---- 4. Grids (correspondence_grids.cpp) --------------------------------------------------
  void SizeGrids();
  // A kept match's grids and tables from its cells' labels.
  void GridsFromCells(std::vector<Label> cells);
  Status FillGrids();
  void FillGrid(int p, FirstError& error);

  // ---- 5. Faces, seams (correspondence_grids.cpp) -------------------------------------------
  std::tuple<int, int, int> CellPlace(std::int64_t cell) const;
  Status CheckFaces();
  Status FaceInTwoCells() const;
  VertexId GridVertex(int p, GridPoint at) const {
    const int n = out_.grid_sizes[p];
    return out_
        .grid_vertices[out_.grid_offsets[p] + static_cast<std::int64_t>(at.j) * (n + 1) + at.i];
  }
  Status CheckSeams();
  void CheckSeamsOf(int p, FirstError& error) const;
  void CheckBaseVertex(int w, FirstError& error) const;

  // ---- 6. Homes and positions (correspondence_grids.cpp) ------------------------------------
  Status FindHomes();
  // The position check, into checks_ and out_. With `kept` (a kept match's checks), a face
  // whose lattice has the positions it had then takes what was measured there, and the others
  // are measured with the vertices it owned (counted in out_.faces_checked_again); otherwise
  // each vertex is measured at its home (FindHomes).
  Status CheckPositions(const PositionChecks* kept);
  // Per Ptex face, where its lattice's points start in PositionChecks::own; the total last.
  std::vector<std::size_t> LatticeOffsets() const;
  bool ChecksFitTheGrids(const PositionChecks& checks) const;

  bool labelling_ = false;
  // With MatchOptions::cache_dir: the keys, and what step 3 read of the positions and chose.
  Hash128 faces_key_, match_key_;
  bool logging_ = false;
  std::vector<ComponentSeeds> seed_logs_;
  ComponentSeeds* met_log_ = nullptr;  // the labelling being tried logs its base vertices here
  PositionChecks checks_;
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

}  // namespace dispex::subdiv::matching
