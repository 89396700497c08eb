#include "subdiv_test_util.h"

#include <gtest/gtest.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <cmath>

namespace dispex::subdiv_test {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

Mesh MakeMesh(std::vector<Float3> positions, const std::vector<std::vector<int>>& faces,
              std::string name) {
  Mesh mesh;
  mesh.source = std::move(name);
  mesh.positions = std::move(positions);
  mesh.face_offsets.push_back(0);
  for (const auto& f : faces) {
    for (int v : f) mesh.face_indices.push_back(v);
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.face_indices.size()));
  }
  return mesh;
}

Mesh MakeCube() {
  return MakeMesh(
      {{-0.5f, -0.5f, 0.5f},
       {0.5f, -0.5f, 0.5f},
       {-0.5f, 0.5f, 0.5f},
       {0.5f, 0.5f, 0.5f},
       {-0.5f, 0.5f, -0.5f},
       {0.5f, 0.5f, -0.5f},
       {-0.5f, -0.5f, -0.5f},
       {0.5f, -0.5f, -0.5f}},
      {{0, 1, 3, 2}, {2, 3, 5, 4}, {4, 5, 7, 6}, {6, 7, 1, 0}, {1, 7, 5, 3}, {6, 0, 2, 4}}, "cube");
}

Mesh MakeGrid(int n) {
  std::vector<Float3> p;
  std::vector<std::vector<int>> faces;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) p.push_back({static_cast<float>(i), static_cast<float>(j), 0});
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      faces.push_back({a, a + 1, a + n + 2, a + n + 1});
    }
  }
  return MakeMesh(std::move(p), faces, "grid");
}

Mesh MakePentagonFan() {
  std::vector<Float3> p;
  const double kPi = 3.14159265358979323846;
  // Inner pentagon (raised) at radius 1, outer ring at radius 2 with a wave in z.
  for (int k = 0; k < 5; ++k) {
    const double a = 2 * kPi * k / 5;
    p.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.3f});
  }
  for (int k = 0; k < 5; ++k) {
    const double a = 2 * kPi * k / 5;
    p.push_back({static_cast<float>(2 * std::cos(a)), static_cast<float>(2 * std::sin(a)),
                 (k % 2) ? 0.2f : -0.1f});
  }
  std::vector<std::vector<int>> faces = {{0, 1, 2, 3, 4}};
  for (int k = 0; k < 5; ++k) {
    const int k1 = (k + 1) % 5;
    faces.push_back({k, 5 + k, 5 + k1, k1});
  }
  return MakeMesh(std::move(p), faces, "pentagon_fan");
}

Mesh MakePentagonPrism() {
  std::vector<Float3> p;
  const double kPi = 3.14159265358979323846;
  for (int z = 0; z < 2; ++z) {
    for (int k = 0; k < 5; ++k) {
      const double a = 2 * kPi * k / 5;
      p.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)),
                   z == 0 ? -0.6f : 0.6f});
    }
  }
  std::vector<std::vector<int>> faces;
  faces.push_back({4, 3, 2, 1, 0});  // bottom, seen from below: counter-clockwise
  faces.push_back({5, 6, 7, 8, 9});  // top
  for (int k = 0; k < 5; ++k) {
    const int k1 = (k + 1) % 5;
    faces.push_back({k, k1, 5 + k1, 5 + k});
  }
  return MakeMesh(std::move(p), faces, "pentagon_prism");
}

