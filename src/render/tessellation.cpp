// Crack-free tessellation of the displaced limit surface.
//
// Each Ptex face is a kx x ky grid of its (u, v) square. The face's four sides lie on "lines"
// of the cage: a cage edge (quads cover it whole, n-gon sub-faces one half each) or, inside an
// n-gon, a spoke from an edge midpoint to the face centre. Every point a face puts on a line
// is named exactly, by the line and a reduced fraction along it (or, at a line's ends, by the
// cage vertex, edge midpoint or face centre there; tessellation_lines.h), so the faces around a
// point find the same name and share one vertex: position and normal from the lowest-numbered face,
// displacement averaged over all of them (or, with per-face displacement, one copy of the vertex
// per face, each displaced by its own face's value, as a renderer that reads each face on its own
// displaces it). A vector map's displacement is a vector in object space, each face's from its
// own frame and channels at its own (u, v), so the faces around a point average (or keep)
// vectors as a scalar map's average heights. Along a line the points of all its faces are merged,
// and a cell whose side received points from a finer neighbour becomes a fan around the cell
// centre, as in the usual crack-free stitching of adaptive tessellations (e.g. Moreton, "Watertight
// tessellation using forward differencing", 2001, and OpenSubdiv's Bfr::Tessellation with
// per-edge rates). Every stage is a flat array filled in parallel in a fixed order, or a
// sort under a total order, so the mesh does not depend on the thread count.
#include "render/tessellation.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>

#include "core/check.h"
#include "core/first_error.h"
#include "render/tessellation_lines.h"
#include "render/vertex_normals.h"

namespace dispex::render {

namespace {

using namespace lines;

Float3 Sub(const Float3& a, const Float3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
double Length2(const Float3& a) {
  return double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z;
}

Status MapValueError(const PtexFile& map, int face) {
  std::vector<float> texels;
  Status read = map.ReadFace(PtexFaceId(face), 0, texels);
  if (!read.ok()) return read;
  return Status::Error(
      fmt::format("{}: face {} holds a value that is not finite", map.name(), face));
}

// TessellateLimitSurface's state, built by its steps in the order Run calls them. Each step
// fills flat arrays the later ones read.
class Tessellation {
 public:
  Tessellation(const Mesh& cage, const LimitSurface& surface,
               std::span<const std::array<int, 2>> density, const PtexFile* map, int channel,
               BoundaryDisplacement boundary, std::optional<VectorSpace> space)
      : cage_(cage),
        surface_(surface),
        density_(density),
        map_(map),
        channel_(channel),
        per_face_(boundary == BoundaryDisplacement::kPerFace),
        space_(map ? space : std::nullopt),
        n_(surface.num_ptex_faces()) {}

  StatusOr<ShadedMesh> Run() {
    DISPEX_CHECK_EQ(density_.size(), static_cast<std::size_t>(n_));
    CollectSides();
    MergeLinePoints();
    NumberSharedVertices();
    CountFaceElements();
    DISPEX_RETURN_IF_ERROR(AllocateMesh());
    if (space_) DISPEX_RETURN_IF_ERROR(RecordVectors());
    DISPEX_RETURN_IF_ERROR(PlaceSharedVertices());
    DISPEX_RETURN_IF_ERROR(FillFaces());
    SmoothNormals();
    return std::move(out_);
  }

 private:
  struct Scratch {
    std::vector<float> uv, p, nrm, du, dv;  // du, dv: of a vector map only
    std::vector<std::int32_t> polygon;
  };

  // Limit points at s.uv, with their frames for a vector map.
  Status Evaluate(int f, Scratch& s) {
    const std::size_t count = s.uv.size() / 2;
    s.p.resize(3 * count);
    s.nrm.resize(3 * count);
    if (!space_) return EvaluatorForThread().EvaluatePoints(PtexFaceId(f), s.uv, s.p, s.nrm);
    s.du.resize(3 * count);
    s.dv.resize(3 * count);
    return EvaluatorForThread().EvaluatePointFrames(PtexFaceId(f), s.uv, {s.p, s.nrm, s.du, s.dv});
  }

  // A vector map's D at point k of s (face f at s.uv[2k], s.uv[2k + 1]), in object space.
  StatusOr<Float3> MapVector(int f, const Scratch& s, std::size_t k) const {
    const float u = s.uv[2 * k], v = s.uv[2 * k + 1];
    const float c[3] = {map_->Sample(PtexFaceId(f), u, v, 0), map_->Sample(PtexFaceId(f), u, v, 1),
                        map_->Sample(PtexFaceId(f), u, v, 2)};
    if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2])) {
      return MapValueError(*map_, f);
    }
    const std::size_t i = 3 * k;
    const SurfaceFrame frame{{s.du[i], s.du[i + 1], s.du[i + 2]},
                             {s.dv[i], s.dv[i + 1], s.dv[i + 2]},
                             {s.nrm[i], s.nrm[i + 1], s.nrm[i + 2]}};
    return VectorFromChannels(*space_, frame, c);
  }

