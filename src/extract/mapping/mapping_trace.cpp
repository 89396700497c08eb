#include "extract/mapping/mapping_trace.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string_view>

#include "core/vec3.h"
#include "dispex/ptex_sampler.h"
#include "extract/mapping/far_sheets.h"
#include "extract/mapping/mapping_blocks.h"
#include "extract/mapping/mapping_lattice.h"
#include "extract/mapping/mapping_rays.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

using namespace mapping;

namespace {

// The cell of sample row (column) i of n in a face's m x m grid of cells.
int CellOf(int i, int m, int n) {
  return static_cast<int>((std::int64_t{2} * i + 1) * m / (std::int64_t{2} * n));
}

// Lays out the neighbourhood of `face` in w, kept while the same face is traced again: the
// slots beyond the face unless every listed sample's rings stay inside it (a few samples, the
// search estimate's), and for the whole grid the lattice the block kernels read.
void PrepareFace(const SculptMapping& mapping, const Mesh& sculpt, int face, int n,
                 std::span<const std::int32_t> samples, MappingScratch& w) {
  const int m = mapping.grid_size(face);
  bool inside = !samples.empty();
  for (std::size_t s = 0; inside && s < samples.size(); ++s) {
    for (const int cell : {CellOf(samples[s] % n, m, n), CellOf(samples[s] / n, m, n)}) {
      inside = inside && cell >= kMaxRings && cell < m - kMaxRings;
    }
  }
  if (w.face != face || (!w.margins && !inside)) LayOut(mapping, face, w, !inside);
  if (samples.empty() && w.lattice_face != face) {
    FillLattice(sculpt, w);
    w.lattice_face = face;
  }
}

// The queries of one face's samples (TraceRingsOfFace). A listed sample goes ring by ring on
// its own; over the whole grid, the samples of a cell whose rings 0 and 1 are all quads of the
// lattice go through TraceBlock together, in blocks of kLanes, and with paired blocks a full
// block waits in the other slot for a second one, and the two are traced together.
class RingTracer {
 public:
  RingTracer(const Mesh& sculpt, int m, int n, std::span<const Float3> origins,
             std::span<const Float3> normals, const NormalQuery& query, const NormalHits& out,
             std::span<std::uint8_t> undecided, MappingScratch& w, MappingCounters& counters)
      : sculpt_(sculpt),
        m_(m),
        n_(n),
        origins_(origins),
        normals_(normals),
        query_(query),
        out_(out),
        undecided_(undecided),
        w_(w),
        counters_(counters),
        pairs_(w.paired_blocks && CpuPairsBlocks()) {}

  void TraceListed(std::span<const std::int32_t> samples) {
    for (const std::int32_t s : samples) {
      const auto k = static_cast<std::size_t>(s);
      if (Valid(k)) One(k, CellOf(s % n_, m_, n_), CellOf(s / n_, m_, n_));
    }
  }

  // Cell by cell, row by row; each cell's samples row by row.
  void TraceGrid() {
    FirstSamples();
    const std::vector<int>& first = w_.first_sample;
    for (int cj = 0; cj < m_; ++cj) {
      const int j_begin = first[static_cast<std::size_t>(cj)];
      const int j_end = first[static_cast<std::size_t>(cj) + 1];
      for (int ci = 0; ci < m_; ++ci) {
        const int i_begin = first[static_cast<std::size_t>(ci)];
        const int i_end = first[static_cast<std::size_t>(ci) + 1];
        const bool block = j_end > j_begin && i_end > i_begin && Plain(ci, cj);
        for (int j = j_begin; j < j_end; ++j) {
          for (int i = i_begin; i < i_end; ++i) {
            const std::size_t k = static_cast<std::size_t>(j) * n_ + i;
            if (!Valid(k)) continue;
            if (!block) {
              One(k, ci, cj);
              continue;
            }
            AddLane(w_, k, origins_[k], FlushTiny(normals_[k]), blocks_[fill_]);
            if (blocks_[fill_].count == kLanes) Flush(ci, cj);
          }
        }
        Flush(ci, cj);
      }
    }
    if (waiting_) TraceAlone(1 - fill_);
  }

 private:
  // Invalid queries are misses; the others are traced.
  bool Valid(std::size_t k) {
    const Float3& o = origins_[k];
    const Float3& d = normals_[k];
    if (Finite(o) && Finite(d) && (d.x != 0 || d.y != 0 || d.z != 0)) return true;
    out_.t[k] = std::numeric_limits<float>::quiet_NaN();
    out_.flags[k] = 0;
    if (!out_.prim.empty()) out_.prim[k] = SculptPrimId();
    undecided_[k] = 0;
    ++counters_.decided;
    return false;
  }

  // Sample k through the rings of cell (ci, cj), one by one.
  void One(std::size_t k, int ci, int cj) {
    const bool done = TraceRings(w_, sculpt_, Line(origins_[k], FlushTiny(normals_[k])), ci, cj,
                                 query_, k, out_, counters_.quads);
    undecided_[k] = !done;
    counters_.decided += done;
  }

