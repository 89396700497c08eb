// Vector maps on the sub-faces of non-quad faces, proven against an evaluation that shares no
// code with dispex's limit surface: OpenSubdiv's Far::PatchTable (adaptive refinement, Gregory
// end caps, double precision) found by Far::PtexIndices ids through Far::PatchMap. Isolation
// level 10, the level of dispex's Bfr surfaces by default (SubdivOptions::approx_level_smooth):
// at level 6 the texels nearest a sub-face's extraordinary corners (its cage vertex and the
// n-gon's centre, 1/64 from them) lie in Far's end-cap patches and differ from the level-10
// surface by up to 5e-4 (parametric, pyramid); quads and the other texels agree either way.
//
// On an n-gon (n != 4) Ptex has n quad sub-faces, each the unit square in its own (u, v);
// OpenSubdiv's Bfr (and Far's patch basis) give the sub-face edges parametric length 0.5
// (bfr_overview.rst), so their dP/du and dP/dv are twice the Ptex ones there. A parametric
// map written or read with the wrong one is off by the tangential part of D (or half of it).
//
// For a pentagonal prism and a cage of triangles (catmark_pyramid), with --vector parametric
// and tangent:
//  - the oracle's derivatives are in Ptex units: raw Far derivatives over central differences
//    of its own positions in Ptex (u, v) are 2 on sub-faces and 1 on quads, and halved they
//    match the differences (so the oracle itself does not assume the factor);
//  - every texel of a full-resolution map, turned into D by the frame docs/VECTOR.md states
//    (built from the oracle's P, dP/du, dP/dv, N), is the displacements of the sculpt's
//    vertices from their limit points, corrected for the blend of the samples around each
//    vertex (D - (m / 4n) L D, L D from the sculpt's own edges: the sum of a vertex's four
//    neighbours - 4 D, none at a grid corner or on an open border) and interpolated bilinearly
//    at the texel centre (the default method, interpolate), to float rounding; the sculpt's
//    vertices are found by their limit points (oracle) and checked against the truth's D;
//  - the same check rejects each wrong frame on the sub-faces: derivatives x2 (OpenSubdiv's
//    own) or x0.5, u and v swapped, tangent channels scaled; a tangent frame does not depend
//    on the derivatives' length (the x2 and x0.5 frames give the same D);
//  - the maps of the default extraction pass `verify` against the sculpt and the truth, and
//    the same maps with the sub-faces' tangential channels halved or doubled fail it.
#include <gtest/gtest.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/ptex.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;
using testing::DataPath;
using testing::RunDispex;
using testing::TempDir;

