// Steps 4 to 6 of MatchRefinedSculpt (correspondence.cpp): each Ptex face's grid filled from
// its (0,0) cell, every quad in one cell and the grids agreeing where they meet, then each
// vertex's home and the position check.
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/first_touch.h"
#include "core/hash128.h"
#include "subdiv/correspondence_matcher.h"

namespace dispex::subdiv::matching {
namespace {

// The position check reads every grid point of grids up to this size, and on larger ones the
// points on every (n / kCheckedLines)-th row and column (the borders included): on level 6 of
// a 941-quad cage (3.9M vertices, one core) 23% of the vertices in 0.06 s, where all of them
// take 0.40 s, a third of the whole match.
constexpr int kCheckedLines = 8;

// The error path of FillGrid's loop over cells, kept out of line so that the loop keeps its
// registers (inlined, Record's locking and Status's construction cost it more instructions
// per cell).
[[gnu::cold, gnu::noinline]] void RecordError(FirstError& error, std::int64_t index,
                                              std::string message) {
  error.Record(index, Status::Error(std::move(message)));
}

// The points of a grid of size n the position check reads, row by row: every point of grids up
// to kCheckedLines, else those on every (n / kCheckedLines)-th row and column.
template <class Visit>
void ForEachLatticePoint(int n, Visit&& visit) {
  const int step = n <= kCheckedLines ? 1 : n / kCheckedLines;
  for (int j = 0; j <= n && n > 0; ++j) {
    for (int i = 0; i <= n; i += (j % step == 0) ? 1 : step) visit(i, j);
  }
}

}  // namespace

// ---- 4. Grids -----------------------------------------------------------------------------

void Matcher::SizeGrids() {
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
  AssignTouched(out_.grid_vertices, static_cast<std::size_t>(out_.grid_offsets.back()), VertexId());
}

// What FillGrids and CheckFaces make of the cells, from the kept ones (which passed them).
void Matcher::GridsFromCells(std::vector<Label> cells) {
  SizeGrids();
  const std::size_t num_faces = sculpt_.num_faces();
  if (options_.face_tables) {
    AssignTouched(out_.face_ptex, num_faces, PtexFaceId());
    AssignTouched(out_.face_cell, num_faces, std::int32_t{-1});
    AssignTouched(out_.face_rotation, num_faces, std::uint8_t{0});
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, cage_.num_ptex_faces()),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int p = r.begin(); p < r.end(); ++p) {
                        const int n = cage_.grid_size(p);
                        const Label* cell = &cells[static_cast<std::size_t>(cell_offsets_[p])];
                        VertexId* grid = &out_.grid_vertices[out_.grid_offsets[p]];
                        // Each grid vertex from one cell (the cells agree at the corners they
                        // share: they passed CheckFaces): corner 0 of its own, corners 1-3 along
                        // the last row and column.
                        for (int j = 0; j < n; ++j) {
                          for (int i = 0; i < n; ++i) {
                            const Label label = cell[j * n + i];
                            grid[j * (n + 1) + i] = VertexId(VertexAt(label, 0));
                            if (i == n - 1) grid[j * (n + 1) + n] = VertexId(VertexAt(label, 1));
                            if (j == n - 1) grid[n * (n + 1) + i] = VertexId(VertexAt(label, 3));
                            if (i == n - 1 && j == n - 1)
                              grid[n * (n + 1) + n] = VertexId(VertexAt(label, 2));
                            if (!options_.face_tables) continue;
                            out_.face_ptex[label / 4] = PtexFaceId(p);
                            out_.face_cell[label / 4] = j * n + i;
                            out_.face_rotation[label / 4] = static_cast<std::uint8_t>(label & 3);
                          }
                        }
                      }
                    });
  out_.cell_labels = std::move(cells);
}

Status Matcher::FillGrids() {
  const int num_ptex = cage_.num_ptex_faces();
  SizeGrids();
  AssignTouched(cells_, sculpt_.num_faces(), Label{0});  // all written when FillGrids succeeds
  FirstError error;
  tbb::parallel_for(tbb::blocked_range<int>(0, num_ptex), [&](const tbb::blocked_range<int>& r) {
    for (int p = r.begin(); p < r.end(); ++p) {
      if (cage_.grid_size(p) > 0) FillGrid(p, error);
    }
  });
  return error.failed() ? error.status() : Status::Ok();
}