  bool Active(int f) const {
    return density_[static_cast<std::size_t>(f)][0] > 0 && !surface_.is_hole(PtexFaceId(f));
  }
  int Kx(int f) const { return density_[static_cast<std::size_t>(f)][0]; }
  int Ky(int f) const { return density_[static_cast<std::size_t>(f)][1]; }

  LimitEvaluator& EvaluatorForThread() {
    auto& e = evaluators_.local();
    if (!e) e.emplace(surface_);
    return *e;
  }

  // The merged line point of grid point i along side `side` of face f.
  std::int64_t GridPoint(int f, int side, int i) const {
    const std::int64_t e = entry_of_[4 * static_cast<std::size_t>(f) + side];
    return entry_grid_point_[static_cast<std::size_t>(grid_offset_[static_cast<std::size_t>(e)] +
                                                      i)];
  }
  // The lowest line point an entry covers (its line points are consecutive from there).
  std::int64_t EntryFirstPoint(std::size_t e) const {
    const auto first = static_cast<std::size_t>(grid_offset_[e]);
    return std::min(entry_grid_point_[first],
                    entry_grid_point_[first + static_cast<std::size_t>(entries_[e].segs)]);
  }
  // Where entry_point_vertex_ holds face f's vertex for line point p of its side `side`.
  std::size_t EntryPointSlot(int f, int side, std::int64_t p) const {
    const auto e = static_cast<std::size_t>(entry_of_[4 * static_cast<std::size_t>(f) + side]);
    return static_cast<std::size_t>(entry_point_offset_[e] + (p - EntryFirstPoint(e)));
  }
  // The vertex face f uses for line point p of its side `side`: the point's one vertex, or
  // with per-face displacement the face's own copy.
  std::int32_t SharedVertex(int f, int side, std::int64_t p) const {
    if (!per_face_) return line_point_vertex_[static_cast<std::size_t>(p)];
    return entry_point_vertex_[EntryPointSlot(f, side, p)];
  }
  // Points a neighbour added between grid points i and i + 1 of a side.
  int ExtraPoints(int f, int side, int i) const {
    const std::int64_t a = GridPoint(f, side, i), b = GridPoint(f, side, i + 1);
    return static_cast<int>(std::abs(b - a) - 1);
  }
  int CellExtras(int f, int i, int j) const {
    const int kx = Kx(f), ky = Ky(f);
    int extra = 0;
    if (j == 0) extra += ExtraPoints(f, 0, i);
    if (i == kx - 1) extra += ExtraPoints(f, 1, j);
    if (j == ky - 1) extra += ExtraPoints(f, 2, kx - 1 - i);
    if (i == 0) extra += ExtraPoints(f, 3, ky - 1 - j);
    return extra;
  }
  // A border cell with extra points becomes a fan around its centre.
  bool Stitched(int f, int i, int j) const {
    const bool border = i == 0 || j == 0 || i == Kx(f) - 1 || j == Ky(f) - 1;
    return border && CellExtras(f, i, j) > 0;
  }