using V3 = std::array<double, 3>;
V3 operator+(const V3& a, const V3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
V3 operator-(const V3& a, const V3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
V3 operator*(const V3& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
double Dot(const V3& a, const V3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
V3 Cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Length(const V3& a) {
  return std::sqrt(Dot(a, a));
}
V3 Normalize(const V3& a) {
  return a * (1 / Length(a));
}

// A pentagonal prism, a little irregular so that no two derivatives are alike: its two
// pentagons are 10 Ptex sub-faces, its five sides quads. Every vertex has valence 3.
constexpr const char* kPrism =
    "v 1.0000 0.0000 -0.6000\n"
    "v 0.2961 0.9773 -0.5500\n"
    "v -0.8176 0.4994 -0.5000\n"
    "v -0.7334 -0.7678 -0.4500\n"
    "v 0.5448 -0.7407 -0.4000\n"
    "v 0.9311 0.1887 0.7000\n"
    "v 0.0760 0.8048 0.6600\n"
    "v -0.7375 0.2678 0.6200\n"
    "v -0.5045 -0.8003 0.5800\n"
    "v 0.6188 -0.5613 0.5400\n"
    "f 5 4 3 2 1\n"
    "f 6 7 8 9 10\n"
    "f 1 2 7 6\n"
    "f 2 3 8 7\n"
    "f 3 4 9 8\n"
    "f 4 5 10 9\n"
    "f 5 1 6 10\n";

// The cage as the OBJ has it: `v` and `f` lines only (f a/b/c: the vertex index).
struct Cage {
  std::vector<double> xyz;
  std::vector<int> sizes, indices;
};

Cage ParseObj(const std::string& path) {
  Cage cage;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string tag;
    ss >> tag;
    if (tag == "v") {
      double x, y, z;
      ss >> x >> y >> z;
      cage.xyz.insert(cage.xyz.end(), {x, y, z});
    } else if (tag == "f") {
      std::string corner;
      int n = 0;
      while (ss >> corner) {
        cage.indices.push_back(std::stoi(corner.substr(0, corner.find('/'))) - 1);
        ++n;
      }
      cage.sizes.push_back(n);
    }
  }
  return cage;
}

// Far's limit surface, found by Ptex face and (u, v) as far_tutorial_5_x does.
class FarLimit {
 public:
  explicit FarLimit(const Cage& cage) {
    Far::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(cage.xyz.size() / 3);
    desc.numFaces = static_cast<int>(cage.sizes.size());
    desc.numVertsPerFace = cage.sizes.data();
    desc.vertIndicesPerFace = cage.indices.data();
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    refiner_.reset(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
    Far::PtexIndices ptex(*refiner_);
    for (int f = 0; f < desc.numFaces; ++f) {
      const int n = cage.sizes[static_cast<std::size_t>(f)];
      EXPECT_EQ(ptex.GetFaceId(f), static_cast<int>(sub_face_.size()));
      sub_face_.resize(sub_face_.size() + (n == 4 ? 1 : static_cast<std::size_t>(n)), n != 4);
    }
    EXPECT_EQ(ptex.GetNumFaces(), static_cast<int>(sub_face_.size()));

    Far::PatchTableFactory::Options options(10);
    options.SetPatchPrecision<double>();
    options.useInfSharpPatch = true;
    options.generateLegacySharpCornerPatches = false;
    options.endCapType = Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS;
    refiner_->RefineAdaptive(options.GetRefineAdaptiveOptions());
    table_.reset(Far::PatchTableFactory::Create(*refiner_, options));
    map_ = std::make_unique<Far::PatchMap>(*table_);

    const int refined = refiner_->GetNumVerticesTotal();
    points_.resize(static_cast<std::size_t>(refined + table_->GetNumLocalPoints()));
    for (std::size_t v = 0; v < cage.xyz.size() / 3; ++v) {
      points_[v].p = {cage.xyz[3 * v], cage.xyz[3 * v + 1], cage.xyz[3 * v + 2]};
    }
    Far::PrimvarRefinerReal<double> primvar(*refiner_);
    Point* src = points_.data();
    for (int level = 1; level < refiner_->GetNumLevels(); ++level) {
      Point* dst = src + refiner_->GetLevel(level - 1).GetNumVertices();
      primvar.Interpolate(level, src, dst);
      src = dst;
    }
    if (table_->GetNumLocalPoints() > 0) {
      table_->GetLocalPointStencilTable<double>()->UpdateValues(points_.data(),
                                                                points_.data() + refined);
    }
  }

  int num_ptex_faces() const { return static_cast<int>(sub_face_.size()); }
  bool sub_face(int ptex) const { return sub_face_[static_cast<std::size_t>(ptex)]; }

  // P and Far's own derivatives (those of the patch basis: per unit of the parametrisation
  // Far and Bfr share, where a sub-face spans 0.5).
  V3 Evaluate(int ptex, double u, double v, V3* du = nullptr, V3* dv = nullptr) const {
    const Far::PatchTable::PatchHandle* handle = map_->FindPatch(ptex, u, v);
    EXPECT_NE(handle, nullptr) << ptex << " " << u << " " << v;
    double w[20], wu[20], wv[20];
    table_->EvaluateBasis(*handle, u, v, w, wu, wv);
    const Far::ConstIndexArray cvs = table_->GetPatchVertices(*handle);
    V3 p{0, 0, 0}, pu{0, 0, 0}, pv{0, 0, 0};
    for (int i = 0; i < cvs.size(); ++i) {
      const V3& c = points_[static_cast<std::size_t>(cvs[i])].p;
      p = p + c * w[i];
      pu = pu + c * wu[i];
      pv = pv + c * wv[i];
    }
    if (du != nullptr) *du = pu;
    if (dv != nullptr) *dv = pv;
    return p;
  }

  // The frame in the Ptex face's own (u, v): Far's derivatives halved on sub-faces (checked
  // against central differences by the first test), N = normalize(dP/du x dP/dv).
  struct Frame {
    V3 p, du, dv, n;
  };
  Frame At(int ptex, double u, double v) const {
    Frame f;
    f.p = Evaluate(ptex, u, v, &f.du, &f.dv);
    const double scale = sub_face(ptex) ? 0.5 : 1.0;
    f.du = f.du * scale;
    f.dv = f.dv * scale;
    f.n = Normalize(Cross(f.du, f.dv));
    return f;
  }

 private:
  struct Point {
    V3 p{0, 0, 0};
    void Clear() { p = {0, 0, 0}; }
    void AddWithWeight(const Point& s, double w) { p = p + s.p * w; }
  };
  std::unique_ptr<Far::TopologyRefiner> refiner_;
  std::unique_ptr<Far::PatchTable> table_;
  std::unique_ptr<Far::PatchMap> map_;
  std::vector<Point> points_;
  std::vector<bool> sub_face_;
};

// ---- The frames the docs state, and wrong ones -------------------------------------------------

enum class FrameError {
  kNone,
  kDerivativesTimes2,
  kDerivativesHalved,
  kSwapped,
  kChannelsTimes2,
  kChannelsHalved
};
const char* FrameErrorName(FrameError e) {
  switch (e) {
    case FrameError::kNone:
      return "as documented";
    case FrameError::kDerivativesTimes2:
      return "dP/du, dP/dv x2 on sub-faces (OpenSubdiv's own)";
    case FrameError::kDerivativesHalved:
      return "dP/du, dP/dv x0.5 on sub-faces";
    case FrameError::kSwapped:
      return "u and v swapped on sub-faces";
    case FrameError::kChannelsTimes2:
      return "channels 0, 1 x2 on sub-faces";
    case FrameError::kChannelsHalved:
      return "channels 0, 1 x0.5 on sub-faces";
  }
  return "?";
}
constexpr FrameError kWrongFrames[] = {FrameError::kDerivativesTimes2,
                                       FrameError::kDerivativesHalved, FrameError::kSwapped,
                                       FrameError::kChannelsTimes2, FrameError::kChannelsHalved};

// D from the channels c by docs/VECTOR.md ("Frame conventions"), with the frame's error applied
// where `sub_face`:
//   parametric  D = c0 dP/du + c1 dP/dv + c2 N
//   tangent     D = c0 T + c1 B + c2 N, T = normalize(dP/du), B = N x T
V3 DocumentedD(VectorSpace space, FarLimit::Frame f, const float c_in[3], bool sub_face,
               FrameError error) {
  double c[3] = {c_in[0], c_in[1], c_in[2]};
  if (sub_face) {
    switch (error) {
      case FrameError::kNone:
        break;
      case FrameError::kDerivativesTimes2:
        f.du = f.du * 2;
        f.dv = f.dv * 2;
        break;
      case FrameError::kDerivativesHalved:
        f.du = f.du * 0.5;
        f.dv = f.dv * 0.5;
        break;
      case FrameError::kSwapped:
        std::swap(f.du, f.dv);
        break;
      case FrameError::kChannelsTimes2:
        c[0] *= 2;
        c[1] *= 2;
        break;
      case FrameError::kChannelsHalved:
        c[0] *= 0.5;
        c[1] *= 0.5;
        break;
    }
  }
  if (space == VectorSpace::kParametric) return f.du * c[0] + f.dv * c[1] + f.n * c[2];
  const V3 t = Normalize(f.du);
  return t * c[0] + Cross(f.n, t) * c[1] + f.n * c[2];
}

// ---- The cases ---------------------------------------------------------------------------------

struct Case {
  const char* name;
  const char* data;  // a cage under tests/data, or nullptr: kPrism
  int levels;
  double amplitude;  // of the sideways pattern, object units
};

const Case kCases[] = {{"pentagon", nullptr, 4, 0.05},
                       {"triangle", "meshes/opensubdiv/catmark_pyramid.obj", 4, 0.1}};

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.name;
}

constexpr VectorSpace kSpaces[] = {VectorSpace::kParametric, VectorSpace::kTangent};

class NonQuadVector : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    const Case& c = GetParam();
    if (c.data != nullptr) {
      cage_ = DataPath(c.data);
    } else {
      cage_ = dir_ / "prism.obj";
      std::ofstream(cage_) << kPrism;
    }
    sculpt_ = dir_ / "sculpt.obj";
    // Sideways: D is all tangential, where the frames differ.
    auto made = MakeSculpt(
        testing::SculptOptions(cage_, sculpt_, c.levels, Pattern::kSideways, c.amplitude));
    ASSERT_TRUE(made.ok()) << made.status().message();
    made_ = *made;
    far_ = std::make_unique<FarLimit>(ParseObj(cage_));
  }

  std::string Extract(VectorSpace space, const std::string& extra, const std::string& name) {
    const std::string map = dir_ / name;
    auto run = RunDispex("extract " + cage_ + " " + sculpt_ + " --vector " +
                             std::string(VectorSpaceName(space)) + " --threads 1 -q " + extra +
                             " -o " + map,
                         dir_);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return map;
  }

  TempDir dir_;
  std::string cage_, sculpt_;
  MakeSculptReport made_;
  std::unique_ptr<FarLimit> far_;
};

// The oracle's derivatives: Far's, over central differences of Far's own positions in the Ptex
// face's (u, v), are 2 on sub-faces and 1 on quads (OpenSubdiv's 0.5-long sub-face edges), so
// halved on sub-faces they are derivatives in Ptex's (u, v). Measured on a 16 x 16 grid of
// every face; the differences (step 1e-5) are exact to about 1e-9 of |dP/du|.
TEST_P(NonQuadVector, OracleDerivativesArePtexDerivatives) {
  const double h = 1e-5;
  double ratio_min[2] = {1e9, 1e9}, ratio_max[2] = {0, 0}, worst = 0;
  for (int f = 0; f < far_->num_ptex_faces(); ++f) {
    const int sub = far_->sub_face(f) ? 1 : 0;
    for (int j = 0; j < 16; ++j) {
      for (int i = 0; i < 16; ++i) {
        const double u = (i + 0.5) / 16, v = (j + 0.5) / 16;
        V3 du_far, dv_far;
        far_->Evaluate(f, u, v, &du_far, &dv_far);
        const V3 fd_u = (far_->Evaluate(f, u + h, v) - far_->Evaluate(f, u - h, v)) * (0.5 / h);
        const V3 fd_v = (far_->Evaluate(f, u, v + h) - far_->Evaluate(f, u, v - h)) * (0.5 / h);
        for (const auto& [raw, fd] : {std::pair{du_far, fd_u}, std::pair{dv_far, fd_v}}) {
          const double ratio = Length(raw) / Length(fd);
          ratio_min[sub] = std::min(ratio_min[sub], ratio);
          ratio_max[sub] = std::max(ratio_max[sub], ratio);
        }
        const FarLimit::Frame frame = far_->At(f, u, v);
        worst = std::max(worst, Length(frame.du - fd_u) / Length(fd_u));
        worst = std::max(worst, Length(frame.dv - fd_v) / Length(fd_v));
      }
    }
  }
  std::printf(
      "%s: |Far dP/du| / |central difference|: quads %.9f..%.9f, sub-faces %.9f..%.9f; "
      "oracle vs differences %.2e\n",
      GetParam().name, ratio_min[0], ratio_max[0], ratio_min[1], ratio_max[1], worst);
  EXPECT_NEAR(ratio_min[0], 1, 1e-6);
  EXPECT_NEAR(ratio_max[0], 1, 1e-6);
  EXPECT_NEAR(ratio_min[1], 2, 2e-6);
  EXPECT_NEAR(ratio_max[1], 2, 2e-6);
  EXPECT_LT(worst, 1e-6);
}

// Sculpt vertex positions on the grid of each Ptex face (n x n cells: 2^L on a quad, 2^(L-1)
// on a sub-face), found by their limit points: every truth record's (face, u, v) evaluated by
// Far, and each grid corner matched to the record with the nearest limit point.
struct SculptGrid {
  std::vector<int> cells;                // per Ptex face
  std::vector<std::vector<V3>> corners;  // per Ptex face, (n + 1)^2, row by row
  std::vector<std::vector<V3>> bends;    // the same places: L D of the vertex there
  double match_max = 0;                  // the farthest match (limit points), object units
  double truth_max = 0;                  // max |sculpt vertex - (limit point + truth D)|
};

SculptGrid BuildSculptGrid(const FarLimit& far, const std::string& sculpt_path, int levels) {
  SculptGrid grid;
  const Cage sculpt = ParseObj(sculpt_path);
  auto truth = ReadGroundTruth(sculpt_path + ".truth");
  EXPECT_TRUE(truth.ok());
  EXPECT_EQ(truth->size(), sculpt.xyz.size() / 3);
  std::vector<V3> limit(truth->size()), position(truth->size());
  for (std::size_t i = 0; i < truth->size(); ++i) {
    limit[i] = far.Evaluate(truth->faces[i].value, truth->uvs[2 * i], truth->uvs[2 * i + 1]);
    position[i] = {sculpt.xyz[3 * i], sculpt.xyz[3 * i + 1], sculpt.xyz[3 * i + 2]};
    const V3 d{truth->d[3 * i], truth->d[3 * i + 1], truth->d[3 * i + 2]};
    grid.truth_max = std::max(grid.truth_max, Length(position[i] - (limit[i] + d)));
  }
  std::vector<std::vector<std::size_t>> ids;  // per Ptex face, the vertex at each grid place
  std::vector<std::uint8_t> grid_corner(limit.size(), 0);
  for (int f = 0; f < far.num_ptex_faces(); ++f) {
    const int n = far.sub_face(f) ? 1 << (levels - 1) : 1 << levels;
    grid.cells.push_back(n);
    std::vector<V3>& corners = grid.corners.emplace_back();
    std::vector<std::size_t>& face_ids = ids.emplace_back();
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const V3 p = far.Evaluate(f, double(i) / n, double(j) / n);
        std::size_t best = 0;
        double best_d = 1e300;
        for (std::size_t k = 0; k < limit.size(); ++k) {
          const double d = Length(limit[k] - p);
          if (d < best_d) best_d = d, best = k;
        }
        grid.match_max = std::max(grid.match_max, best_d);
        corners.push_back(position[best]);
        face_ids.push_back(best);
        if ((i == 0 || i == n) && (j == 0 || j == n)) grid_corner[best] = 1;
      }
    }
  }
  // L D from the sculpt's edges: a vertex's four neighbours' D - 4 D, D = vertex - limit point.
  std::vector<std::set<int>> neighbours(limit.size());
  for (std::size_t q = 0, first = 0; q < sculpt.sizes.size(); first += sculpt.sizes[q++]) {
    const std::size_t size = static_cast<std::size_t>(sculpt.sizes[q]);
    for (std::size_t c = 0; c < size; ++c) {
      const int a = sculpt.indices[first + c], b = sculpt.indices[first + (c + 1) % size];
      neighbours[static_cast<std::size_t>(a)].insert(b);
      neighbours[static_cast<std::size_t>(b)].insert(a);
    }
  }
  std::vector<V3> bend(limit.size(), V3{0, 0, 0});
  for (std::size_t v = 0; v < limit.size(); ++v) {
    if (grid_corner[v] || neighbours[v].size() != 4) continue;
    bend[v] = (position[v] - limit[v]) * -4.0;
    for (const int w : neighbours[v]) {
      bend[v] =
          bend[v] + (position[static_cast<std::size_t>(w)] - limit[static_cast<std::size_t>(w)]);
    }
  }
  for (const std::vector<std::size_t>& face_ids : ids) {
    std::vector<V3>& bends = grid.bends.emplace_back();
    for (const std::size_t id : face_ids) bends.push_back(bend[id]);
  }
  return grid;
}

