// Ground-truth sculpts: the cage refined uniformly with OpenSubdiv, or a jittered triangulated
// grid on every Ptex face, every vertex on the limit surface and moved by a known displacement
// D (pattern_field.h: h along the limit normal, or a vector pattern), which is evaluated at
// each vertex's (Ptex face, u, v), limit position and normal.
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <unordered_map>

#include "core/atomic_output.h"
#include "core/enum_names.h"
#include "core/system.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"
#include "verify/pattern_field.h"
#include "verify/streamed_sculpt.h"

namespace dispex {

namespace {

// The sculpt before displacement: vertices on the limit surface, and where each face lies.
struct SculptLayoutMesh {
  Mesh mesh;
  std::vector<float> normals;          // 3 per vertex
  std::vector<PtexFaceId> ptex_faces;  // per vertex: the Ptex face of its truth record...
  std::vector<float> uvs;              // ...and its (u, v) there
  std::vector<PtexFaceId> face_ptex;   // per face: the Ptex face containing it...
  std::vector<float> corner_uvs;       // ...and its corners' (u, v) there, 2 per face corner
};

std::uint64_t Mix(std::uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}
// Uniform in [-1, 1), a pure function of its arguments.
double Jitter(std::uint32_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  std::uint64_t h = Mix(Mix(Mix(Mix(seed) ^ a) ^ b) ^ c);
  return double(h >> 11) * 0x1.0p-52 - 1.0;
}

constexpr double kJitter = 0.3;  // of a cell

struct KeyHash {
  std::size_t operator()(const std::array<std::int64_t, 4>& k) const {
    return Mix(Mix(Mix(Mix(std::uint64_t(k[0])) ^ std::uint64_t(k[1])) ^ std::uint64_t(k[2])) ^
               std::uint64_t(k[3]));
  }
};

using Key = std::array<std::int64_t, 4>;

// `n` cells per side of a quad Ptex face, n / 2 on n-gon sub-faces, so that both sides of a
// base edge have n cells. A vertex on the base is named by where it lies: a cage vertex, step
// j of a base edge (from its lower vertex), step r of the spoke from edge k's midpoint to
// the centre of an n-gon, the centre, or a Ptex face's interior grid point. Jitter is a
// function of that name, so every Ptex face touching a vertex puts it at the same place.
class JitteredNames {
 public:
  JitteredNames(const Mesh& cage, const LimitSurface& surface, int n, std::uint32_t seed)
      : cage_(cage), surface_(surface), n_(n), half_(n / 2), seed_(seed) {}

  // A point of base edge (a, b) at step p of n from a: its name and its place in [0, 1] from a.
  double EdgePoint(std::int32_t a, std::int32_t b, int p, Key& key) const {
    const std::int32_t lo = std::min(a, b), hi = std::max(a, b);
    const int j = a < b ? p : n_ - p;
    double q;
    if (j == 0 || j == n_) {
      key = {0, j == 0 ? lo : hi, 0, 0};
      q = j == 0 ? 0 : 1;
    } else {
      key = {1, lo, hi, j};
      q = (j + (2 * j == n_ ? 0.0
                            : kJitter * Jitter(seed_, std::uint64_t(lo), std::uint64_t(hi),
                                               std::uint64_t(j)))) /
          n_;
    }
    return a < b ? q : 1 - q;
  }

  // Step r of `half` on spoke k of base face `face` (r = 0: edge k's midpoint).
  double SpokePoint(BaseFaceId face, std::span<const std::int32_t> fv, int k, int r,
                    Key& key) const {
    if (r == 0) {
      EdgePoint(fv[k], fv[(k + 1) % fv.size()], half_, key);
      return 0.0;
    }
    if (r == half_) {
      key = {2, face.value, 0, 0};
      return 1.0;
    }
    key = {3, face.value, k, r};
    return (r + kJitter * Jitter(seed_, std::uint64_t(face.value) + (1ull << 40), std::uint64_t(k),
                                 std::uint64_t(r))) /
           half_;
  }