  // Whether rings 0 and 1 of cell (ci, cj) are all quads of the lattice (no extraordinary
  // corner).
  bool Plain(int ci, int cj) const {
    for (int c = 0; c < 4; ++c) {
      if (w_.fan_corner[c] && CornerDistance(ci, cj, m_, c) == 0) return false;
    }
    const int width = m_ + 2 * kMargin;
    for (int b = cj - 1; b <= cj + 1; ++b) {
      for (int a = ci - 1; a <= ci + 1; ++a) {
        if (w_.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)].state !=
            kCell) {
          return false;
        }
      }
    }
    return true;
  }

  // w.first_sample: the first sample row (column) of each cell row (column); n at the end.
  void FirstSamples() {
    std::vector<int>& first = w_.first_sample;
    first.assign(static_cast<std::size_t>(m_) + 1, n_);
    for (int i = n_ - 1; i >= 0; --i) first[static_cast<std::size_t>(CellOf(i, m_, n_))] = i;
    for (int c = m_ - 1; c >= 0; --c) {
      const auto at = static_cast<std::size_t>(c);
      first[at] = std::min(first[at], first[at + 1]);
    }
  }

  // The answers of block b's lanes: decided, settled undecided, or on to the rings one by one.
  void Finish(int b, const bool* decided, const bool* settled) {
    for (int l = 0; l < blocks_[b].count; ++l) {
      const std::size_t k = blocks_[b].k[l];
      counters_.quads += 9;
      if (decided[l]) {
        undecided_[k] = 0;
        ++counters_.decided;
      } else if (settled[l]) {
        undecided_[k] = 1;
      } else {
        One(k, block_ci_[b], block_cj_[b]);
      }
    }
    blocks_[b].count = 0;
  }

  void TraceAlone(int b) {
    bool decided[kLanes], settled[kLanes];
    TraceBlock(w_, sculpt_, block_ci_[b], block_cj_[b], blocks_[b], query_, out_, decided, settled);
    Finish(b, decided, settled);
  }

  // The block being filled, of cell (ci, cj), is traced: alone, or with paired blocks left
  // waiting for a second one, or traced with the one waiting.
  void Flush(int ci, int cj) {
    if (blocks_[fill_].count == 0) return;
    block_ci_[fill_] = ci;
    block_cj_[fill_] = cj;
    if (!pairs_) {
      TraceAlone(fill_);
    } else if (!waiting_) {
      waiting_ = true;
      fill_ = 1 - fill_;
    } else {
      TracePair();
    }
  }

  void TracePair() {
#if defined(__x86_64__)
    const int first = 1 - fill_;
    const int ci_pair[2] = {block_ci_[first], block_ci_[fill_]};
    const int cj_pair[2] = {block_cj_[first], block_cj_[fill_]};
    const Lanes* const pair[2] = {&blocks_[first], &blocks_[fill_]};
    bool decided[2][kLanes], settled[2][kLanes];
    TraceBlockPair(w_, sculpt_, ci_pair, cj_pair, pair, query_, out_, decided, settled);
    Finish(first, decided[0], settled[0]);
    Finish(fill_, decided[1], settled[1]);
    waiting_ = false;
#endif
  }

  const Mesh& sculpt_;
  const int m_, n_;
  std::span<const Float3> origins_, normals_;
  const NormalQuery& query_;
  const NormalHits& out_;
  std::span<std::uint8_t> undecided_;
  MappingScratch& w_;
  MappingCounters& counters_;
  // Blocks of samples, one cell's each, filled in blocks_[fill_]; with pairs_, a full block
  // waits in the other slot (waiting_) for a second one.
  const bool pairs_;
  Lanes blocks_[2];
  int block_ci_[2] = {}, block_cj_[2] = {};
  int fill_ = 0;
  bool waiting_ = false;
};

// TraceMapped's rings, for a face not at risk of folds.
void TraceRingsOfFace(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                      std::span<const std::int32_t> samples, std::span<const Float3> origins,
                      std::span<const Float3> normals, const NormalQuery& query,
                      const NormalHits& out, std::span<std::uint8_t> undecided, MappingScratch& w,
                      MappingCounters& counters) {
  PrepareFace(mapping, sculpt, face.value, n, samples, w);
  RingTracer tracer(sculpt, mapping.grid_size(face.value), n, origins, normals, query, out,
                    undecided, w, counters);
  if (samples.empty()) {
    tracer.TraceGrid();
  } else {
    tracer.TraceListed(samples);
  }
}

}  // namespace

bool PairedBlocksByDefault() {
  static const bool paired = [] {
    const char* kernel = std::getenv("DISPEX_MAPPING_KERNEL");
    return CpuPairsBlocks() && !(kernel != nullptr && std::string_view(kernel) == "sse2");
  }();
  return paired;
}