void Matcher::FillGrid(int p, FirstError& error) {
  const int n = cage_.grid_size(p);
  Label* cells = &cells_[cell_offsets_[p]];
  VertexId* grid = &out_.grid_vertices[out_.grid_offsets[p]];
  Label row = seeds_[p];
  for (int j = 0; j < n; ++j) {
    if (j > 0) {
      const Label up = Step(row, 2);
      if (up == kNoLabel) {
        RecordError(error, cell_offsets_[p] + (j - 1) * n, NoNeighbourMessage(row, 2, p));
        return;
      }
      row = up;
    }
    Label label = row;
    for (int i = 0; i < n; ++i) {
      if (i > 0) {
        const Label right = Step(label, 1);
        if (right == kNoLabel) {
          RecordError(error, cell_offsets_[p] + j * n + i - 1, NoNeighbourMessage(label, 1, p));
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
          RecordError(
              error, cell_offsets_[p] + j * n + i,
              fmt::format("{}: face {} does not fit the grid of Ptex face {} ({}x{}): as cell "
                          "({}, {}) it puts vertex {} at grid point ({}, {}), which holds "
                          "vertex {}",
                          where_, label / 4, p, n, n, i, j, vertex.value, gi, gj, slot.value));
          return;
        }
      }
    }
  }
}

// ---- 5. Faces, seams ----------------------------------------------------------------------