  // Slot (i, j) of Ptex face f on edge e at step t (counter-clockwise): its name and (u, v).
  void BoundaryPoint(int f, int e, int t, Key& key, float* uv) const {
    PtexFaceId face(f);
    BaseFaceId base = surface_.base_face(face);
    auto fv = cage_.face(std::size_t(base.value));
    const int size = static_cast<int>(fv.size());
    double s;
    if (size == 4) {
      s = EdgePoint(fv[e], fv[(e + 1) % 4], t, key);
    } else {
      const int k = surface_.sub_face(face);
      switch (e) {
        case 0:
          s = 2 * EdgePoint(fv[k], fv[(k + 1) % size], t, key);
          break;
        case 1:
          s = SpokePoint(base, fv, k, t, key);
          break;
        case 2:
          s = 1 - SpokePoint(base, fv, (k + size - 1) % size, half_ - t, key);
          break;
        default:
          s = 2 * EdgePoint(fv[(k + size - 1) % size], fv[k], half_ + t, key) - 1;
          break;
      }
    }
    const double p[4][2] = {{s, 0}, {1, s}, {1 - s, 1}, {0, 1 - s}};
    uv[0] = static_cast<float>(std::clamp(p[e][0], 0.0, 1.0));
    uv[1] = static_cast<float>(std::clamp(p[e][1], 0.0, 1.0));
  }

