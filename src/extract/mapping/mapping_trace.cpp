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

// TraceMapped's rings, for a face not at risk of folds.
void TraceRingsOfFace(const SculptMapping& mapping, const Mesh& sculpt, PtexFaceId face, int n,
                      std::span<const std::int32_t> samples, std::span<const Float3> origins,
                      std::span<const Float3> normals, const NormalQuery& query,
                      const NormalHits& out, std::span<std::uint8_t> undecided, MappingScratch& w,
                      MappingCounters& counters) {
  const int m = mapping.grid_size(face.value);
  auto cell_of = [&](int i) {
    return static_cast<int>((std::int64_t{2} * i + 1) * m / (std::int64_t{2} * n));
  };
  // A few samples whose rings all stay inside the face (the search estimate's) need no apron
  // beyond it.
  bool inside = !samples.empty();
  for (std::size_t s = 0; inside && s < samples.size(); ++s) {
    for (const int cell : {cell_of(samples[s] % n), cell_of(samples[s] / n)}) {
      inside = inside && cell >= kMaxRings && cell < m - kMaxRings;
    }
  }
  if (w.face != face.value || (!w.margins && !inside)) LayOut(mapping, face.value, w, !inside);
  if (samples.empty() && w.lattice_face != face.value) {
    FillLattice(sculpt, w);
    w.lattice_face = face.value;
  }
  // Invalid queries are misses; the others get their cell's rings, one by one.
  auto valid = [&](std::size_t k) {
    const Float3& o = origins[k];
    const Float3& d = normals[k];
    if (Finite(o) && Finite(d) && (d.x != 0 || d.y != 0 || d.z != 0)) return true;
    out.t[k] = std::numeric_limits<float>::quiet_NaN();
    out.flags[k] = 0;
    if (!out.prim.empty()) out.prim[k] = SculptPrimId();
    undecided[k] = 0;
    ++counters.decided;
    return false;
  };
  auto one = [&](std::size_t k, int ci, int cj) {
    const bool done = TraceRings(w, sculpt, Line(origins[k], FlushTiny(normals[k])), ci, cj, query,
                                 k, out, counters.quads);
    undecided[k] = !done;
    counters.decided += done;
  };
  if (!samples.empty()) {
    for (const std::int32_t s : samples) {
      const auto k = static_cast<std::size_t>(s);
      if (valid(k)) one(k, cell_of(s % n), cell_of(s / n));
    }
    return;
  }
  // The whole grid, cell by cell: where rings 0 and 1 are all quads of the lattice (no
  // extraordinary corner), the cell's samples go through TraceBlock together.
  const int width = m + 2 * kMargin;
  auto plain = [&](int ci, int cj) {
    for (int c = 0; c < 4; ++c) {
      if (w.fan_corner[c] && CornerDistance(ci, cj, m, c) == 0) return false;
    }
    for (int b = cj - 1; b <= cj + 1; ++b) {
      for (int a = ci - 1; a <= ci + 1; ++a) {
        if (w.apron[static_cast<std::size_t>((b + kMargin) * width + a + kMargin)].state != kCell) {
          return false;
        }
      }
    }
    return true;
  };
  // Blocks of samples, one cell's each, filled in blocks[fill]; paired, a full block
  // waits in the other slot for a second one, and the two are traced together.
  const bool pairs = w.paired_blocks && CpuPairsBlocks();
  Lanes blocks[2];
  int block_ci[2] = {}, block_cj[2] = {};
  int fill = 0;
  bool waiting = false;
  auto finish = [&](int b, const bool* decided, const bool* settled) {
    for (int l = 0; l < blocks[b].count; ++l) {
      const std::size_t k = blocks[b].k[l];
      counters.quads += 9;
      if (decided[l]) {
        undecided[k] = 0;
        ++counters.decided;
      } else if (settled[l]) {
        undecided[k] = 1;
      } else {
        one(k, block_ci[b], block_cj[b]);
      }
    }
    blocks[b].count = 0;
  };
  auto trace_alone = [&](int b) {
    bool decided[kLanes], settled[kLanes];
    TraceBlock(w, sculpt, block_ci[b], block_cj[b], blocks[b], query, out, decided, settled);
    finish(b, decided, settled);
  };
  auto flush = [&](int ci, int cj) {
    if (blocks[fill].count == 0) return;
    block_ci[fill] = ci;
    block_cj[fill] = cj;
    if (!pairs) {
      trace_alone(fill);
    } else if (!waiting) {
      waiting = true;
      fill = 1 - fill;
    } else {
#if defined(__x86_64__)
      const int first = 1 - fill;
      const int ci_pair[2] = {block_ci[first], block_ci[fill]};
      const int cj_pair[2] = {block_cj[first], block_cj[fill]};
      const Lanes* const pair[2] = {&blocks[first], &blocks[fill]};
      bool decided[2][kLanes], settled[2][kLanes];
      TraceBlockPair(w, sculpt, ci_pair, cj_pair, pair, query, out, decided, settled);
      finish(first, decided[0], settled[0]);
      finish(fill, decided[1], settled[1]);
      waiting = false;
#endif
    }
  };
  // The first sample row (column) of each cell row (column); n at the end.
  w.first_sample.assign(static_cast<std::size_t>(m) + 1, n);
  for (int i = n - 1; i >= 0; --i) w.first_sample[static_cast<std::size_t>(cell_of(i))] = i;
  for (int c = m - 1; c >= 0; --c) {
    const auto at = static_cast<std::size_t>(c);
    w.first_sample[at] = std::min(w.first_sample[at], w.first_sample[at + 1]);
  }
  for (int cj = 0; cj < m; ++cj) {
    const int j_begin = w.first_sample[static_cast<std::size_t>(cj)];
    const int j_end = w.first_sample[static_cast<std::size_t>(cj) + 1];
    for (int ci = 0; ci < m; ++ci) {
      const int i_begin = w.first_sample[static_cast<std::size_t>(ci)];
      const int i_end = w.first_sample[static_cast<std::size_t>(ci) + 1];
      const bool block = j_end > j_begin && i_end > i_begin && plain(ci, cj);
      for (int j = j_begin; j < j_end; ++j) {
        for (int i = i_begin; i < i_end; ++i) {
          const std::size_t k = static_cast<std::size_t>(j) * n + i;
          if (!valid(k)) continue;
          if (!block) {
            one(k, ci, cj);
            continue;
          }
          AddLane(w, k, origins[k], FlushTiny(normals[k]), blocks[fill]);
          if (blocks[fill].count == kLanes) flush(ci, cj);
        }
      }
      flush(ci, cj);
    }
  }
  if (waiting) trace_alone(1 - fill);
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