// D at (u, v) of face f sampled `samples` a side, as docs/VECTOR.md defines it: the
// displacements of the corners of the cell of the face's grid that holds (u, v) from their
// limit points, corrected for the blend, bilinear over the cell.
V3 SculptD(const FarLimit& far, const SculptGrid& grid, int f, double u, double v, int samples) {
  const int n = grid.cells[static_cast<std::size_t>(f)];
  const double sharpen = double(n) / (4.0 * samples);
  const int i = std::min(static_cast<int>(u * n), n - 1),
            j = std::min(static_cast<int>(v * n), n - 1);
  const double s = u * n - i, t = v * n - j;
  const std::vector<V3>& c = grid.corners[static_cast<std::size_t>(f)];
  const std::vector<V3>& bends = grid.bends[static_cast<std::size_t>(f)];
  auto at = [&](int di, int dj) {
    const auto k = static_cast<std::size_t>((j + dj) * (n + 1) + i + di);
    return c[k] - bends[k] * sharpen -
           far.Evaluate(f, static_cast<double>(i + di) / n, static_cast<double>(j + dj) / n);
  };
  return at(0, 0) * ((1 - s) * (1 - t)) + at(1, 0) * (s * (1 - t)) + at(1, 1) * (s * t) +
         at(0, 1) * ((1 - s) * t);
}