 private:
  const Mesh& cage_;
  const LimitSurface& surface_;
  const int n_, half_;
  const std::uint32_t seed_;
};

Status CheckDensity(const LimitSurface& surface, int n) {
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    BaseFaceId base = surface.base_face(PtexFaceId(f));
    if (surface.base_face_size(base) != 4 && n % 2 != 0) {
      return Status::Error(
          fmt::format("density {}: the cage has n-gons, whose sub-faces take "
                      "density / 2 cells per side: must be even",
                      n));
    }
  }
  return Status::Ok();
}

// The grid points of every Ptex face, (cells + 1)^2 slots each (none for holes).
struct SlotGrid {
  std::vector<std::size_t> first_slot;  // per Ptex face, and the total at the end
  std::vector<int> cells;               // per Ptex face, per side
  std::size_t size() const { return first_slot.back(); }
  std::size_t operator()(int f, int i, int j) const {
    return first_slot[f] + std::size_t(j) * std::size_t(cells[f] + 1) + std::size_t(i);
  }
};

StatusOr<SlotGrid> PlanSlots(const LimitSurface& surface, int n) {
  const int faces = surface.num_ptex_faces();
  SlotGrid grid;
  grid.first_slot.assign(std::size_t(faces) + 1, 0);
  grid.cells.assign(std::size_t(faces), 0);
  for (int f = 0; f < faces; ++f) {
    const bool quad = surface.base_face_size(surface.base_face(PtexFaceId(f))) == 4;
    grid.cells[f] = surface.is_hole(PtexFaceId(f)) ? 0 : quad ? n : n / 2;
    const std::size_t side = std::size_t(grid.cells[f]) + 1;
    grid.first_slot[f + 1] = grid.first_slot[f] + (grid.cells[f] ? side * side : 0);
  }
  if (grid.size() >= (std::size_t{1} << 31)) {
    return Status::Error(
        fmt::format("density {}: {} Ptex faces would need more than 2^31 "
                    "vertices",
                    n, faces));
  }
  return grid;
}

// Every slot's (u, v) and vertex: one vertex per name, numbered in order of first use; its
// truth record is that first use, so the vertices each face adds are contiguous. Returns per
// Ptex face its first vertex (and the count at the end).
std::vector<std::size_t> NameVertices(const JitteredNames& names, const SlotGrid& grid,
                                      std::uint32_t seed, std::vector<float>& uv,
                                      std::vector<std::uint32_t>& vertex, SculptLayoutMesh& out) {
  const int faces = static_cast<int>(grid.cells.size());
  std::unordered_map<Key, std::uint32_t, KeyHash> ids;
  std::vector<std::size_t> first_vertex(std::size_t(faces) + 1, 0);
  for (int f = 0; f < faces; ++f) {
    first_vertex[f] = out.ptex_faces.size();
    const int m = grid.cells[f];
    for (int j = 0; j <= m && m > 0; ++j) {
      for (int i = 0; i <= m; ++i) {
        const std::size_t s = grid(f, i, j);
        Key key;
        if (i > 0 && i < m && j > 0 && j < m) {
          key = {4, f, i, j};
          uv[2 * s] = static_cast<float>((i + kJitter * Jitter(seed, s, 0, 1)) / m);
          uv[2 * s + 1] = static_cast<float>((j + kJitter * Jitter(seed, s, 0, 2)) / m);
        } else {
          const int e = j == 0 ? 0 : i == m ? 1 : j == m ? 2 : 3;
          const int t = e == 0 ? i : e == 1 ? j : e == 2 ? m - i : m - j;
          names.BoundaryPoint(f, e, t, key, &uv[2 * s]);
        }
        auto [it, added] = ids.try_emplace(key, std::uint32_t(out.ptex_faces.size()));
        vertex[s] = it->second;
        if (added) {
          out.ptex_faces.push_back(PtexFaceId(f));
          out.uvs.push_back(uv[2 * s]);
          out.uvs.push_back(uv[2 * s + 1]);
        }
      }
    }
  }
  first_vertex[faces] = out.ptex_faces.size();
  return first_vertex;
}

// Two triangles per cell, counter-clockwise in (u, v) as the Ptex face is: the diagonal picked
// at random, unless that one folds a triangle in (u, v).
void Triangulate(const SlotGrid& grid, std::uint32_t seed, const std::vector<float>& uv,
                 const std::vector<std::uint32_t>& vertex, SculptLayoutMesh& out) {
  out.mesh.face_offsets.push_back(0);
  for (int f = 0; f < static_cast<int>(grid.cells.size()); ++f) {
    const int m = grid.cells[f];
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        const std::size_t c[4] = {grid(f, i, j), grid(f, i + 1, j), grid(f, i + 1, j + 1),
                                  grid(f, i, j + 1)};
        auto area = [&](int a, int b, int d) {
          const float* p = &uv[2 * c[a]];
          const float* q = &uv[2 * c[b]];
          const float* r = &uv[2 * c[d]];
          return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
        };
        bool first = Jitter(seed, grid(f, i, j), 0, 4) < 0;
        if (first && !(area(0, 1, 2) > 0 && area(0, 2, 3) > 0)) first = false;
        if (!first && !(area(0, 1, 3) > 0 && area(1, 2, 3) > 0)) first = true;
        const int tris[2][2][3] = {{{0, 1, 3}, {1, 2, 3}}, {{0, 1, 2}, {0, 2, 3}}};
        for (const auto& tri : tris[first ? 1 : 0]) {
          for (int k : tri) {
            out.mesh.face_indices.push_back(std::int32_t(vertex[c[k]]));
            out.corner_uvs.push_back(uv[2 * c[k]]);
            out.corner_uvs.push_back(uv[2 * c[k] + 1]);
          }
          out.mesh.face_offsets.push_back(std::uint32_t(out.mesh.face_indices.size()));
          out.face_ptex.push_back(PtexFaceId(f));
        }
      }
    }
  }
}

// Each vertex's limit position and normal at its (Ptex face, u, v), a Ptex face at a time.
Status PlaceOnLimitSurface(const LimitSurface& surface,
                           const std::vector<std::size_t>& first_vertex, SculptLayoutMesh& out) {
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<std::vector<float>> positions;
  std::atomic<bool> failed{false};
  tbb::parallel_for(0, surface.num_ptex_faces(), [&](int f) {
    const std::size_t begin = first_vertex[f], end = first_vertex[f + 1];
    if (begin == end) return;
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    std::vector<float>& p = positions.local();
    p.resize(3 * (end - begin));
    std::span<const float> uvs(&out.uvs[2 * begin], 2 * (end - begin));
    std::span<float> nrm(&out.normals[3 * begin], 3 * (end - begin));
    if (!evaluator->EvaluatePoints(PtexFaceId(f), uvs, p, nrm).ok()) failed = true;
    for (std::size_t v = begin; v < end; ++v) {
      const float* q = &p[3 * (v - begin)];
      out.mesh.positions[v] = Float3{q[0], q[1], q[2]};
    }
  });
  if (failed) return Status::Error("evaluating the limit surface at a sculpt vertex failed");
  return Status::Ok();
}