// Where cell `cell` (an index into cells_) is: its Ptex face and (i, j).
std::tuple<int, int, int> Matcher::CellPlace(std::int64_t cell) const {
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
Status Matcher::CheckFaces() {
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

Status Matcher::FaceInTwoCells() const {
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

// Grid points shared by two Ptex faces hold one vertex: along their common edges, and at
// every base vertex (whose faces need not be connected through edges around it).
Status Matcher::CheckSeams() {
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

void Matcher::CheckSeamsOf(int p, FirstError& error) const {
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

void Matcher::CheckBaseVertex(int w, FirstError& error) const {
  const RefinedCage::Corner* first = cage_.corners_begin(w);
  for (const RefinedCage::Corner* c = first; c != cage_.corners_end(w); ++c) {
    const VertexId a =
        GridVertex(first->ptex, CornerPoint(cage_.grid_size(first->ptex), first->corner));
    const VertexId b = GridVertex(c->ptex, CornerPoint(cage_.grid_size(c->ptex), c->corner));
    if (a == b) continue;
    error.Record(w, Status::Error(fmt::format(
                        "{}: vertices {} and {} both sit at base vertex {} (corners of Ptex faces "
                        "{} and {}): the sculpt is not the base refined",
                        where_, a.value, b.value, w, first->ptex, c->ptex)));
    return;
  }
}

// ---- 6. Homes and positions ---------------------------------------------------------------

// A vertex inside a Ptex face is on that grid only; one on a border takes the lowest of the
// faces whose grids hold it.
Status Matcher::FindHomes() {
  const std::size_t num_vertices = sculpt_.num_vertices();
  constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::max();
  AssignTouched(out_.vertex_faces, num_vertices, PtexFaceId(kNone));
  if (options_.vertex_homes) AssignTouched(out_.vertex_uvs, 2 * num_vertices, 0.0f);
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
    if (!options_.vertex_homes) return;
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
  if (options_.vertex_homes) {
    each_grid_point(true, [&](int p, int n, int i, int j, bool border, std::int32_t v) {
      if (border && out_.vertex_faces[v].value == p) set_uv(n, i, j, v);
    });
  }
  for (std::size_t v = 0; v < num_vertices; ++v) {
    if (out_.vertex_faces[v].value == kNone) {
      return Status::Error(fmt::format(
          "{}: vertex {} is on no grid: other vertices sit at two grid points", where_, v));
    }
  }
  return Status::Ok();
}

std::vector<std::size_t> Matcher::LatticeOffsets() const {
  const int num_ptex = cage_.num_ptex_faces();
  std::vector<std::size_t> at(static_cast<std::size_t>(num_ptex) + 1, 0);
  for (int p = 0; p < num_ptex; ++p) {
    std::size_t points = 0;
    ForEachLatticePoint(cage_.grid_size(p), [&](int, int) { ++points; });
    at[p + 1] = at[p] + points;
  }
  return at;
}

bool Matcher::ChecksFitTheGrids(const PositionChecks& checks) const {
  const auto num_ptex = static_cast<std::size_t>(cage_.num_ptex_faces());
  if (checks.lattice_keys.size() != num_ptex || checks.own.size() != LatticeOffsets().back()) {
    return false;
  }
  return std::all_of(checks.worst.begin(), checks.worst.end(), [&](std::int32_t v) {
    return v >= -1 && (v < 0 || static_cast<std::size_t>(v) < sculpt_.num_vertices());
  });
}

Status Matcher::CheckPositions(const PositionChecks* kept) {
  const int num_ptex = cage_.num_ptex_faces();
  const auto faces = static_cast<std::size_t>(num_ptex);
  PositionChecks& now = checks_;
  now.max.assign(faces, -1);
  now.sum_squares.assign(faces, 0);
  now.worst.assign(faces, -1);
  now.count.assign(faces, 0);
  // What a match run whole keeps for the next (KeepMatch), and what a kept one compares.
  const bool keep = logging_ && kept == nullptr;
  const std::vector<std::size_t> lattice_at =
      keep || kept != nullptr ? LatticeOffsets() : std::vector<std::size_t>();
  now.own.assign(keep ? lattice_at.back() : 0, 0);
  now.lattice_keys.assign(keep || kept != nullptr ? faces : 0, Hash128{});
  std::atomic<std::size_t> checked_again{0};
  FirstError error;
  tbb::parallel_for(tbb::blocked_range<int>(0, num_ptex), [&](const tbb::blocked_range<int>& r) {
    std::vector<float> uv, xyz;
    std::vector<std::int32_t> vertices;
    std::vector<Float3> points;
    for (int p = r.begin(); p < r.end(); ++p) {
      const int n = cage_.grid_size(p);
      if (n == 0) continue;
      const auto f = static_cast<std::size_t>(p);
      if (keep || kept != nullptr) {
        points.clear();
        ForEachLatticePoint(n, [&](int i, int j) {
          points.push_back(sculpt_.positions[GridVertex(p, {i, j}).value]);
        });
        const Hash128 key = HashBytes(std::as_bytes(std::span(points)));
        now.lattice_keys[f] = key;
        if (kept != nullptr && kept->lattice_keys[f] == key) {
          now.max[f] = kept->max[f];
          now.sum_squares[f] = kept->sum_squares[f];
          now.worst[f] = kept->worst[f];
          now.count[f] = kept->count[f];
          continue;
        }
        if (kept != nullptr) checked_again.fetch_add(1, std::memory_order_relaxed);
      }
      uv.clear();
      vertices.clear();
      std::size_t k = 0;
      ForEachLatticePoint(n, [&](int i, int j) {
        const VertexId v = GridVertex(p, {i, j});
        const bool own = kept != nullptr ? kept->own[lattice_at[f] + k] != 0
                                         : out_.vertex_faces[v.value].value == p;
        if (keep) now.own[lattice_at[f] + k] = own ? 1 : 0;
        ++k;
        if (!own) return;
        vertices.push_back(v.value);
        uv.push_back(static_cast<float>(i) / n);
        uv.push_back(static_cast<float>(j) / n);
      });
      if (vertices.empty()) continue;
      xyz.resize(3 * vertices.size());
      Status st = Evaluator().EvaluatePoints(PtexFaceId(p), uv, xyz, {});
      if (!st.ok()) {
        error.Record(p, st);
        continue;
      }
      for (std::size_t q = 0; q < vertices.size(); ++q) {
        const Vec3d limit{xyz[3 * q], xyz[3 * q + 1], xyz[3 * q + 2]};
        const double d2 = Distance2(Position(vertices[q]), limit);
        now.sum_squares[f] += d2;
        if (d2 > now.max[f]) {
          now.max[f] = d2;
          now.worst[f] = vertices[q];
        }
      }
      now.count[f] = vertices.size();
    }
  });
  if (error.failed()) return error.status();
  out_.faces_checked_again = checked_again.load();
  double max = -1, sum_squares = 0;
  std::int32_t worst = -1;
  int worst_face = -1;
  for (std::size_t f = 0; f < faces; ++f) {
    out_.checked_vertices += now.count[f];
    sum_squares += now.sum_squares[f];
    if (now.max[f] > max) {
      max = now.max[f];
      worst = now.worst[f];
      worst_face = static_cast<int>(f);
    }
  }
  out_.max_offset = std::sqrt(std::max(max, 0.0));
  out_.rms_offset = out_.checked_vertices ? std::sqrt(sum_squares / out_.checked_vertices) : 0;
  out_.worst_vertex = VertexId(worst);
  if (out_.max_offset > offset_limit_) {
    const int n = out_.grid_sizes[worst_face];
    GridPoint at;
    for (int k = 0; k < (n + 1) * (n + 1); ++k) {
      if (GridVertex(worst_face, {k % (n + 1), k / (n + 1)}).value == worst) {
        at = {k % (n + 1), k / (n + 1)};
        break;
      }
    }
    return Status::Error(fmt::format(
        "{}: the position check failed: vertex {} is {:.6g} from its home on Ptex face {} at "
        "({}, {}), more than max_offset {:.6g} (is the cage the one the sculpt was refined "
        "from, with the same tags?)",
        where_, worst, out_.max_offset, worst_face, static_cast<float>(at.i) / n,
        static_cast<float>(at.j) / n, offset_limit_));
  }
  return Status::Ok();
}

}  // namespace dispex::subdiv::matching