struct MapCheck {
  double max_error[2] = {0, 0};       // quads, sub-faces: max |D_map - D|
  double max_tangential[2] = {0, 0};  // of D
  std::size_t texels[2] = {0, 0};
};

MapCheck CheckMap(const FarLimit& far, const SculptGrid& grid, const PtexFile& map,
                  VectorSpace space, FrameError error) {
  MapCheck out;
  std::vector<float> texels;
  for (int f = 0; f < far.num_ptex_faces(); ++f) {
    const int sub = far.sub_face(f) ? 1 : 0;
    const PtexFaceInfo& info = map.face_info(PtexFaceId(f));
    EXPECT_EQ(info.subface, sub == 1) << "face " << f;
    EXPECT_TRUE(map.ReadFace(PtexFaceId(f), 0, texels).ok());
    for (int j = 0; j < info.vres(); ++j) {
      for (int i = 0; i < info.ures(); ++i) {
        const double u = (i + 0.5) / info.ures(), v = (j + 0.5) / info.vres();
        const FarLimit::Frame frame = far.At(f, u, v);
        const V3 want = SculptD(far, grid, f, u, v, info.ures());
        const float* c = &texels[3 * (static_cast<std::size_t>(j) * info.ures() + i)];
        const V3 got = DocumentedD(space, frame, c, sub == 1, error);
        out.max_error[sub] = std::max(out.max_error[sub], Length(got - want));
        out.max_tangential[sub] =
            std::max(out.max_tangential[sub], Length(want - frame.n * Dot(want, frame.n)));
        ++out.texels[sub];
      }
    }
  }
  return out;
}