// The jittered layout (JitteredNames): `n` cells per side of a quad Ptex face.
StatusOr<SculptLayoutMesh> BuildJittered(const Mesh& cage, const LimitSurface& surface, int n,
                                         std::uint32_t seed) {
  DISPEX_RETURN_IF_ERROR(CheckDensity(surface, n));
  DISPEX_ASSIGN_OR_RETURN(const SlotGrid grid, PlanSlots(surface, n));
  std::vector<float> uv(2 * grid.size());
  std::vector<std::uint32_t> vertex(grid.size());
  SculptLayoutMesh out;
  const std::vector<std::size_t> first_vertex =
      NameVertices(JitteredNames(cage, surface, n, seed), grid, seed, uv, vertex, out);
  const std::size_t count = out.ptex_faces.size();
  out.mesh.positions.resize(count);
  out.normals.resize(3 * count);
  Triangulate(grid, seed, uv, vertex, out);
  DISPEX_RETURN_IF_ERROR(PlaceOnLimitSurface(surface, first_vertex, out));
  return out;
}

SculptLayoutMesh FromRefined(RefinedMesh&& refined) {
  SculptLayoutMesh out;
  out.mesh = std::move(refined.mesh);
  out.normals = std::move(refined.normals);
  out.ptex_faces = std::move(refined.ptex_faces);
  out.uvs = std::move(refined.uvs);
  out.face_ptex = std::move(refined.face_ptex);
  out.corner_uvs = std::move(refined.face_uvs);  // quads: 8 per face, 2 per corner
  return out;
}

struct SculptQuality {
  std::vector<float> face_errors;
  double linear_error = 0;
  std::size_t folded_faces = 0;
};

// Points of a face in (u, v), with the linear surface there: the edge midpoints, and the centre
// of a quad (measured against both diagonals' midpoints: FaceError) or a triangle's centroid.
struct FacePoints {
  float uv[10];
  double linear[5][3];
  int points = 0;
};

// `c`: the (u, v) of the face's corners.
void PointsOfFace(const Mesh& mesh, std::span<const std::int32_t> face, const float* c,
                  FacePoints& out) {
  auto add = [&](std::initializer_list<std::size_t> corners) {
    double w = 1.0 / double(corners.size());
    const int points = out.points;
    out.uv[2 * points] = out.uv[2 * points + 1] = 0;
    for (int d = 0; d < 3; ++d) out.linear[points][d] = 0;
    for (std::size_t k : corners) {
      out.uv[2 * points] += float(w * c[2 * k]);
      out.uv[2 * points + 1] += float(w * c[2 * k + 1]);
      Float3 q = mesh.positions[static_cast<std::size_t>(face[k])];
      out.linear[points][0] += w * q.x, out.linear[points][1] += w * q.y,
          out.linear[points][2] += w * q.z;
    }
    ++out.points;
  };
  if (face.size() == 4) {
    add({0, 1, 2, 3});
    add({0, 1});
    add({1, 2});
    add({2, 3});
    add({3, 0});
  } else {
    add({0, 1, 2});
    add({0, 1});
    add({1, 2});
    add({2, 0});
  }
}