  // 1. Sides of every face, sorted by line.
  void CollectSides() {
    entries_.resize(4 * static_cast<std::size_t>(n_));
    tbb::parallel_for(0, n_, [&](int f) {
      if (!Active(f)) return;
      const auto& d = density_[static_cast<std::size_t>(f)];
      DISPEX_CHECK(d[0] >= 1 && d[0] <= 1024 && d[1] >= 1 && d[1] <= 1024);
      FaceSides(cage_, surface_, f, d[0], d[1], &entries_[4 * static_cast<std::size_t>(f)]);
    });
    entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                  [](const SideEntry& e) { return e.face < 0; }),
                   entries_.end());
    tbb::parallel_sort(entries_.begin(), entries_.end(),
                       [](const SideEntry& x, const SideEntry& y) {
                         if (x.line != y.line) return x.line < y.line;
                         if (x.face != y.face) return x.face < y.face;
                         return x.side < y.side;
                       });
    const std::size_t num_entries = entries_.size();
    entry_of_.assign(4 * static_cast<std::size_t>(n_), -1);
    grid_offset_.assign(num_entries + 1, 0);
    for (std::size_t e = 0; e < num_entries; ++e) {
      entry_of_[4 * static_cast<std::size_t>(entries_[e].face) + entries_[e].side] =
          static_cast<std::int64_t>(e);
      grid_offset_[e + 1] = grid_offset_[e] + entries_[e].segs + 1;
      if (e == 0 || entries_[e].line != entries_[e - 1].line) line_start_.push_back(e);
    }
    line_start_.push_back(num_entries);
    num_lines_ = line_start_.size() - 1;
  }

  // 2. The merged points of each line (at most the sum of its sides' points), and the records
  // of every face side that covers each point.
  void MergeLinePoints() {
    const std::size_t num_entries = entries_.size();
    entry_grid_point_.resize(static_cast<std::size_t>(grid_offset_[num_entries]));
    line_point_frac_.resize(entry_grid_point_.size());
    line_point_count_.assign(num_lines_, 0);
    std::vector<std::int64_t> record_count(num_lines_ + 1, 0);
    struct Candidate {
      Frac t;
      std::int64_t grid;  // index into entry_grid_point_
    };
    tbb::enumerable_thread_specific<std::vector<Candidate>> candidates;
    tbb::parallel_for(std::size_t{0}, num_lines_, [&](std::size_t g) {
      auto& c = candidates.local();
      c.clear();
      for (std::size_t e = line_start_[g]; e < line_start_[g + 1]; ++e) {
        for (int i = 0; i <= entries_[e].segs; ++i) {
          c.push_back({PointOnSide(entries_[e], i), grid_offset_[e] + i});
        }
      }
      std::sort(c.begin(), c.end(), [](const Candidate& x, const Candidate& y) {
        if (FracLess(x.t, y.t)) return true;
        if (FracLess(y.t, x.t)) return false;
        return x.grid < y.grid;
      });
      const std::int64_t base = grid_offset_[line_start_[g]];
      std::int64_t m = -1;
      for (std::size_t k = 0; k < c.size(); ++k) {
        if (k == 0 || FracLess(c[k - 1].t, c[k].t)) {
          line_point_frac_[static_cast<std::size_t>(base + ++m)] = c[k].t;
        }
        entry_grid_point_[static_cast<std::size_t>(c[k].grid)] = base + m;
      }
      line_point_count_[g] = m + 1;
      std::int64_t records = 0;
      for (std::int64_t p = 0; p <= m; ++p) {
        for (std::size_t e = line_start_[g]; e < line_start_[g + 1]; ++e) {
          records += Covers(entries_[e], line_point_frac_[static_cast<std::size_t>(base + p)]);
        }
      }
      record_count[g + 1] = records;
    });
    std::partial_sum(record_count.begin(), record_count.end(), record_count.begin());
    records_.resize(static_cast<std::size_t>(record_count[num_lines_]));
    tbb::parallel_for(std::size_t{0}, num_lines_, [&](std::size_t g) {
      const std::int64_t base = grid_offset_[line_start_[g]];
      std::size_t r = static_cast<std::size_t>(record_count[g]);
      const LineKey& line = entries_[line_start_[g]].line;
      for (std::int64_t p = 0; p < line_point_count_[g]; ++p) {
        const Frac t = line_point_frac_[static_cast<std::size_t>(base + p)];
        const PointKey key = KeyOf(cage_, line, t);
        for (std::size_t e = line_start_[g]; e < line_start_[g + 1]; ++e) {
          if (!Covers(entries_[e], t)) continue;
          Record& rec = records_[r++];
          rec.key = key;
          rec.face = entries_[e].face;
          rec.side = entries_[e].side;
          rec.line_point = base + p;
          SideUv(entries_[e].side, SigmaOf(entries_[e], t), rec.u, rec.v);
        }
      }
    });
  }

  // 3. One vertex per distinct point; with per-face displacement one per point and face (a
  // face that meets a point at two (u, v), as around a degenerate edge, gets one for each).
  void NumberSharedVertices() {
    tbb::parallel_sort(records_.begin(), records_.end(), RecordLess);
    if (!per_face_) line_point_vertex_.assign(line_point_frac_.size(), -1);
    for (std::size_t r = 0; r < records_.size(); ++r) {
      if (r == 0 || records_[r].key != records_[r - 1].key) point_records_.push_back(r);
      if (!per_face_) {
        line_point_vertex_[static_cast<std::size_t>(records_[r].line_point)] =
            static_cast<std::int32_t>(point_records_.size() - 1);
      }
    }
    point_records_.push_back(records_.size());
    num_points_ = point_records_.size() - 1;
    num_shared_ = per_face_ ? NumberFaceCopies() : num_points_;
  }

  // Per-face displacement: copy c holds records [copy_records_[c], [c + 1]), point k's copies
  // are [point_copies_[k], [k + 1]), and every (entry, line point it covers) names its copy in
  // entry_point_vertex_. Returns the number of copies.
  std::size_t NumberFaceCopies() {
    const std::size_t num_entries = entries_.size();
    entry_point_offset_.assign(num_entries + 1, 0);
    for (std::size_t e = 0; e < num_entries; ++e) {
      const auto first = static_cast<std::size_t>(grid_offset_[e]);
      const std::int64_t a = entry_grid_point_[first];
      const std::int64_t b = entry_grid_point_[first + static_cast<std::size_t>(entries_[e].segs)];
      entry_point_offset_[e + 1] = entry_point_offset_[e] + std::abs(b - a) + 1;
    }
    DISPEX_CHECK_EQ(static_cast<std::size_t>(entry_point_offset_[num_entries]), records_.size());
    entry_point_vertex_.assign(records_.size(), -1);
    for (std::size_t r = 0; r < records_.size(); ++r) {
      const Record& rec = records_[r];
      const bool new_point = r == 0 || rec.key != records_[r - 1].key;
      if (new_point) point_copies_.push_back(copy_records_.size());
      if (new_point || rec.face != records_[r - 1].face || rec.u != records_[r - 1].u ||
          rec.v != records_[r - 1].v) {
        copy_records_.push_back(r);
      }
      entry_point_vertex_[EntryPointSlot(rec.face, rec.side, rec.line_point)] =
          static_cast<std::int32_t>(copy_records_.size() - 1);
    }
    point_copies_.push_back(copy_records_.size());
    const std::size_t copies = copy_records_.size();
    copy_records_.push_back(records_.size());
    return copies;
  }

  // 4. Per face: interior grid points and the centres of stitched cells, and its triangles.
  void CountFaceElements() {
    vertex_start_.assign(static_cast<std::size_t>(n_) + 1, 0);
    triangle_start_.assign(static_cast<std::size_t>(n_) + 1, 0);
    tbb::parallel_for(0, n_, [&](int f) {
      if (!Active(f)) return;
      const int kx = Kx(f), ky = Ky(f);
      std::int64_t vertices = std::int64_t(kx - 1) * (ky - 1), triangles = 0;
      for (int j = 0; j < ky; ++j) {
        for (int i = 0; i < kx; ++i) {
          const bool border = i == 0 || j == 0 || i == kx - 1 || j == ky - 1;
          const int extra = border ? CellExtras(f, i, j) : 0;
          if (extra == 0) {
            triangles += 2;
          } else {
            vertices += 1;
            triangles += 4 + extra;
          }
        }
      }
      vertex_start_[static_cast<std::size_t>(f) + 1] = vertices;
      triangle_start_[static_cast<std::size_t>(f) + 1] = triangles;
    });
    vertex_start_[0] = static_cast<std::int64_t>(num_shared_);
    std::partial_sum(vertex_start_.begin(), vertex_start_.end(), vertex_start_.begin());
    std::partial_sum(triangle_start_.begin(), triangle_start_.end(), triangle_start_.begin());
  }

  Status AllocateMesh() {
    const std::int64_t num_vertices = vertex_start_[static_cast<std::size_t>(n_)];
    const std::int64_t num_triangles = triangle_start_[static_cast<std::size_t>(n_)];
    if (num_vertices >= std::numeric_limits<std::int32_t>::max() ||
        3 * num_triangles >= std::numeric_limits<std::int32_t>::max()) {
      return Status::Error(fmt::format(
          "{}: the tessellation would have {} triangles, more than 32-bit indices hold; lower "
          "the density",
          surface_.source(), num_triangles));
    }
    Mesh& mesh = out_.mesh;
    mesh.source = surface_.source() + (map_ ? " displaced by " + map_->name() : " (limit surface)");
    mesh.positions.reserve(static_cast<std::size_t>(num_vertices) + 1);
    mesh.positions.resize(static_cast<std::size_t>(num_vertices));
    limit_normals_.resize(static_cast<std::size_t>(num_vertices));
    mesh.face_indices.resize(3 * static_cast<std::size_t>(num_triangles));
    mesh.face_offsets.resize(static_cast<std::size_t>(num_triangles) + 1);
    tbb::parallel_for(std::size_t{0}, mesh.face_offsets.size(), [&](std::size_t t) {
      mesh.face_offsets[t] = static_cast<std::uint32_t>(3 * t);
    });
    return Status::Ok();
  }

  // Vertex `v` at limit point p(i) moved by h along the limit normal nrm(i) (xyz at 3i).
  void Place(std::size_t v, const Scratch& s, std::size_t k, float h) {
    const std::size_t i = 3 * k;
    limit_normals_[v] = {s.nrm[i], s.nrm[i + 1], s.nrm[i + 2]};
    out_.mesh.positions[v] = {s.p[i] + h * s.nrm[i], s.p[i + 1] + h * s.nrm[i + 1],
                              s.p[i + 2] + h * s.nrm[i + 2]};
  }
  // The same moved by the vector d.
  void Place(std::size_t v, const Scratch& s, std::size_t k, const Float3& d) {
    const std::size_t i = 3 * k;
    limit_normals_[v] = {s.nrm[i], s.nrm[i + 1], s.nrm[i + 2]};
    out_.mesh.positions[v] = {s.p[i] + d.x, s.p[i + 1] + d.y, s.p[i + 2] + d.z};
  }

  // 5a. A vector map: every record's D, from its own face's frame and channels at its own
  // (u, v), the records of a face evaluated together.
  Status RecordVectors() {
    const std::size_t faces = static_cast<std::size_t>(n_);
    std::vector<std::size_t> start(faces + 1, 0), order(records_.size());
    for (const Record& r : records_) ++start[static_cast<std::size_t>(r.face) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t r = 0; r < records_.size(); ++r) {
      order[fill[static_cast<std::size_t>(records_[r].face)]++] = r;
    }
    record_vectors_.resize(records_.size());
    tbb::parallel_for(std::size_t{0}, faces, [&](std::size_t face) {
      const std::size_t begin = start[face], end = start[face + 1];
      if (begin == end) return;
      const int f = static_cast<int>(face);
      Scratch& s = scratch_.local();
      s.uv.resize(2 * (end - begin));
      for (std::size_t k = begin; k < end; ++k) {
        s.uv[2 * (k - begin)] = records_[order[k]].u;
        s.uv[2 * (k - begin) + 1] = records_[order[k]].v;
      }
      Status st = Evaluate(f, s);
      if (!st.ok()) return error_.Record(f, st);
      for (std::size_t k = begin; k < end; ++k) {
        StatusOr<Float3> d = MapVector(f, s, k - begin);
        if (!d.ok()) return error_.Record(f, d.status());
        record_vectors_[order[k]] = *d;
      }
    });
    if (error_.failed()) return error_.status();
    return Status::Ok();
  }

  // 5. Shared vertices: each point evaluated on its first face, displaced by the mean of all
  // faces, or with per-face displacement each face's copy by that face's own value.
  Status PlaceSharedVertices() {
    std::vector<std::pair<std::int32_t, std::int32_t>> owners(num_points_);  // (face, point)
    for (std::size_t v = 0; v < num_points_; ++v) {
      owners[v] = {records_[point_records_[v]].face, static_cast<std::int32_t>(v)};
    }
    std::sort(owners.begin(), owners.end());
    std::vector<std::size_t> owner_start;
    for (std::size_t k = 0; k < owners.size(); ++k) {
      if (k == 0 || owners[k].first != owners[k - 1].first) owner_start.push_back(k);
    }
    owner_start.push_back(owners.size());
    tbb::parallel_for(std::size_t{0}, owner_start.size() - 1, [&](std::size_t g) {
      const std::size_t begin = owner_start[g], end = owner_start[g + 1];
      const int f = owners[begin].first;
      Scratch& s = scratch_.local();
      s.uv.resize(2 * (end - begin));
      s.p.resize(3 * (end - begin));
      s.nrm.resize(3 * (end - begin));
      for (std::size_t k = begin; k < end; ++k) {
        const Record& r = records_[point_records_[static_cast<std::size_t>(owners[k].second)]];
        s.uv[2 * (k - begin)] = r.u;
        s.uv[2 * (k - begin) + 1] = r.v;
      }
      Status st = EvaluatorForThread().EvaluatePoints(PtexFaceId(f), s.uv, s.p, s.nrm);
      if (!st.ok()) return error_.Record(f, st);
      for (std::size_t k = begin; k < end; ++k) {
        const auto v = static_cast<std::size_t>(owners[k].second);
        if (space_) {
          if (per_face_) {
            for (std::size_t c = point_copies_[v]; c < point_copies_[v + 1]; ++c) {
              Place(c, s, k - begin, record_vectors_[copy_records_[c]]);
            }
            continue;
          }
          double sum[3] = {0, 0, 0};
          for (std::size_t r = point_records_[v]; r < point_records_[v + 1]; ++r) {
            const Float3& d = record_vectors_[r];
            sum[0] += d.x, sum[1] += d.y, sum[2] += d.z;
          }
          const double count = double(point_records_[v + 1] - point_records_[v]);
          Place(v, s, k - begin,
                Float3{static_cast<float>(sum[0] / count), static_cast<float>(sum[1] / count),
                       static_cast<float>(sum[2] / count)});
          continue;
        }
        if (per_face_) {
          for (std::size_t c = point_copies_[v]; c < point_copies_[v + 1]; ++c) {
            const Record& own = records_[copy_records_[c]];
            float h = 0;
            if (map_) {
              h = map_->Sample(PtexFaceId(own.face), own.u, own.v, channel_);
              if (!std::isfinite(h)) return error_.Record(own.face, MapValueError(*map_, own.face));
            }
            Place(c, s, k - begin, h);
          }
          continue;
        }
        float h = 0;
        if (map_) {
          double sum = 0;
          for (std::size_t r = point_records_[v]; r < point_records_[v + 1]; ++r) {
            const float value =
                map_->Sample(PtexFaceId(records_[r].face), records_[r].u, records_[r].v, channel_);
            if (!std::isfinite(value))
              return error_.Record(records_[r].face, MapValueError(*map_, records_[r].face));
            sum += value;
          }
          h = static_cast<float>(sum / double(point_records_[v + 1] - point_records_[v]));
        }
        Place(v, s, k - begin, h);
      }
    });
    if (error_.failed()) return error_.status();
    return Status::Ok();
  }

  // 6. Interior points and triangles, face by face.
  Status FillFaces() {
    tbb::parallel_for(0, n_, [&](int f) {
      if (!Active(f)) return;
      Scratch& s = scratch_.local();
      Status st = PlaceInteriorVertices(f, s);
      if (!st.ok()) return error_.Record(f, st);
      EmitTriangles(f, s);
    });
    if (error_.failed()) return error_.status();
    return Status::Ok();
  }

  // Interior grid points, then the centres of stitched cells.
  Status PlaceInteriorVertices(int f, Scratch& s) {
    const int kx = Kx(f), ky = Ky(f);
    s.uv.clear();
    for (int j = 1; j < ky; ++j) {
      for (int i = 1; i < kx; ++i) {
        s.uv.push_back(float(i) / float(kx));
        s.uv.push_back(float(j) / float(ky));
      }
    }
    for (int j = 0; j < ky; ++j) {
      for (int i = 0; i < kx; ++i) {
        if (Stitched(f, i, j)) {
          s.uv.push_back((float(i) + 0.5f) / float(kx));
          s.uv.push_back((float(j) + 0.5f) / float(ky));
        }
      }
    }
    const std::size_t count = s.uv.size() / 2;
    const auto first = static_cast<std::size_t>(vertex_start_[static_cast<std::size_t>(f)]);
    DISPEX_CHECK_EQ(first + count,
                    static_cast<std::size_t>(vertex_start_[static_cast<std::size_t>(f) + 1]));
    if (count == 0) return Status::Ok();
    DISPEX_RETURN_IF_ERROR(Evaluate(f, s));
    for (std::size_t k = 0; k < count; ++k) {
      if (space_) {
        DISPEX_ASSIGN_OR_RETURN(const Float3 d, MapVector(f, s, k));
        Place(first + k, s, k, d);
        continue;
      }
      float h = 0;
      if (map_) {
        h = map_->Sample(PtexFaceId(f), s.uv[2 * k], s.uv[2 * k + 1], channel_);
        if (!std::isfinite(h)) return MapValueError(*map_, f);
      }
      Place(first + k, s, k, h);
    }
    return Status::Ok();
  }

  // Two triangles per plain cell (split along the shorter diagonal), a fan around the centre
  // for a stitched one.
  void EmitTriangles(int f, Scratch& s) {
    const int kx = Kx(f), ky = Ky(f);
    const auto first = static_cast<std::size_t>(vertex_start_[static_cast<std::size_t>(f)]);
    Mesh& mesh = out_.mesh;
    auto shared = [&](int side, int i) { return SharedVertex(f, side, GridPoint(f, side, i)); };
    auto grid_vertex = [&](int i, int j) -> std::int32_t {
      if (j == 0) return shared(0, i);
      if (i == kx) return shared(1, j);
      if (j == ky) return shared(2, kx - i);
      if (i == 0) return shared(3, ky - j);
      return static_cast<std::int32_t>(first + std::size_t(j - 1) * (kx - 1) + (i - 1));
    };
    // Appends the points strictly between grid points i and i + 1 of a side.
    auto append_between = [&](int side, int i) {
      const std::int64_t a = GridPoint(f, side, i), b = GridPoint(f, side, i + 1);
      const std::int64_t step = b > a ? 1 : -1;
      for (std::int64_t p = a + step; p != b; p += step) {
        s.polygon.push_back(SharedVertex(f, side, p));
      }
    };
    std::int32_t* tri = mesh.face_indices.data() + 3 * triangle_start_[static_cast<std::size_t>(f)];
    auto emit = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
      *tri++ = a;
      *tri++ = b;
      *tri++ = c;
    };
    auto centre = static_cast<std::int32_t>(first + std::size_t(kx - 1) * (ky - 1));
    for (int j = 0; j < ky; ++j) {
      for (int i = 0; i < kx; ++i) {
        const std::int32_t a = grid_vertex(i, j), b = grid_vertex(i + 1, j);
        const std::int32_t c = grid_vertex(i + 1, j + 1), d = grid_vertex(i, j + 1);
        if (!Stitched(f, i, j)) {
          const auto& P = mesh.positions;
          if (Length2(Sub(P[static_cast<std::size_t>(a)], P[static_cast<std::size_t>(c)])) <=
              Length2(Sub(P[static_cast<std::size_t>(b)], P[static_cast<std::size_t>(d)]))) {
            emit(a, b, c);
            emit(a, c, d);
          } else {
            emit(a, b, d);
            emit(b, c, d);
          }
          continue;
        }
        s.polygon.clear();
        s.polygon.push_back(a);
        if (j == 0) append_between(0, i);
        s.polygon.push_back(b);
        if (i == kx - 1) append_between(1, j);
        s.polygon.push_back(c);
        if (j == ky - 1) append_between(2, kx - 1 - i);
        s.polygon.push_back(d);
        if (i == 0) append_between(3, ky - 1 - j);
        for (std::size_t k = 0; k < s.polygon.size(); ++k) {
          emit(centre, s.polygon[k], s.polygon[(k + 1) % s.polygon.size()]);
        }
        ++centre;
      }
    }
    DISPEX_CHECK(tri ==
                 mesh.face_indices.data() + 3 * triangle_start_[static_cast<std::size_t>(f) + 1]);
  }

  // 7. Smooth normals. With per-face displacement the copies of a point that sit at the same
  // displaced position (the faces' values agree there) are one vertex for the average, so the
  // shading is smooth where the surface is and shows a seam where it cracks.
  void SmoothNormals() {
    const Mesh& mesh = out_.mesh;
    std::vector<Float3> triangle_normals(mesh.face_indices.size() / 3);
    tbb::parallel_for(std::size_t{0}, triangle_normals.size(), [&](std::size_t t) {
      const Float3& a = mesh.positions[static_cast<std::size_t>(mesh.face_indices[3 * t])];
      const Float3& b = mesh.positions[static_cast<std::size_t>(mesh.face_indices[3 * t + 1])];
      const Float3& c = mesh.positions[static_cast<std::size_t>(mesh.face_indices[3 * t + 2])];
      const Float3 e1 = Sub(b, a), e2 = Sub(c, a);
      // A float cross product, not Vec3d's Cross: in double a third of the components round
      // differently, and the normals (and pixels) would change.
      triangle_normals[t] = {e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z,
                             e1.x * e2.y - e1.y * e2.x};
    });
    if (!per_face_) {
      VertexNormals(mesh.positions.size(), mesh.face_offsets, mesh.face_indices, triangle_normals,
                    limit_normals_, out_.normals);
      return;
    }
    // Each copy stands for the lowest-numbered copy of its point at the same position.
    std::vector<std::int32_t> joined(num_shared_);
    tbb::parallel_for(std::size_t{0}, num_points_, [&](std::size_t k) {
      for (std::size_t c = point_copies_[k]; c < point_copies_[k + 1]; ++c) {
        joined[c] = static_cast<std::int32_t>(c);
        for (std::size_t d = point_copies_[k]; d < c; ++d) {
          if (std::memcmp(&mesh.positions[c], &mesh.positions[d], sizeof(Float3)) == 0) {
            joined[c] = static_cast<std::int32_t>(d);
            break;
          }
        }
      }
    });
    std::vector<std::int32_t> indices(mesh.face_indices.size());
    tbb::parallel_for(std::size_t{0}, indices.size(), [&](std::size_t i) {
      const std::int32_t v = mesh.face_indices[i];
      const auto k = static_cast<std::size_t>(v);
      indices[i] = k < num_shared_ ? joined[k] : v;
    });
    VertexNormals(mesh.positions.size(), mesh.face_offsets, indices, triangle_normals,
                  limit_normals_, out_.normals);
    for (std::size_t c = 0; c < num_shared_; ++c) {
      out_.normals[c] = out_.normals[static_cast<std::size_t>(joined[c])];
    }
  }

  const Mesh& cage_;
  const LimitSurface& surface_;
  std::span<const std::array<int, 2>> density_;
  const PtexFile* map_;
  int channel_;
  bool per_face_;                     // BoundaryDisplacement::kPerFace
  std::optional<VectorSpace> space_;  // a vector map's
  int n_;                             // Ptex faces

  std::vector<SideEntry> entries_;         // face sides, by line
  std::vector<std::int64_t> entry_of_;     // 4 f + side -> its entry, or -1
  std::vector<std::int64_t> grid_offset_;  // entry -> its first grid point
  std::vector<std::size_t> line_start_;    // entries of line g: [line_start_[g], [g + 1])
  std::size_t num_lines_ = 0;
  std::vector<std::int64_t> entry_grid_point_;  // grid point -> merged line point
  std::vector<Frac> line_point_frac_;
  std::vector<std::int64_t> line_point_count_;
  std::vector<Record> records_;
  std::vector<std::int32_t> line_point_vertex_;  // line point -> its vertex (mean displacement)
  std::vector<std::size_t> point_records_;       // records of point i: [point_records_[i], [i + 1])
  std::size_t num_points_ = 0;
  // Per-face displacement only (see NumberFaceCopies).
  std::vector<std::size_t> copy_records_, point_copies_;
  std::vector<std::int64_t> entry_point_offset_;
  std::vector<std::int32_t> entry_point_vertex_;
  std::size_t num_shared_ = 0;  // vertices 0 .. num_shared_ - 1 are the shared points' (copies)
  std::vector<Float3> record_vectors_;  // a vector map's D per record (RecordVectors)
  std::vector<std::int64_t> vertex_start_, triangle_start_;  // per face, prefix sums

  ShadedMesh out_;
  std::vector<Float3> limit_normals_;
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators_;
  tbb::enumerable_thread_specific<Scratch> scratch_;
  FirstError error_;
};

}  // namespace

StatusOr<ShadedMesh> TessellateLimitSurface(const Mesh& cage, const LimitSurface& surface,
                                            std::span<const std::array<int, 2>> density,
                                            const PtexFile* map, int channel,
                                            BoundaryDisplacement boundary,
                                            std::optional<VectorSpace> vector_space) {
  return Tessellation(cage, surface, density, map, channel, boundary, vector_space).Run();
}

}  // namespace dispex::render