// Every texel of a full-resolution map (2^(L+1) texels a side, one sample each) is the sculpt
// at its centre minus the limit point, through the documented frame, on quads and sub-faces,
// to float rounding; each wrong frame on the sub-faces misses by a good part of D's tangential
// part, and leaves the quads as they were.
TEST_P(NonQuadVector, FullResolutionMapsMatchTheOracleInTheDocumentedFrame) {
  const Case& c = GetParam();
  const SculptGrid grid = BuildSculptGrid(*far_, sculpt_, c.levels);
  const double diagonal = made_.diagonal;
  EXPECT_LT(grid.match_max, 1e-9 * diagonal);
  EXPECT_LT(grid.truth_max, 1e-6 * diagonal);
  const int res = 2 << c.levels;
  const std::string fixed = "--resolution-rule fixed --fixed-resolution " + std::to_string(res) +
                            "x" + std::to_string(res) + " --oversample " + std::to_string(res);
  for (VectorSpace space : kSpaces) {
    SCOPED_TRACE(VectorSpaceName(space));
    const std::string path = Extract(space, fixed, "full.ptx");
    auto map = PtexFile::Open(path);
    ASSERT_TRUE(map.ok()) << map.status().message();
    ASSERT_EQ(map->num_faces(), far_->num_ptex_faces());
    ASSERT_NE(map->FindMetaData(std::string(kVectorSpaceMetaKey)), nullptr);
    EXPECT_EQ(map->FindMetaData(std::string(kVectorSpaceMetaKey))->AsString(),
              VectorSpaceName(space));
    const MapCheck good = CheckMap(*far_, grid, *map, space, FrameError::kNone);
    std::printf(
        "%s %s: %zu quad and %zu sub-face texels, max |D - tangential| %.4g / %.4g; "
        "documented frame max error quads %.3g, sub-faces %.3g\n",
        c.name, std::string(VectorSpaceName(space)).c_str(), good.texels[0], good.texels[1],
        good.max_tangential[0], good.max_tangential[1], good.max_error[0], good.max_error[1]);
    EXPECT_GT(good.texels[1], 0u);
    EXPECT_GT(good.max_tangential[1], 0.5 * c.amplitude) << "D has a tangential part";
    const double exact = 1e-6 * diagonal;
    EXPECT_LT(good.max_error[0], exact);
    EXPECT_LT(good.max_error[1], exact);
    for (FrameError error : kWrongFrames) {
      SCOPED_TRACE(FrameErrorName(error));
      const MapCheck wrong = CheckMap(*far_, grid, *map, space, error);
      std::printf("  %-50s quads %.3g, sub-faces %.3g (%.2f of the largest tangential |D|)\n",
                  FrameErrorName(error), wrong.max_error[0], wrong.max_error[1],
                  wrong.max_error[1] / good.max_tangential[1]);
      EXPECT_EQ(wrong.max_error[0], good.max_error[0]) << "quads are left alone";
      const bool scale_free =
          space == VectorSpace::kTangent &&
          (error == FrameError::kDerivativesTimes2 || error == FrameError::kDerivativesHalved);
      if (scale_free) {
        // T = normalize(dP/du): the derivatives' length does not enter a tangent map.
        EXPECT_LT(wrong.max_error[1], exact);
      } else {
        EXPECT_GT(wrong.max_error[1], 0.3 * good.max_tangential[1]);
        EXPECT_GT(wrong.max_error[1], 1000 * exact);
      }
    }
  }
}