double BoundsDiagonal(const Mesh& mesh) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const Float3& p : mesh.positions) {
    const double c[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

std::array<double, 3> Centroid(const Mesh& mesh) {
  std::array<double, 3> c{0, 0, 0};
  for (const Float3& p : mesh.positions) {
    c[0] += p.x;
    c[1] += p.y;
    c[2] += p.z;
  }
  for (double& x : c) x /= static_cast<double>(mesh.positions.size());
  return c;
}

void UnitCross(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
  const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
  if (len > 0) {
    for (int k = 0; k < 3; ++k) out[k] /= len;
  }
}

double AngleBetween(const double a[3], const double b[3]) {
  double cross[3];
  cross[0] = a[1] * b[2] - a[2] * b[1];
  cross[1] = a[2] * b[0] - a[0] * b[2];
  cross[2] = a[0] * b[1] - a[1] * b[0];
  const double s = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
  const double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  if (s == 0 && c == 0) return 0;
  return std::atan2(s, c);
}

double AngleBetween(const float a[3], const double b[3]) {
  const double ad[3] = {a[0], a[1], a[2]};
  return AngleBetween(ad, b);
}

namespace {

struct Point3 {
  double p[3];
  void Clear() { p[0] = p[1] = p[2] = 0; }
  void AddWithWeight(const Point3& src, double w) {
    p[0] += w * src.p[0];
    p[1] += w * src.p[1];
    p[2] += w * src.p[2];
  }
};

// The cage as an OpenSubdiv refiner (Catmull-Clark, its tags, boundary, crease and triangle
// rules), built here with the library's own descriptor so that the oracles do not share
// dispex's topology code.
std::unique_ptr<Far::TopologyRefiner> CreateRefiner(const Mesh& cage) {
  Sdc::Options sdc;
  if (cage.tags.crease_method == CreaseMethod::kChaikin) {
    sdc.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
  }
  if (cage.tags.triangles == TriangleSubdivision::kSmooth) {
    sdc.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
  }
  switch (cage.tags.boundary) {
    case BoundaryInterpolation::kNone:
      sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE);
      break;
    case BoundaryInterpolation::kEdgeOnly:
      sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
      break;
    case BoundaryInterpolation::kEdgeAndCorner:
      sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
      break;
  }
  std::vector<int> verts_per_face;
  for (std::size_t f = 0; f < cage.num_faces(); ++f) verts_per_face.push_back(cage.face_size(f));
  std::vector<int> crease_pairs, corner_verts, holes;
  std::vector<float> crease_weights, corner_weights;
  for (const auto& c : cage.tags.creases) {
    crease_pairs.push_back(c.v0.value);
    crease_pairs.push_back(c.v1.value);
    crease_weights.push_back(c.sharpness);
  }
  for (const auto& c : cage.tags.corners) {
    corner_verts.push_back(c.vertex.value);
    corner_weights.push_back(c.sharpness);
  }
  for (BaseFaceId h : cage.tags.holes) holes.push_back(h.value);

  Far::TopologyDescriptor desc;
  desc.numVertices = static_cast<int>(cage.num_vertices());
  desc.numFaces = static_cast<int>(cage.num_faces());
  desc.numVertsPerFace = verts_per_face.data();
  desc.vertIndicesPerFace = cage.face_indices.data();
  desc.numCreases = static_cast<int>(crease_weights.size());
  desc.creaseVertexIndexPairs = crease_pairs.data();
  desc.creaseWeights = crease_weights.data();
  desc.numCorners = static_cast<int>(corner_weights.size());
  desc.cornerVertexIndices = corner_verts.data();
  desc.cornerWeights = corner_weights.data();
  desc.numHoles = static_cast<int>(holes.size());
  desc.holeIndices = holes.data();

  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  return std::unique_ptr<Far::TopologyRefiner>(
      Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
}

}  // namespace

struct PatchOracle::State {
  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<Far::PatchTable> table;
  std::unique_ptr<Far::PatchMap> map;
  std::unique_ptr<Far::PtexIndices> ptex;
  std::vector<Point3> points;  // base, refined, then local points
  std::vector<bool> extraordinary;
};

PatchOracle::PatchOracle(const Mesh& cage, int isolation) : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.refiner = CreateRefiner(cage);
  if (!st.refiner) return;
  st.ptex = std::make_unique<Far::PtexIndices>(*st.refiner);
  const Far::TopologyLevel& base = st.refiner->GetLevel(0);
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    st.extraordinary.push_back(!base.IsVertexValenceRegular(v) || base.IsVertexNonManifold(v));
  }

  Far::PatchTableFactory::Options options(isolation);
  options.SetPatchPrecision<double>();
  options.useInfSharpPatch = true;
  options.generateLegacySharpCornerPatches = false;
  options.shareEndCapPatchPoints = false;
  options.endCapType = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
  Far::TopologyRefiner::AdaptiveOptions adaptive = options.GetRefineAdaptiveOptions();
  adaptive.isolationLevel = isolation;
  adaptive.secondaryLevel = isolation;
  st.refiner->RefineAdaptive(adaptive);
  st.table.reset(Far::PatchTableFactory::Create(*st.refiner, options));
  st.map = std::make_unique<Far::PatchMap>(*st.table);

  // (RefineAdaptive reallocates the levels: `base` is stale from here on.)
  const int num_base = st.refiner->GetLevel(0).GetNumVertices();
  const int num_refined = st.refiner->GetNumVerticesTotal() - num_base;
  const int num_local = st.table->GetNumLocalPoints();
  st.points.resize(num_base + num_refined + num_local);
  for (int v = 0; v < num_base; ++v) {
    st.points[v].p[0] = cage.positions[v].x;
    st.points[v].p[1] = cage.positions[v].y;
    st.points[v].p[2] = cage.positions[v].z;
  }
  Far::PrimvarRefinerReal<double> primvar(*st.refiner);
  Point3* src = st.points.data();
  Point3* dst = src + num_base;
  for (int level = 1; level < st.refiner->GetNumLevels(); ++level) {
    primvar.Interpolate(level, src, dst);
    src = dst;
    dst += st.refiner->GetLevel(level).GetNumVertices();
  }
  if (num_local > 0) {
    st.table->GetLocalPointStencilTable<double>()->UpdateValues(
        st.points.data(), st.points.data() + num_base + num_refined);
  }
  ok_ = true;
}