// The largest distance from the true displaced surface (limit points p, normals n at the
// face's points) to the face.
double FaceError(const Mesh& mesh, std::span<const std::int32_t> face, PtexFaceId ptex,
                 const FacePoints& at, const float* p, const float* n,
                 const verify::PatternField& pattern) {
  auto corner = [&](std::size_t k) { return mesh.positions[static_cast<std::size_t>(face[k])]; };
  double worst = 0;
  for (int s = 0; s < at.points; ++s) {
    double disp[3];
    pattern.Displacement(ptex, at.uv[2 * s], at.uv[2 * s + 1], &p[3 * s], &n[3 * s], disp);
    double truth[3] = {p[3 * s] + disp[0], p[3 * s + 1] + disp[1], p[3 * s + 2] + disp[2]};
    auto distance = [&](const double* q) {
      double dx = q[0] - truth[0], dy = q[1] - truth[1], dz = q[2] - truth[2];
      return std::sqrt(dx * dx + dy * dy + dz * dz);
    };
    if (face.size() == 4 && s == 0) {
      for (int d = 0; d < 2; ++d) {
        Float3 a = corner(d), b = corner(d + 2);
        double mid[3] = {0.5 * (double(a.x) + b.x), 0.5 * (double(a.y) + b.y),
                         0.5 * (double(a.z) + b.z)};
        worst = std::max(worst, distance(mid));
      }
    } else {
      worst = std::max(worst, distance(at.linear[s]));
    }
  }
  return worst;
}

// Whether the face is turned inside out against the limit normal n (at its first point).
bool IsFolded(const Mesh& mesh, std::span<const std::int32_t> face, const float* n) {
  const std::size_t size = face.size();
  auto at = [&](std::size_t k) { return mesh.positions[static_cast<std::size_t>(face[k])]; };
  Float3 a = at(0), b = at(1), c2 = at(2), d = size == 4 ? at(3) : at(0);
  double e1[3], e2[3];
  if (size == 4) {  // the diagonals
    e1[0] = double(c2.x) - a.x, e1[1] = double(c2.y) - a.y, e1[2] = double(c2.z) - a.z;
    e2[0] = double(d.x) - b.x, e2[1] = double(d.y) - b.y, e2[2] = double(d.z) - b.z;
  } else {
    e1[0] = double(b.x) - a.x, e1[1] = double(b.y) - a.y, e1[2] = double(b.z) - a.z;
    e2[0] = double(c2.x) - a.x, e2[1] = double(c2.y) - a.y, e2[2] = double(c2.z) - a.z;
  }
  double fn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                  e1[0] * e2[1] - e1[1] * e2[0]};
  return fn[0] * n[0] + fn[1] * n[1] + fn[2] * n[2] < 0;
}

// Face f's error (FaceError) and whether it folds; false when the limit surface could not be
// evaluated. Faces other than triangles and quads are left alone.
bool MeasureFace(LimitEvaluator& evaluator, const SculptLayoutMesh& layout,
                 const verify::PatternField& pattern, std::size_t f, float& error,
                 std::uint8_t& folded) {
  const Mesh& mesh = layout.mesh;
  auto face = mesh.face(f);
  const std::size_t size = face.size();
  if (size != 3 && size != 4) return true;
  FacePoints at;
  PointsOfFace(mesh, face, &layout.corner_uvs[2 * mesh.face_offsets[f]], at);
  const int points = at.points;
  float p[15], n[15];
  if (!evaluator
           .EvaluatePoints(layout.face_ptex[f], std::span<const float>(at.uv, 2 * points),
                           std::span<float>(p, 3 * points), std::span<float>(n, 3 * points))
           .ok()) {
    return false;
  }
  error = static_cast<float>(FaceError(mesh, face, layout.face_ptex[f], at, p, n, pattern));
  folded = IsFolded(mesh, face, n);
  return true;
}

// See MakeSculptReport::linear_error and folded_faces. `layout.mesh` already holds the
// displaced positions.
StatusOr<SculptQuality> MeasureSculpt(const LimitSurface& surface, const SculptLayoutMesh& layout,
                                      const verify::PatternField& pattern) {
  const std::size_t faces = layout.mesh.num_faces();
  SculptQuality quality;
  quality.face_errors.assign(faces, 0.0f);
  std::vector<std::uint8_t> folded(faces, 0);
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  std::atomic<bool> failed{false};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, faces, 1024),
      [&](const tbb::blocked_range<std::size_t>& range) {
        auto& evaluator = evaluators.local();
        if (!evaluator) evaluator.emplace(surface);
        for (std::size_t f = range.begin(); f < range.end(); ++f) {
          if (!MeasureFace(*evaluator, layout, pattern, f, quality.face_errors[f], folded[f])) {
            failed = true;
            return;
          }
        }
      });
  if (failed) return Status::Error("evaluating the limit surface at a sculpt face centre failed");
  if (faces) {
    quality.linear_error =
        *std::max_element(quality.face_errors.begin(), quality.face_errors.end());
  }
  for (std::uint8_t f : folded) quality.folded_faces += f;
  // No bound holds near a fold of a scalar pattern (rays along the normal can meet another
  // sheet): infinite local error there. The vector patterns' truth is D itself, which a fold
  // along the normal does not make ambiguous (kOverhang folds by design), so their faces keep
  // their measured error.
  if (!pattern.vector()) {
    for (std::size_t f = 0; f < faces; ++f) {
      if (folded[f]) quality.face_errors[f] = std::numeric_limits<float>::infinity();
    }
  }
  return quality;
}