// Rewrites `in` with the texels of every sub-face changed by `edit` (its 3 channels), keeping
// the faces' layout, the meta data that names the space, and the edge filter.
void RewriteSubFaces(const std::string& in, const std::string& out,
                     const std::function<void(float*)>& edit) {
  auto map = PtexFile::Open(in);
  ASSERT_TRUE(map.ok()) << map.status().message();
  PtexWriterOptions options;
  options.num_channels = 3;
  options.data_type = map->header().data_type;
  options.edge_filter = map->header().edge_filter;
  auto writer = PtexWriter::Create(out, options, map->num_faces());
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (const char* key : {"dispex:vector_space", "dispex:channels"}) {
    const PtexMetaItem* item = map->FindMetaData(key);
    ASSERT_NE(item, nullptr) << key;
    ASSERT_TRUE(writer->AddMetaData(key, item->AsString()).ok());
  }
  std::vector<float> texels;
  for (int f = 0; f < map->num_faces(); ++f) {
    PtexFaceInfo info = map->face_info(PtexFaceId(f));
    ASSERT_TRUE(map->ReadFace(PtexFaceId(f), 0, texels).ok());
    if (info.subface) {
      for (std::size_t t = 0; t < texels.size(); t += 3) edit(&texels[t]);
    }
    info.constant = false;
    ASSERT_TRUE(writer->SetFace(PtexFaceId(f), info, texels).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
}

// The default extraction (the error bound, automatic tolerance) round-trips through verify:
// against the sculpt both ways and the truth's D with tau = a tenth of the largest |D|, the
// truth RMS and p99 within verify's bounds, the records over the per-record bound (if any) only
// where Catmull-Clark's frame is singular: at a corner of a Ptex face (every cage vertex here
// has valence 3, and n-gon centres are extraordinary). The same maps with the sub-faces'
// channels 0 and 1 halved or doubled fail verify: in a parametric map that is what writing
// with OpenSubdiv's sub-face derivatives, or reading with them, does (a tangent map's channels
// do not depend on the derivatives' length; there it shows verify sees the sub-faces' scale).
TEST_P(NonQuadVector, DefaultMapsRoundTripThroughVerify) {
  const double tau = 0.1 * made_.max_displacement;
  auto check = [&](const std::string& map) {
    VerifyOptions verify;
    verify.base_path = cage_;
    verify.sculpt_path = sculpt_;
    verify.map_path = map;
    verify.truth_path = sculpt_ + ".truth";
    verify.tolerance = tau;
    auto report = Verify(verify);
    EXPECT_TRUE(report.ok()) << report.status().message();
    return report.ok() ? *report : VerifyReport{};
  };
  for (VectorSpace space : kSpaces) {
    SCOPED_TRACE(VectorSpaceName(space));
    const std::string map = Extract(space, "", "default.ptx");
    const VerifyReport good = check(map);
    std::printf(
        "%s %s: verify truth rms %.3g p99 %.3g max %.3g (tau %.3g), %zu of %zu over, "
        "worst %.2fx at face %d (%g, %g); sculpt->map %.3g map->sculpt %.3g; %s\n",
        GetParam().name, std::string(VectorSpaceName(space)).c_str(), good.truth.rms,
        good.truth.p99, good.truth.max, tau, good.truth_over_bound, good.truth.count,
        good.truth_worst_ratio, good.truth_worst.face, good.truth_worst.u, good.truth_worst.v,
        good.sculpt_to_map.max, good.map_to_sculpt.max,
        good.passed ? "passed" : good.failure.c_str());
    EXPECT_TRUE(good.map_vector);
    EXPECT_EQ(good.map_space, space);
    EXPECT_EQ(good.truth_quantity, "|D_map - D|");
    EXPECT_LE(good.truth.rms, 0.5 * tau);
    EXPECT_LE(good.truth.p99, 1.5 * tau);
    if (good.truth_over_bound > 0) {
      const bool corner = (good.truth_worst.u == 0 || good.truth_worst.u == 1) &&
                          (good.truth_worst.v == 0 || good.truth_worst.v == 1);
      EXPECT_TRUE(corner) << good.failure;
      EXPECT_LE(good.truth_over_bound, good.truth.count / 100);
    }
    for (float factor : {0.5f, 2.0f}) {
      SCOPED_TRACE(factor);
      const std::string wrong = dir_ / "wrong.ptx";
      RewriteSubFaces(map, wrong, [&](float* c) {
        c[0] *= factor;
        c[1] *= factor;
      });
      const VerifyReport r = check(wrong);
      std::printf("  sub-face channels 0, 1 x%.1f: truth rms %.3g max %.3g, %zu over; %s\n", factor,
                  r.truth.rms, r.truth.max, r.truth_over_bound,
                  r.passed ? "passed" : r.failure.c_str());
      EXPECT_FALSE(r.passed);
      EXPECT_GT(r.truth.rms, 0.5 * tau);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cages, NonQuadVector, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           return std::string(param.param.name);
                         });

}  // namespace
}  // namespace dispex