PatchOracle::~PatchOracle() = default;

FarLimit FarUniformLimit(const Mesh& cage, int levels) {
  FarLimit out;
  std::unique_ptr<Far::TopologyRefiner> refiner = CreateRefiner(cage);
  if (!refiner) return out;
  Far::TopologyRefiner::UniformOptions options(levels);
  options.fullTopologyInLastLevel = true;
  refiner->RefineUniform(options);

  std::vector<Point3> points(refiner->GetNumVerticesTotal());
  for (std::size_t v = 0; v < cage.num_vertices(); ++v) {
    points[v] = {{cage.positions[v].x, cage.positions[v].y, cage.positions[v].z}};
  }
  Far::PrimvarRefinerReal<double> primvar(*refiner);
  Point3* src = points.data();
  for (int l = 1; l <= levels; ++l) {
    Point3* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
    primvar.Interpolate(l, src, dst);
    src = dst;
  }
  const Far::TopologyLevel& leaf = refiner->GetLevel(levels);
  const int n = leaf.GetNumVertices();
  std::vector<Point3> limit(n), tan1(n), tan2(n);
  primvar.Limit(src, limit, tan1, tan2);
  out.num_vertices = n;
  out.num_faces = leaf.GetNumFaces();
  out.positions.resize(n);
  out.normals.resize(n);
  for (int v = 0; v < n; ++v) {
    out.positions[v] = {limit[v].p[0], limit[v].p[1], limit[v].p[2]};
    UnitCross(tan1[v].p, tan2[v].p, out.normals[v].data());
  }
  out.from_base_vertex.assign(n, 0);
  for (int v = 0; v < static_cast<int>(cage.num_vertices()); ++v) {
    int child = v;
    for (int l = 0; l < levels && child >= 0; ++l) {
      child = refiner->GetLevel(l).GetVertexChildVertex(child);
    }
    if (child >= 0) out.from_base_vertex[child] = 1;
    out.base_vertex_child.push_back(child);
  }
  for (int f = 0; f < out.num_faces; ++f) {
    const auto fv = leaf.GetFaceVertices(f);
    out.faces.emplace_back(fv.begin(), fv.end());
    int base = f;
    for (int l = levels; l > 0; --l) base = refiner->GetLevel(l).GetFaceParentFace(base);
    out.face_base.push_back(base);
  }
  return out;
}

int PatchOracle::num_ptex_faces() const {
  return state_->ptex->GetNumFaces();
}

bool PatchOracle::IsExtraordinary(int vertex) const {
  return state_->extraordinary[vertex];
}

bool PatchOracle::Evaluate(int ptex, double u, double v, double p[3], double du[3],
                           double dv[3]) const {
  const State& st = *state_;
  const Far::PatchTable::PatchHandle* handle = st.map->FindPatch(ptex, u, v);
  if (handle == nullptr) return false;
  double w[20], wu[20], wv[20];
  st.table->EvaluateBasis(*handle, u, v, w, wu, wv);
  const Far::ConstIndexArray cvs = st.table->GetPatchVertices(*handle);
  for (int k = 0; k < 3; ++k) p[k] = du[k] = dv[k] = 0;
  for (int i = 0; i < cvs.size(); ++i) {
    const double* c = st.points[cvs[i]].p;
    for (int k = 0; k < 3; ++k) {
      p[k] += w[i] * c[k];
      du[k] += wu[i] * c[k];
      dv[k] += wv[i] * c[k];
    }
  }
  return true;
}

}  // namespace dispex::subdiv_test