// Per vertex, the largest face error within two rings: the faces around the vertex and every
// face touching them. A map's value at the vertex is read from the samples around it, which
// lie within one sample spacing (at most half a sculpt edge) and whose rays meet faces of the
// one-ring; the second ring covers rays that leave the one-ring sideways (the normal turns
// between the base and the sculpt) and uneven cells (jittered layouts).
std::vector<float> LocalErrors(const Mesh& mesh, const std::vector<float>& face_errors) {
  std::vector<float> ring1(mesh.num_vertices(), 0.0f), local(mesh.num_vertices(), 0.0f);
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    for (std::int32_t v : mesh.face(f)) ring1[v] = std::max(ring1[v], face_errors[f]);
  }
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    float m = 0;
    for (std::int32_t v : mesh.face(f)) m = std::max(m, ring1[v]);
    for (std::int32_t v : mesh.face(f)) local[v] = std::max(local[v], m);
  }
  return local;
}

constexpr auto kSculptLayoutNames = EnumTable<SculptLayout>({
    {SculptLayout::kRefined, "refined"},
    {SculptLayout::kJittered, "jittered"},
});

}  // namespace

std::string_view SculptLayoutName(SculptLayout layout) {
  return EnumName(kSculptLayoutNames, layout);
}

StatusOr<SculptLayout> ParseSculptLayout(std::string_view name) {
  return ParseEnum(kSculptLayoutNames, "layout", name);
}