void GatherBlockQuads(const SculptMapping& mapping, const Mesh& sculpt, std::int64_t block,
                      BlockQuads& out) {
  const SculptBlocks& blocks = mapping.blocks();
  const SculptBlocks::Place at = blocks.block(block);
  const int b = blocks.block_size(at.face);
  out.b = b;
  std::fill(std::begin(out.quarter_box), std::end(out.quarter_box), Box::Empty());
  // Cell (i, j)'s face has corner RotationOf + k at the cell's corner k, (i, j), (i + 1, j),
  // (i + 1, j + 1), (i, j + 1); a lattice point names the vertex last seen there.
  constexpr int kSide = SculptBlocks::kBlock + 1;
  static constexpr int kDx[4] = {0, 1, 1, 0}, kDy[4] = {0, 0, 1, 1};
  std::int32_t vertex[kSide][kSide];
  std::uint8_t point[kSide][kSide];
  for (auto& row : vertex) std::fill(std::begin(row), std::end(row), -1);
  const Float3* p = sculpt.positions.data();
  out.num_points = 0;
  for (int j = 0; j < b; ++j) {
    for (int i = 0; i < b; ++i) {
      const int c = j * b + i;
      const std::uint32_t cell = mapping.cell(at.face, at.bi * b + i, at.bj * b + j);
      const std::int32_t face = SculptMapping::FaceOf(cell);
      const int rotation = SculptMapping::RotationOf(cell);
      const std::int32_t* ids = sculpt.face_indices.data() + 4 * static_cast<std::size_t>(face);
      const int quarter = b == 1 ? 0 : (2 * j / b) * 2 + 2 * i / b;
      Box& box = out.quarter_box[quarter];
      out.face[c] = face;
      out.quarter_of[c] = static_cast<std::uint8_t>(quarter);
      for (int k = 0; k < 4; ++k) {
        const int x = i + kDx[k], y = j + kDy[k], corner = (rotation + k) & 3;
        if (vertex[y][x] != ids[corner]) {
          vertex[y][x] = ids[corner];
          point[y][x] = static_cast<std::uint8_t>(out.num_points);
          out.points[out.num_points++] = p[ids[corner]];
        }
        out.corner_point[c][corner] = point[y][x];
        const Float3& v = out.points[point[y][x]];
        const float xyz[3] = {v.x, v.y, v.z};
        for (int a = 0; a < 3; ++a) {
          box.lower[a] = std::min(box.lower[a], xyz[a]);
          box.upper[a] = std::max(box.upper[a], xyz[a]);
        }
      }
    }
  }
}

bool WindowCrossesQuads(const BlockQuads& quads, const Mesh& sculpt, unsigned quarters,
                        const Float3& origin, const Float3& normal, float window) {
  const Line line(origin, FlushTiny(normal));
  Crossings x;
  x.distance = window;
  // Each point projected once, when a cell of a quarter tested first needs it (the same
  // doubles as TestQuad's).
  double px[4 * BlockQuads::kCells], py[4 * BlockQuads::kCells];
  bool projected[4 * BlockQuads::kCells] = {};
  const int cells = quads.b * quads.b;
  for (int c = 0; c < cells; ++c) {
    if (!(quarters >> quads.quarter_of[c] & 1u)) continue;
    double cx[4], cy[4];
    for (int k = 0; k < 4; ++k) {
      const int at = quads.corner_point[c][k];
      if (!projected[at]) {
        line.Project(quads.points[at], px[at], py[at]);
        projected[at] = true;
      }
      cx[k] = px[at];
      cy[k] = py[at];
    }
    TestProjectedQuad(line, sculpt, quads.face[c], 0, cx[0], cy[0], cx[1], cy[1], cx[2], cy[2],
                      cx[3], cy[3], x);
  }
  return x.degenerate || x.plus.found() || x.minus.found();
}

void TraceMapped(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                 std::span<const std::int32_t> samples, std::span<const Float3> origins,
                 std::span<const Float3> normals, const NormalQuery& query, const NormalHits& out,
                 std::span<std::uint8_t> undecided, MappingScratch& w, MappingCounters& counters) {
  const std::size_t count = samples.empty() ? static_cast<std::size_t>(n) * n : samples.size();
  counters.queries += count;
  if (mapping.fold_risk(face.value)) {
    for (std::size_t s = 0; s < count; ++s) {
      undecided[samples.empty() ? s : static_cast<std::size_t>(samples[s])] = 1;
    }
    return;
  }
  TraceRingsOfFace(mapping, sculpt, face, n, samples, origins, normals, query, out, undecided, w,
                   counters);
  const std::uint64_t far = CheckFarSheets(mapping, sculpt, face.value, n, samples, origins,
                                           normals, query, out, undecided, w);
  counters.decided -= far;
  counters.far_sheets += far;
}

}  // namespace dispex::extract