namespace dispex::subdiv_test {

OracleComparison CompareWithOracle(const Mesh& cage, const SubdivOptions& options, int n,
                                   int oracle_isolation) {
  OracleComparison result;
  StatusOr<LimitSurface> surface = LimitSurface::Build(cage, options);
  if (!surface.ok()) {
    result.error = surface.status().message();
    return result;
  }
  const int isolation =
      oracle_isolation > 0 ? oracle_isolation : surface->options().approx_level_sharp;
  PatchOracle oracle(cage, isolation);
  if (!oracle.ok()) {
    result.error = "oracle failed to build";
    return result;
  }
  if (oracle.num_ptex_faces() != surface->num_ptex_faces()) {
    result.error = "Ptex face counts differ";
    return result;
  }
  result.built = true;
  const double diag = BoundsDiagonal(cage);
  const auto centroid = Centroid(cage);
  LimitEvaluator eval(*surface);

  // Sample set: texel centres, then points near each corner.
  std::vector<float> uv;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      uv.push_back((i + 0.5f) / n);
      uv.push_back((j + 0.5f) / n);
    }
  }
  const int grid_count = n * n;
  const float near[3] = {1.0f / 4096, 1.0f / 512, 1.0f / 64};
  for (int c = 0; c < 4; ++c) {
    for (float a : near) {
      for (float b : near) {
        const float u = (c & 1) ? 1.0f - a : a;
        const float v = (c & 2) ? 1.0f - b : b;
        uv.push_back(u);
        uv.push_back(v);
      }
    }
  }
  const std::size_t count = uv.size() / 2;
  std::vector<float> grid_p(3 * grid_count), grid_n(3 * grid_count);
  std::vector<float> pts_p(3 * count), pts_n(3 * count);
  double outward_sum = 0;
  std::int64_t outward_count = 0;

  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    const PtexFaceId face(f);
    double p0[3], d0[3], d1[3];
    const bool oracle_has = oracle.Evaluate(f, 0.5, 0.5, p0, d0, d1);
    if (surface->is_hole(face) == oracle_has) ++result.hole_mismatches;
    if (surface->is_hole(face) || !oracle_has) continue;
    if (!eval.EvaluateGrid(face, n, n, grid_p, grid_n).ok() ||
        !eval.EvaluatePoints(face, uv, pts_p, pts_n).ok()) {
      result.error = "evaluation failed on Ptex face " + std::to_string(f);
      result.built = false;
      return result;
    }
    // Which corners of this Ptex face are extraordinary points of the surface.
    bool xord_corner[4] = {false, false, false, false};
    const int base = surface->base_face(face).value;
    const auto fv = cage.face(base);
    const int size = cage.face_size(base);
    if (size == 4) {
      static constexpr int kCornerOfVertex[4] = {0, 1, 3, 2};  // vertex k -> corner bits
      for (int k = 0; k < 4; ++k) xord_corner[kCornerOfVertex[k]] = oracle.IsExtraordinary(fv[k]);
    } else {
      const int k = surface->sub_face(face);
      xord_corner[0] = oracle.IsExtraordinary(fv[k]);
      xord_corner[3] = true;  // the n-gon's centre
    }
    for (std::size_t s = 0; s < count; ++s) {
      const double u = uv[2 * s], v = uv[2 * s + 1];
      double p[3], du[3], dv[3];
      if (!oracle.Evaluate(f, u, v, p, du, dv)) {
        ++result.hole_mismatches;
        continue;
      }
      const float* mine_p =
          (s < static_cast<std::size_t>(grid_count)) ? &grid_p[3 * s] : &pts_p[3 * s];
      const float* mine_n =
          (s < static_cast<std::size_t>(grid_count)) ? &grid_n[3 * s] : &pts_n[3 * s];
      // Grid and point evaluation must agree at the texel centres too.
      if (s < static_cast<std::size_t>(grid_count)) {
        for (int k = 0; k < 3; ++k) {
          result.max_position_error = std::max(
              result.max_position_error, std::abs(pts_p[3 * s + k] - grid_p[3 * s + k]) / diag);
        }
      }
      double err = 0;
      for (int k = 0; k < 3; ++k) err += (mine_p[k] - p[k]) * (mine_p[k] - p[k]);
      result.max_position_error = std::max(result.max_position_error, std::sqrt(err) / diag);
      double ref_n[3];
      UnitCross(du, dv, ref_n);
      const double angle = AngleBetween(mine_n, ref_n);
      result.max_normal_angle = std::max(result.max_normal_angle, angle);
      bool near_xord = false;
      for (int c = 0; c < 4; ++c) {
        const double cu = (c & 1) ? 1.0 : 0.0, cv = (c & 2) ? 1.0 : 0.0;
        if (xord_corner[c] && std::abs(u - cu) < 1.0 / 16 && std::abs(v - cv) < 1.0 / 16) {
          near_xord = true;
        }
      }
      if (!near_xord) {
        result.max_normal_angle_regular = std::max(result.max_normal_angle_regular, angle);
      }
      outward_sum +=
          (mine_n[0] * (mine_p[0] - centroid[0]) + mine_n[1] * (mine_p[1] - centroid[1]) +
           mine_n[2] * (mine_p[2] - centroid[2])) /
          diag;
      ++outward_count;
      ++result.samples;
    }
  }
  result.mean_outward = outward_count > 0 ? outward_sum / outward_count : 0;
  return result;
}

}  // namespace dispex::subdiv_test