namespace {

// The options' ranges and combinations, before any work.
Status CheckMakeSculptOptions(const MakeSculptOptions& options) {
  const bool jittered = options.layout == SculptLayout::kJittered;
  if (!jittered && (options.levels < 1 || options.levels > 8)) {
    return Status::Error(fmt::format("levels = {}: must be 1..8", options.levels));
  }
  if (jittered && (options.density < 2 || options.density > 256)) {
    return Status::Error(
        fmt::format("density {}: the jittered layout needs 2..256 cells per "
                    "Ptex face side",
                    options.density));
  }
  if (!jittered && options.density != 0) {
    return Status::Error(
        fmt::format("density {}: only the jittered layout has a density", options.density));
  }
  if (!(std::isfinite(options.amplitude) && options.amplitude >= 0)) {
    return Status::Error(fmt::format("amplitude = {}: must be >= 0", options.amplitude));
  }
  if (options.output_path.empty()) return Status::Error("no output file given (output_path)");
  if (MeshFormatOfName(options.output_path) == MeshFormat::kUnknown) {
    return Status::Error(fmt::format("{}: output_path must name an OBJ or PLY file (.obj or .ply)",
                                     options.output_path));
  }
  if (options.output_path == options.cage_path) {
    return Status::Error("the output must differ from the cage");
  }
  if (options.pattern == Pattern::kImage && options.image_path.empty()) {
    return Status::Error("the image pattern needs a height image (image:FILE.png)");
  }
  if (options.streamed) {
    if (jittered) return Status::Error("streamed: only the refined layout is streamed");
    if (MeshFormatOfName(options.output_path) != MeshFormat::kPly) {
      return Status::Error(
          fmt::format("{}: a streamed sculpt is written as PLY (.ply)", options.output_path));
    }
    if (!options.truth_path.empty()) {
      return Status::Error("streamed: a streamed sculpt has no truth file (truth_path)");
    }
  }
  return Status::Ok();
}

// What the pattern is evaluated with: the cage's bounding box, the sculpt's edge length, the
// amplitude (1% of the diagonal unless given) and the seed.
PatternFrame FrameFor(const Mesh& cage, const MakeSculptOptions& options) {
  const bool jittered = options.layout == SculptLayout::kJittered;
  BoundingBox box = ComputeBounds(cage);
  PatternFrame frame;
  frame.center[0] = 0.5f * (box.min.x + box.max.x);
  frame.center[1] = 0.5f * (box.min.y + box.max.y);
  frame.center[2] = 0.5f * (box.min.z + box.max.z);
  frame.diagonal = box.diagonal();
  frame.edge =
      MedianEdgeLength(cage) / (jittered ? double(options.density) : double(1 << options.levels));
  frame.amplitude = options.amplitude > 0 ? options.amplitude : 0.01 * frame.diagonal;
  frame.seed = options.seed;
  return frame;
}

// The sculpt before displacement, in the layout the options ask for.
StatusOr<SculptLayoutMesh> BuildLayout(const Mesh& cage, const LimitSurface& surface,
                                       const MakeSculptOptions& options) {
  if (options.layout == SculptLayout::kJittered) {
    return BuildJittered(cage, surface, options.density, options.seed);
  }
  RefineOptions refine_options;
  refine_options.face_charts = true;
  DISPEX_ASSIGN_OR_RETURN(RefinedMesh refined,
                          RefineUniform(surface, options.levels, refine_options));
  return FromRefined(std::move(refined));
}

// Moves every vertex of the layout by D and returns its truth (no local errors yet), with
// `tangential` the length of each vertex's D - (D.N) N.
GroundTruth Displace(SculptLayoutMesh& layout, const verify::PatternField& pattern,
                     std::vector<float>& tangential) {
  Mesh& sculpt = layout.mesh;
  const std::size_t n = sculpt.num_vertices();
  GroundTruth truth;
  truth.faces = layout.ptex_faces;
  truth.uvs = layout.uvs;
  truth.h.resize(n);
  truth.d.resize(3 * n);
  tangential.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v < range.end(); ++v) {
                        Float3& p = sculpt.positions[v];
                        const float xyz[3] = {p.x, p.y, p.z};
                        const float* normal = &layout.normals[3 * v];
                        double d[3], t;
                        const double h =
                            pattern.HeightAndDisplacement(truth.faces[v], truth.uvs[2 * v],
                                                          truth.uvs[2 * v + 1], xyz, normal, d, &t);
                        for (int i = 0; i < 3; ++i) truth.d[3 * v + i] = static_cast<float>(d[i]);
                        truth.h[v] = static_cast<float>(h);
                        tangential[v] = static_cast<float>(t);
                        p.x = static_cast<float>(p.x + d[0]);
                        p.y = static_cast<float>(p.y + d[1]);
                        p.z = static_cast<float>(p.z + d[2]);
                      }
                    });
  return truth;
}

// The sculpt's first line: how it was made.
std::string SculptComment(const MakeSculptOptions& options, const PatternFrame& frame) {
  const bool jittered = options.layout == SculptLayout::kJittered;
  const std::string pattern_name = options.pattern == Pattern::kImage
                                       ? "image:" + options.image_path
                                       : std::string(PatternName(options.pattern));
  const std::string how =
      jittered ? fmt::format("jittered {}x{} per Ptex face", options.density, options.density)
               : fmt::format("refined {} times", options.levels);
  return fmt::format("dispex make-sculpt: {} {}, pattern {}, amplitude {}, seed {}",
                     options.cage_path, how, pattern_name, frame.amplitude, options.seed);
}

// The sculpt and its truth file.
Status WriteSculpt(const MakeSculptOptions& options, const PatternFrame& frame, const Mesh& sculpt,
                   const GroundTruth& truth) {
  DISPEX_RETURN_IF_ERROR(WriteMesh(options.output_path, sculpt, SculptComment(options, frame)));
  std::string truth_path =
      options.truth_path.empty() ? options.output_path + ".truth" : options.truth_path;
  return WriteGroundTruth(truth_path, truth);
}

// The report's figures of the displacement (h, |D| and its tangential part).
void ReportDisplacement(const GroundTruth& truth, const std::vector<float>& tangential,
                        MakeSculptReport& report) {
  const std::size_t n = truth.h.size();
  if (!n) return;
  auto [lo, hi] = std::minmax_element(truth.h.begin(), truth.h.end());
  report.h_min = *lo;
  report.h_max = *hi;
  report.max_tangential = *std::max_element(tangential.begin(), tangential.end());
  for (std::size_t v = 0; v < n; ++v) {
    const float* d = &truth.d[3 * v];
    report.max_displacement =
        std::max(report.max_displacement,
                 std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]));
  }
}

// What every report says of the frame the pattern was evaluated in, and the cage's ignored tags.
MakeSculptReport FrameReport(const Mesh& cage, const PatternFrame& frame) {
  MakeSculptReport report;
  report.amplitude = frame.amplitude;
  report.diagonal = frame.diagonal;
  report.edge = frame.edge;
  report.frame = frame;
  report.warnings = IgnoredTagWarnings(cage);
  return report;
}

// MakeSculpt with options.streamed: the refinement written as it is evaluated, without truth.
StatusOr<MakeSculptReport> MakeStreamedSculpt(const MakeSculptOptions& options, const Mesh& cage,
                                              const LimitSurface& surface,
                                              const PatternFrame& frame,
                                              const verify::PatternField& pattern,
                                              const Stopwatch& clock) {
  DISPEX_ASSIGN_OR_RETURN(
      verify::StreamedSculpt sculpt,
      verify::WriteStreamedRefinement(cage, surface, options.levels, pattern, options.output_path,
                                      SculptComment(options, frame)));
  MakeSculptReport report = FrameReport(cage, frame);
  report.vertices = sculpt.vertices;
  report.faces = sculpt.faces;
  report.h_min = sculpt.h_min;
  report.h_max = sculpt.h_max;
  report.max_displacement = sculpt.max_displacement;
  report.max_tangential = sculpt.max_tangential;
  report.linear_error = std::numeric_limits<double>::quiet_NaN();
  report.seconds = clock.seconds();
  return report;
}

}  // namespace

StatusOr<MakeSculptReport> MakeSculpt(const MakeSculptOptions& options) {
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(CheckMakeSculptOptions(options).WithCode(StatusCode::kInvalidArgument));
  std::optional<tbb::global_control> limit;
  if (options.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism,
                  static_cast<std::size_t>(options.threads));
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh cage, ReadMesh(options.cage_path));
  DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(cage));
  const PatternFrame frame = FrameFor(cage, options);
  // Before the refinement, so that a bad image or a cage without UVs fails at once.
  DISPEX_ASSIGN_OR_RETURN(
      verify::PatternField pattern,
      verify::PatternField::Create(options.pattern, options.image_path, frame, cage, surface));
  if (options.streamed) return MakeStreamedSculpt(options, cage, surface, frame, pattern, clock);
  DISPEX_ASSIGN_OR_RETURN(SculptLayoutMesh layout, BuildLayout(cage, surface, options));

  std::vector<float> tangential;
  GroundTruth truth = Displace(layout, pattern, tangential);
  const Mesh& sculpt = layout.mesh;
  DISPEX_ASSIGN_OR_RETURN(SculptQuality quality, MeasureSculpt(surface, layout, pattern));
  truth.local_error = LocalErrors(sculpt, quality.face_errors);
  DISPEX_RETURN_IF_ERROR(WriteSculpt(options, frame, sculpt, truth));

  MakeSculptReport report = FrameReport(cage, frame);
  report.vertices = sculpt.num_vertices();
  report.faces = sculpt.num_faces();
  ReportDisplacement(truth, tangential, report);
  report.linear_error = quality.linear_error;
  report.folded_faces = quality.folded_faces;
  report.seconds = clock.seconds();
  return report;
}

}  // namespace dispex
