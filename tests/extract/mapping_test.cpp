// Scalar extraction through the subdivision correspondence (--method mapping) against the ray
// path: the kernel sample by sample, then whole maps, the method's choice, the samples it
// leaves to a BVH, and threads.
//
// The bound on t: where both methods keep the same triangle t is the same expression of the
// same floats, bit for bit; where the line passes within rounding of an edge or of a quad's
// diagonal, Embree and the mapping may keep the two triangles on either side of it, whose
// planes both hold the edge, so t differs by the rounding of where the line meets it times
// the planes' difference in slope: well under one ulp of the tracer's scale (the power of two
// at or above the base's largest |coordinate|) on these sculpts. kUlps = 4 leaves room and
// still rejects any other triangle (a cell apart is thousands of ulps).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"
#include "e2e_support.h"
#include "extract/extract_inputs.h"
#include "extract/mapping/mapping_trace.h"

namespace dispex::extract {
namespace {

using dispex::testing::DataPath;
using dispex::testing::TempDir;

constexpr double kUlps = 4;

double UlpOfScale(const Mesh& base) {
  return std::ldexp(double(TracerScale(base)), -23);
}

std::string Cage(const char* name) {
  return DataPath(std::string("meshes/opensubdiv/") + name);
}

// A refined sculpt of `cage` in `dir`.
std::string MakeRefined(const TempDir& dir, const std::string& cage, int levels, Pattern pattern,
                        const std::string& name = "sculpt.obj") {
  const std::string path = dir / name;
  auto made = MakeSculpt(dispex::testing::SculptOptions(cage, path, levels, pattern, 0));
  EXPECT_TRUE(made.ok()) << made.status().message();
  return path;
}

// ---- The kernel, sample by sample ------------------------------------------------------------

struct KernelResult {
  std::size_t samples = 0, decided = 0, hits = 0, same_t = 0, flags_differ = 0, hit_differs = 0;
  double max_ulps = 0;
};

// Every face's samples at `n` per side (2^L per sub-face side when n = 0: extract's own plan is
// 2^(L+1) on quads, 2^L on sub-faces) through TraceMapped and through the Embree tracer.
// A cage, a sculpt that is it refined, and the mapping extract builds between them (held in
// place: the surface and the mapping are built from the meshes here).
struct MappedSculpt {
  Mesh base, sculpt;
  std::optional<LimitSurface> surface;
  std::vector<PtexFaceInfo> faces;
  std::optional<SculptMapping> mapping;
};

std::unique_ptr<MappedSculpt> MapSculpt(const std::string& cage, const std::string& sculpt_path) {
  auto m = std::make_unique<MappedSculpt>();
  auto base = ReadMesh(cage);
  auto sculpt = ReadMesh(sculpt_path);
  EXPECT_TRUE(base.ok() && sculpt.ok());
  m->base = std::move(*base);
  m->sculpt = std::move(*sculpt);
  auto surface = LimitSurface::Build(m->base);
  EXPECT_TRUE(surface.ok());
  m->surface.emplace(std::move(*surface));
  m->faces = PtexFaceTable(*m->surface);
  auto correspondence = MatchRefinedSculpt(*m->surface, m->sculpt);
  EXPECT_TRUE(correspondence.ok()) << correspondence.status().message();
  auto mapping = SculptMapping::Build(*correspondence, m->sculpt, m->faces);
  EXPECT_TRUE(mapping.ok()) << mapping.status().message();
  EXPECT_TRUE(mapping->MarkFolds(*m->surface, m->sculpt, m->faces).ok());
  mapping->BuildBlocks(m->sculpt);
  m->mapping.emplace(std::move(*mapping));
  return m;
}

KernelResult CompareKernel(const std::string& cage, const std::string& sculpt_path,
                           HitPolicy policy, double distance_fraction) {
  const auto mapped = MapSculpt(cage, sculpt_path);
  const Mesh* const base = &mapped->base;
  const Mesh* const sculpt = &mapped->sculpt;
  const auto& surface = mapped->surface;
  const auto& mapping = mapped->mapping;
  EXPECT_EQ(mapping->fold_risk_faces(), 0u) << "these sculpts do not fold";
  TracerOptions options;
  options.scale = TracerScale(*base);
  auto tracer = MakeEmbreeTracer(*sculpt, options);
  EXPECT_TRUE(tracer.ok());
  const double ulp = UlpOfScale(*base);
  const NormalQuery query{static_cast<float>(distance_fraction * ComputeBounds(*base).diagonal()),
                          policy};
  LimitEvaluator evaluator(*surface);
  MappingScratch scratch;
  MappingCounters counters;
  TraceCounters trace_counters;
  KernelResult r;
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    if (surface->is_hole(PtexFaceId(f))) continue;
    const int n = 2 * mapping->grid_size(f);
    const std::size_t count = static_cast<std::size_t>(n) * n;
    std::vector<float> pos(3 * count), nrm(3 * count), t1(count), t2(count);
    std::vector<std::uint8_t> f1(count), f2(count), undecided(count);
    EXPECT_TRUE(evaluator.EvaluateGrid(PtexFaceId(f), n, n, pos, nrm).ok());
    const std::span<const Float3> o(reinterpret_cast<const Float3*>(pos.data()), count);
    const std::span<const Float3> d(reinterpret_cast<const Float3*>(nrm.data()), count);
    TraceMapped(*mapping, *sculpt, PtexFaceId(f), n, {}, o, d, query, NormalHits{t1, {}, f1},
                undecided, scratch, counters);
    (*tracer)->TraceNormals(o, d, query, NormalHits{t2, {}, f2}, trace_counters);
    for (std::size_t k = 0; k < count; ++k) {
      ++r.samples;
      if (undecided[k]) continue;
      ++r.decided;
      const bool h1 = f1[k] & HitFlags::kHit, h2 = f2[k] & HitFlags::kHit;
      r.hit_differs += h1 != h2;
      if (!h1 || !h2) continue;
      ++r.hits;
      r.same_t += std::memcmp(&t1[k], &t2[k], sizeof(float)) == 0;
      r.flags_differ += f1[k] != f2[k];
      r.max_ulps = std::max(r.max_ulps, std::fabs(double(t1[k]) - double(t2[k])) / ulp);
    }
  }
  return r;
}

struct KernelCase {
  const char* name;
  const char* cage;
  int levels;
  Pattern pattern;
};

void PrintTo(const KernelCase& c, std::ostream* os) {
  *os << c.name;
}

class MappingKernel : public ::testing::TestWithParam<KernelCase> {};

// Rejects: a kernel that misses a triangle the ray path hits (or the reverse), keeps another
// triangle than the nearest, computes t with less precision than the Tracer's plane formula in
// double (t then differs in its last bits on many samples, where here all but the ties are bit
// for bit equal), or sets other flags; and one that leaves more than a few samples undecided
// on sculpts with no fold (each costs a BVH).
TEST_P(MappingKernel, AgreesWithTheRayPathSampleBySample) {
  TempDir dir;
  const KernelCase& c = GetParam();
  const std::string sculpt = MakeRefined(dir, Cage(c.cage), c.levels, c.pattern);
  for (HitPolicy policy :
       {HitPolicy::kNearest, HitPolicy::kOutsideFirst, HitPolicy::kInsideFirst}) {
    SCOPED_TRACE(std::string(HitPolicyName(policy)));
    const KernelResult r = CompareKernel(Cage(c.cage), sculpt, policy, 0.05);
    EXPECT_GE(double(r.decided), 0.97 * double(r.samples));
    EXPECT_EQ(r.hits, r.decided) << "every decided sample hits these sculpts";
    EXPECT_EQ(r.hit_differs, 0u);
    EXPECT_EQ(r.flags_differ, 0u);
    EXPECT_LE(r.max_ulps, kUlps);
    EXPECT_GE(double(r.same_t), 0.99 * double(r.hits));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cages, MappingKernel,
    ::testing::Values(
        KernelCase{"quads_detail_l3", "catmark_cube.obj", 3, Pattern::kDetail},
        KernelCase{"ngons_detail_l3", "catmark_nonquads.obj", 3, Pattern::kDetail},
        KernelCase{"ngons_ridges_l2", "catmark_nonquads.obj", 2, Pattern::kRidges},
        KernelCase{"boundary_ridges_l3", "catmark_edgecorner.obj", 3, Pattern::kRidges},
        KernelCase{"holes_detail_l2", "catmark_hole_test1.obj", 2, Pattern::kDetail},
        KernelCase{"creases_detail_l4", "catmark_cube_creases0.obj", 4, Pattern::kDetail},
        KernelCase{"valence8_ridges_l4", "catmark_pole8.obj", 4, Pattern::kRidges}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

// ---- The two block kernels -------------------------------------------------------------------

// Every face's samples at n per side for each n of `sizes(m)` (m the face's grid), traced with
// the 4-lane kernel alone and with blocks paired (AVX2), one answer per sample to compare bit
// for bit. Returns the number of samples whose answer differs, counting those traced.
std::size_t PairedAgainstSingleBlocks(const std::string& cage, const std::string& sculpt_path,
                                      HitPolicy policy, std::size_t& samples) {
  const auto mapped = MapSculpt(cage, sculpt_path);
  const Mesh* const base = &mapped->base;
  const Mesh* const sculpt = &mapped->sculpt;
  const auto& surface = mapped->surface;
  const auto& mapping = mapped->mapping;
  const NormalQuery query{static_cast<float>(0.05 * ComputeBounds(*base).diagonal()), policy};
  LimitEvaluator evaluator(*surface);
  MappingScratch single, paired;
  single.paired_blocks = false;
  paired.paired_blocks = true;
  MappingCounters counters;
  std::size_t differ = 0;
  samples = 0;
  for (int f = 0; f < surface->num_ptex_faces(); ++f) {
    if (surface->is_hole(PtexFaceId(f))) continue;
    const int m = mapping->grid_size(f);
    // Cells of 4 samples (the default plan), of 1, of 1 or 2 by 1 or 2 (blocks of 1 to 4 lanes,
    // an odd count of blocks in a row) and of 9 to 16 (full blocks, then a remainder).
    for (const int n : {2 * m, m, m + m / 2 + 1, 3 * m + 1}) {
      const std::size_t count = static_cast<std::size_t>(n) * n;
      std::vector<float> pos(3 * count), nrm(3 * count), t1(count), t2(count);
      std::vector<std::uint8_t> f1(count), f2(count), u1(count), u2(count);
      EXPECT_TRUE(evaluator.EvaluateGrid(PtexFaceId(f), n, n, pos, nrm).ok());
      const std::span<const Float3> o(reinterpret_cast<const Float3*>(pos.data()), count);
      const std::span<const Float3> d(reinterpret_cast<const Float3*>(nrm.data()), count);
      TraceMapped(*mapping, *sculpt, PtexFaceId(f), n, {}, o, d, query, NormalHits{t1, {}, f1}, u1,
                  single, counters);
      TraceMapped(*mapping, *sculpt, PtexFaceId(f), n, {}, o, d, query, NormalHits{t2, {}, f2}, u2,
                  paired, counters);
      for (std::size_t k = 0; k < count; ++k) {
        ++samples;
        const bool same =
            u1[k] == u2[k] && (u1[k] || (f1[k] == f2[k] && std::memcmp(&t1[k], &t2[k], 4) == 0));
        differ += !same;
      }
    }
  }
  return differ;
}

// A face's grid of sculpt vertices read row by row (GridVertices, what the face keys and the
// vertex displacements read) is the grid vertex by vertex (GridVertex), and every vertex is the
// same corner of each of the (up to) four cells around it. The sculpt's faces are shuffled and
// their corners turned, so that cells sit at every rotation: reading the wrong corner of a
// cell, or a row of the wrong length, fails it.
TEST(MappingGrids, GridVerticesAreEveryCellsCorners) {
  TempDir dir;
  const std::string refined = MakeRefined(dir, Cage("catmark_nonquads.obj"), 3, Pattern::kDetail);
  auto sculpt = ReadMesh(refined);
  ASSERT_TRUE(sculpt.ok());
  std::mt19937 rng(11);
  std::vector<std::size_t> order(sculpt->num_faces());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  Mesh turned = *sculpt;
  turned.face_indices.clear();
  for (std::size_t f : order) {
    const auto face = sculpt->face(f);
    const std::size_t r = rng() % 4;
    for (std::size_t k = 0; k < 4; ++k) turned.face_indices.push_back(face[(k + r) % 4]);
  }
  const std::string path = dir / "turned.obj";
  ASSERT_TRUE(WriteObj(path, turned).ok());
  const auto mapped = MapSculpt(Cage("catmark_nonquads.obj"), path);
  const SculptMapping& mapping = *mapped->mapping;
  std::array<int, 4> rotations{};
  std::vector<VertexId> grid;
  for (int f = 0; f < mapping.num_ptex_faces(); ++f) {
    const int m = mapping.grid_size(f);
    if (m == 0) continue;
    mapping.GridVertices(f, mapped->sculpt, grid);
    const auto side = static_cast<std::size_t>(m) + 1;
    ASSERT_EQ(grid.size(), side * side);
    for (int b = 0; b <= m; ++b) {
      for (int a = 0; a <= m; ++a) {
        const VertexId v = grid[static_cast<std::size_t>(b) * side + static_cast<std::size_t>(a)];
        ASSERT_EQ(v.value, mapping.GridVertex(f, a, b, mapped->sculpt).value)
            << "face " << f << " vertex " << a << ", " << b;
        // Cell (i, j)'s corner at (a, b): 0 at (i, j), 1 at (i + 1, j), 2 at (i + 1, j + 1), 3
        // at (i, j + 1), counted from the cell's rotation.
        for (int i = std::max(a - 1, 0); i <= std::min(a, m - 1); ++i) {
          for (int j = std::max(b - 1, 0); j <= std::min(b, m - 1); ++j) {
            const std::uint32_t cell = mapping.cell(f, i, j);
            const int k = a == i ? (b == j ? 0 : 3) : (b == j ? 1 : 2);
            const auto corner = static_cast<std::size_t>(
                4 * SculptMapping::FaceOf(cell) + ((SculptMapping::RotationOf(cell) + k) & 3));
            ASSERT_EQ(v.value, mapped->sculpt.face_indices[corner])
                << "face " << f << " cell " << i << ", " << j << " corner " << k;
            ++rotations[static_cast<std::size_t>(SculptMapping::RotationOf(cell))];
          }
        }
      }
    }
  }
  for (int r = 0; r < 4; ++r) EXPECT_GT(rotations[std::size_t(r)], 0) << "rotation " << r;
}

// Rejects a paired kernel that takes a lane's lattice, slots, triangle split or line from the
// other block: its answers differ from the 4-lane kernel's (taking the first block's quads for
// both changed 1,814 samples here, its lattice 30). A lane the kernel leaves undecided goes on
// to the rings one by one and answers alike: slower, not wrong.
TEST(MappingKernels, PairedBlocksAnswerAsSingleBlocks) {
#if defined(__x86_64__)
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "this CPU lacks AVX2: one kernel only";
#else
  GTEST_SKIP() << "one kernel only off x86-64";
#endif
  TempDir dir;
  for (const auto& [cage, levels, pattern] :
       {std::tuple{"catmark_cube.obj", 3, Pattern::kDetail},
        std::tuple{"catmark_nonquads.obj", 2, Pattern::kRidges},
        std::tuple{"catmark_edgecorner.obj", 3, Pattern::kRidges}}) {
    SCOPED_TRACE(cage);
    const std::string sculpt = MakeRefined(dir, Cage(cage), levels, pattern);
    for (HitPolicy policy : {HitPolicy::kNearest, HitPolicy::kInsideFirst}) {
      std::size_t samples = 0;
      EXPECT_EQ(PairedAgainstSingleBlocks(Cage(cage), sculpt, policy, samples), 0u);
      EXPECT_GT(samples, 4000u);
    }
  }
}

// ---- Whole maps ------------------------------------------------------------------------------

ExtractOptions Options(const std::string& base, const std::string& sculpt,
                       const std::string& output, ExtractMethod method) {
  ExtractOptions o = dispex::testing::MethodOptions(base, sculpt, output, method);
  o.threads = 2;
  o.check_inputs = false;  // the fallback cases turn and lift the sculpt against its base
  return o;
}

// The same extraction both ways, into `dir`: through the mapping (mapping.ptx) and through rays
// (rays.ptx), each with `adjust` applied to its options.
template <class Adjust>
std::pair<StatusOr<ExtractReport>, StatusOr<ExtractReport>> ExtractBothWays(
    const std::string& cage, const std::string& sculpt, const TempDir& dir, Adjust adjust) {
  return {Extract(adjust(Options(cage, sculpt, dir / "mapping.ptx", ExtractMethod::kMapping))),
          Extract(adjust(Options(cage, sculpt, dir / "rays.ptx", ExtractMethod::kRays)))};
}

// Every face's texels of both maps: resolutions equal, and the largest |difference| (in ulps
// of `ulp`) and how many texels differ at all.
struct TexelComparison {
  bool same_resolutions = true;
  std::size_t texels = 0, differ = 0, beyond = 0;  // beyond: by more than kUlps
  double max_ulps = 0;
};

TexelComparison CompareTexels(const std::string& a_path, const std::string& b_path, double ulp) {
  TexelComparison c;
  auto a = PtexFile::Open(a_path);
  auto b = PtexFile::Open(b_path);
  EXPECT_TRUE(a.ok() && b.ok());
  if (!a.ok() || !b.ok() || a->num_faces() != b->num_faces()) {
    c.same_resolutions = false;
    return c;
  }
  std::vector<float> ta, tb;
  for (int f = 0; f < a->num_faces(); ++f) {
    EXPECT_TRUE(a->ReadFace(PtexFaceId(f), 0, ta).ok() && b->ReadFace(PtexFaceId(f), 0, tb).ok());
    if (ta.size() != tb.size()) {
      c.same_resolutions = false;
      continue;
    }
    for (std::size_t k = 0; k < ta.size(); ++k) {
      ++c.texels;
      c.differ += std::memcmp(&ta[k], &tb[k], sizeof(float)) != 0;
      const double ulps = std::fabs(double(ta[k]) - double(tb[k])) / ulp;
      c.max_ulps = std::max(c.max_ulps, ulps);
      c.beyond += !(ulps <= kUlps);
    }
  }
  return c;
}

struct MapCase {
  const char* name;
  const char* cage;
  int levels;
  Pattern pattern;
  HitPolicy policy = HitPolicy::kNearest;
};

void PrintTo(const MapCase& c, std::ostream* os) {
  *os << c.name;
}

class MappingMaps : public ::testing::TestWithParam<MapCase> {};

// Every texel a sample (a fixed 2^(L+1) samples per side and the same fixed resolution, holes
// zero): the maps of both methods agree texel by texel within kUlps. Rejects a mapping path
// that answers any sample differently from the ray path (another triangle, a miss, a hole
// filled differently), in the first pass or the second search.
TEST_P(MappingMaps, EveryTexelAgreesWithTheRayMap) {
  TempDir dir;
  const MapCase& c = GetParam();
  const std::string cage = Cage(c.cage);
  const std::string sculpt = MakeRefined(dir, cage, c.levels, c.pattern);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  std::string paths[2];
  ExtractReport reports[2];
  for (int m = 0; m < 2; ++m) {
    const ExtractMethod method = m == 0 ? ExtractMethod::kMapping : ExtractMethod::kRays;
    paths[m] = dir / (m == 0 ? "mapping.ptx" : "rays.ptx");
    ExtractOptions o = Options(cage, sculpt, paths[m], method);
    o.ray_policy = c.policy;
    o.oversample = 1 << (c.levels + 1);
    o.resolution_rule = ResolutionRule::kFixed;
    o.fixed_ulog2 = o.fixed_vlog2 = c.levels + 1;
    o.holes = HolePolicy::kZero;
    auto report = Extract(o);
    ASSERT_TRUE(report.ok()) << report.status().message();
    reports[m] = *report;
  }
  EXPECT_EQ(reports[0].method.used, ExtractMethod::kMapping);
  EXPECT_EQ(reports[0].method.levels, c.levels);
  EXPECT_EQ(reports[1].method.used, ExtractMethod::kRays);
  // The same automatic search distance: the same long rays, answered both ways.
  EXPECT_EQ(reports[0].settings.search_distance, reports[1].settings.search_distance);
  EXPECT_EQ(reports[0].sampling.misses, reports[1].sampling.misses);
  EXPECT_EQ(reports[0].sampling.hits_negative, reports[1].sampling.hits_negative);
  EXPECT_EQ(reports[0].sampling.hits_opposed, reports[1].sampling.hits_opposed);
  EXPECT_LE(reports[0].sampling.rays_cast, reports[1].sampling.rays_cast / 10)
      << "the mapping cast many rays";
  const TexelComparison t = CompareTexels(paths[0], paths[1], UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_GT(t.texels, 0u);
  EXPECT_LE(t.max_ulps, kUlps) << t.differ << " of " << t.texels << " texels differ";
}

INSTANTIATE_TEST_SUITE_P(
    Cages, MappingMaps,
    ::testing::Values(MapCase{"quads_detail_l2", "catmark_cube.obj", 2, Pattern::kDetail},
                      MapCase{"ngons_detail_l3", "catmark_nonquads.obj", 3, Pattern::kDetail},
                      MapCase{"boundary_ridges_l3", "catmark_edgecorner.obj", 3, Pattern::kRidges},
                      MapCase{"holes_detail_l3", "catmark_hole_test1.obj", 3, Pattern::kDetail},
                      MapCase{"creases_ridges_l4", "catmark_cube_creases0.obj", 4,
                              Pattern::kRidges},
                      MapCase{"ngons_outside_first", "catmark_nonquads.obj", 2, Pattern::kRidges,
                              HitPolicy::kOutsideFirst},
                      MapCase{"boundary_inside_first", "catmark_edgecorner.obj", 2,
                              Pattern::kDetail, HitPolicy::kInsideFirst}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

// The default options (error bound, watertight edges, automatic search distance and
// oversampling): every face at the resolution the ray map gives it, every texel within kUlps
// of the ray map's. Not byte for byte: a sample whose line passes within rounding of a quad's
// diagonal or a shared edge (on these symmetric cages, samples a quarter cell from a cell's
// corner on flat parts: exactly on its diagonal in (u, v)) takes its t from the other triangle
// than Embree's, the same plane through the edge to rounding; faces stored at their full sample
// resolution hold those samples as they are, others a linear resampling of them. Rejects any
// other difference: a resolution chosen differently, a texel beyond rounding, a search distance
// or a second search that differs.
TEST(MappingMaps, MappingMapsAgreeWithTheRayMaps) {
  for (const MapCase& c : {MapCase{"ngons", "catmark_nonquads.obj", 3, Pattern::kDetail},
                           MapCase{"creases", "catmark_cube_creases0.obj", 3, Pattern::kRidges},
                           MapCase{"holes", "catmark_hole_test1.obj", 3, Pattern::kDetail}}) {
    SCOPED_TRACE(c.name);
    TempDir dir;
    const std::string cage = Cage(c.cage);
    const std::string sculpt = MakeRefined(dir, cage, c.levels, c.pattern);
    auto base = ReadMesh(cage);
    ASSERT_TRUE(base.ok());
    auto mapping = Extract(Options(cage, sculpt, dir / "mapping.ptx", ExtractMethod::kMapping));
    auto rays = Extract(Options(cage, sculpt, dir / "rays.ptx", ExtractMethod::kRays));
    ASSERT_TRUE(mapping.ok() && rays.ok())
        << (mapping.ok() ? rays.status().message() : mapping.status().message());
    EXPECT_EQ(mapping->method.used, ExtractMethod::kMapping);
    EXPECT_EQ(mapping->settings.search_distance, rays->settings.search_distance);
    EXPECT_EQ(mapping->spectral.texels_after, rays->spectral.texels_after);
    EXPECT_EQ(mapping->edges.raised_faces, rays->edges.raised_faces);
    const TexelComparison t =
        CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
    EXPECT_TRUE(t.same_resolutions);
    EXPECT_LE(t.max_ulps, kUlps) << t.differ << " of " << t.texels << " texels differ";
  }
}

// ---- Choosing the method -----------------------------------------------------------------------

// Rejects: auto using the mapping on a sculpt that is not the base refined (or failing on
// it), mapping not failing there, or failing without the match's reason.
TEST(MappingMethod, AutoFallsBackToRaysAndMappingFailsWithTheReason) {
  TempDir dir;
  const std::string cage = Cage("catmark_nonquads.obj");
  const std::string sculpt = dir / "jittered.obj";
  ASSERT_TRUE(
      MakeSculpt(dispex::testing::JitteredSculptOptions(cage, sculpt, 8, Pattern::kDetail, 0))
          .ok());
  auto automatic = Extract(Options(cage, sculpt, dir / "auto.ptx", ExtractMethod::kAuto));
  ASSERT_TRUE(automatic.ok()) << automatic.status().message();
  EXPECT_EQ(automatic->method.used, ExtractMethod::kRays);
  EXPECT_EQ(automatic->method.levels, -1);
  EXPECT_NE(automatic->method.reason.find("only quads"), std::string::npos)
      << automatic->method.reason;
  const nlohmann::json json = nlohmann::json::parse(ExtractReportJson(*automatic));
  EXPECT_EQ(json["method"]["used"], "rays");

  auto forced = Extract(Options(cage, sculpt, dir / "mapping.ptx", ExtractMethod::kMapping));
  ASSERT_FALSE(forced.ok());
  EXPECT_EQ(forced.status().message(), "method mapping: " + automatic->method.reason);
  EXPECT_EQ(forced.status().message().find('\n'), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "mapping.ptx"));
  auto interpolated =
      Extract(Options(cage, sculpt, dir / "interpolated.ptx", ExtractMethod::kInterpolate));
  ASSERT_FALSE(interpolated.ok());
  EXPECT_EQ(interpolated.status().message(), "method interpolate: " + automatic->method.reason);
  EXPECT_FALSE(std::filesystem::exists(dir / "interpolated.ptx"));

  // Rays on a refined sculpt when asked, and the option recorded only when given.
  const std::string refined = MakeRefined(dir, cage, 2, Pattern::kSmooth, "refined.obj");
  auto rays = Extract(Options(cage, refined, dir / "rays.ptx", ExtractMethod::kRays));
  ASSERT_TRUE(rays.ok());
  EXPECT_EQ(rays->method.used, ExtractMethod::kRays);
  EXPECT_EQ(rays->times.match, 0.0);
  auto chosen = Extract(Options(cage, refined, dir / "chosen.ptx", ExtractMethod::kAuto));
  ASSERT_TRUE(chosen.ok());
  EXPECT_EQ(chosen->method.used, ExtractMethod::kInterpolate);
  EXPECT_EQ(chosen->sampling.rays_cast, 0u);
  auto options_of = [](const std::string& path) {
    auto map = PtexFile::Open(path);
    EXPECT_TRUE(map.ok());
    return nlohmann::json::parse(map->FindMetaData("dispex:options")->AsString());
  };
  EXPECT_FALSE(options_of(dir / "chosen.ptx").contains("method"));
  EXPECT_EQ(options_of(dir / "rays.ptx")["method"], "rays");
  auto statistics = PtexFile::Open(dir / "chosen.ptx");
  ASSERT_TRUE(statistics.ok());
  EXPECT_EQ(
      nlohmann::json::parse(statistics->FindMetaData("dispex:statistics")->AsString())["method"],
      "interpolate");
}

// A sculpt exported with every face wound the other way (flipped normals) is still the base
// refined: it is read reversed, with a warning, and gives the maps of the sculpt wound as the
// base is, scalar and vector, texel for texel. Rejects refusing it (the ray path then counts
// every hit as facing against the normal and holds no edge), and matching it without reversing
// the faces the mapping tests.
TEST(MappingMethod, SculptWoundTheOtherWayIsReadReversed) {
  TempDir dir;
  const std::string cage = Cage("catmark_nonquads.obj");
  auto sculpt = ReadMesh(MakeRefined(dir, cage, 3, Pattern::kDetail));
  ASSERT_TRUE(sculpt.ok());
  ASSERT_TRUE(WriteObj(dir / "wound.obj", *sculpt).ok());
  ReverseWinding(*sculpt);
  ASSERT_TRUE(WriteObj(dir / "flipped.obj", *sculpt).ok());
  for (const bool vector : {false, true}) {
    SCOPED_TRACE(vector ? "vector" : "scalar");
    std::optional<ExtractReport> reports[2];
    for (const bool flipped : {false, true}) {
      ExtractOptions o =
          Options(cage, dir / (flipped ? "flipped.obj" : "wound.obj"),
                  dir / (flipped ? "flipped.ptx" : "wound.ptx"), ExtractMethod::kAuto);
      if (vector) o.vector = VectorSpace::kObject;
      auto report = Extract(o);
      ASSERT_TRUE(report.ok()) << report.status().message();
      reports[flipped] = *report;
    }
    const ExtractReport& flipped = *reports[1];
    EXPECT_EQ(flipped.method.levels, 3);
    if (!vector) {
      EXPECT_EQ(flipped.method.used, ExtractMethod::kInterpolate);
      EXPECT_EQ(flipped.sampling.hits_opposed, 0);
      EXPECT_EQ(flipped.edges.discontinuous, 0);
    }
    ASSERT_EQ(flipped.warnings.size(), reports[0]->warnings.size() + 1);
    EXPECT_NE(flipped.warnings.back().find(
                  "flipped.obj: every face winds the other way from the base's (flipped "
                  "normals); it is read with the winding reversed"),
              std::string::npos)
        << flipped.warnings.back();
    const TexelComparison t = CompareTexels(dir / "flipped.ptx", dir / "wound.ptx", 1.0);
    EXPECT_TRUE(t.same_resolutions);
    EXPECT_GT(t.texels, 0u);
    EXPECT_EQ(t.differ, 0u);
  }
  // Through rays nothing is matched: most hits face against the normal, and the report says why.
  auto rays = Extract(Options(cage, dir / "flipped.obj", dir / "rays.ptx", ExtractMethod::kRays));
  ASSERT_TRUE(rays.ok()) << rays.status().message();
  EXPECT_GT(2 * rays->sampling.hits_opposed, rays->sampling.samples);
  ASSERT_FALSE(rays->warnings.empty());
  EXPECT_NE(rays->warnings.back().find("flipped.obj may wind the other way"), std::string::npos)
      << rays->warnings.back();
}

// Rejects a name table that loses a method, and a parser that takes what it should not.
TEST(MappingMethod, NamesRoundTrip) {
  for (ExtractMethod m : {ExtractMethod::kAuto, ExtractMethod::kRays, ExtractMethod::kMapping,
                          ExtractMethod::kInterpolate}) {
    auto parsed = ParseExtractMethod(ExtractMethodName(m));
    ASSERT_TRUE(parsed.ok());
    EXPECT_EQ(*parsed, m);
  }
  auto bad = ParseExtractMethod("bvh");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("auto, rays, mapping or interpolate"), std::string::npos);
}

// Rejects a manifest that ignores "method" or accepts an unknown one.
TEST(MappingMethod, ManifestOption) {
  TempDir dir;
  const std::string cage = Cage("catmark_cube.obj");
  std::ofstream(dir / "manifest.json")
      << R"({"output_dir": "maps", "options": {"method": "rays"}, "shapes": [)"
      << R"({"name": "a", "base": ")" << cage << R"(", "sculpt": ")" << cage
      << R"(", "options": {"method": "mapping"}}, {"name": "b", "base": ")" << cage
      << R"(", "sculpt": ")" << cage << R"("}]})";
  auto manifest = ReadExtractManifest(dir / "manifest.json", ExtractAssetOptions{});
  ASSERT_TRUE(manifest.ok()) << manifest.status().message();
  ASSERT_EQ(manifest->manifest.size(), 2u);
  EXPECT_EQ(manifest->manifest[0].options.method, ExtractMethod::kMapping);
  EXPECT_EQ(manifest->manifest[1].options.method, ExtractMethod::kRays);
  std::ofstream(dir / "bad.json") << R"({"output_dir": "maps", "options": {"method": "bvh"},)"
                                  << R"( "shapes": [{"name": "a", "base": ")" << cage
                                  << R"(", "sculpt": ")" << cage << R"("}]})";
  auto bad = ReadExtractManifest(dir / "bad.json", ExtractAssetOptions{});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("method"), std::string::npos) << bad.status().message();
}

// ---- Samples the rings do not decide ------------------------------------------------------------

// The sculpt turned about the z axis by `degrees`: its vertices move along the (nearly
// spherical) surface, several cells near the equator, so the hits of those samples lie outside
// the rings around their cells; the topology and the match stay.
std::string Turned(const TempDir& dir, const std::string& sculpt_path, double degrees) {
  auto sculpt = ReadMesh(sculpt_path);
  EXPECT_TRUE(sculpt.ok());
  const double a = degrees * M_PI / 180, c = std::cos(a), s = std::sin(a);
  for (Float3& p : sculpt->positions) {
    const double x = p.x, y = p.y;
    p.x = static_cast<float>(c * x - s * y);
    p.y = static_cast<float>(s * x + c * y);
  }
  const std::string path = dir / "turned.obj";
  EXPECT_TRUE(WriteObj(path, *sculpt).ok());
  return path;
}

// Rejects: a mapping that decides samples whose hits lie beyond its rings (the maps differ),
// one that does not count the samples it leaves to the BVH, and a fallback that depends on the
// thread count (the maps of 1 and 2 threads differ).
TEST(MappingFallback, HitsBeyondTheRingsGoToABvhAndTheMapEqualsTheRayMap) {
  TempDir dir;
  const std::string cage = Cage("catmark_cube.obj");
  const std::string sculpt = Turned(dir, MakeRefined(dir, cage, 4, Pattern::kSmooth), 25);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  auto fixed = [&](ExtractOptions o) {
    o.oversample = 32;
    o.resolution_rule = ResolutionRule::kFixed;
    o.fixed_ulog2 = o.fixed_vlog2 = 5;
    o.holes = HolePolicy::kZero;
    o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.3};
    return o;
  };
  auto [mapping, rays] = ExtractBothWays(cage, sculpt, dir, fixed);
  ASSERT_TRUE(mapping.ok()) << mapping.status().message();
  ASSERT_TRUE(rays.ok()) << rays.status().message();
  EXPECT_EQ(mapping->method.used, ExtractMethod::kMapping);
  EXPECT_GT(mapping->method.fallback_samples, 0);
  EXPECT_GT(mapping->method.fallback_faces, 0);
  EXPECT_LT(mapping->method.fallback_samples, mapping->sampling.samples);
  EXPECT_GE(mapping->sampling.rays_cast,
            static_cast<std::uint64_t>(mapping->method.fallback_samples));
  EXPECT_NE(mapping->tracer.find("left undecided"), std::string::npos) << mapping->tracer;
  EXPECT_EQ(mapping->sampling.misses, rays->sampling.misses);
  const TexelComparison t = CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_LE(t.max_ulps, kUlps) << t.differ << " of " << t.texels << " texels differ";

  ExtractOptions one = fixed(Options(cage, sculpt, dir / "one.ptx", ExtractMethod::kMapping));
  one.threads = 1;
  auto single = Extract(one);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->method.fallback_samples, mapping->method.fallback_samples);
  EXPECT_EQ(single->method.fallback_faces, mapping->method.fallback_faces);
  EXPECT_EQ(dispex::testing::Slurp(dir / "one.ptx"), dispex::testing::Slurp(dir / "mapping.ptx"));
}

// The default pipeline (edge pass, automatic distances) on the same sculpt at 1 and 2 threads:
// byte-identical files. Rejects any dependence on scheduling in the mapping, its fallback or
// the re-extraction of raised faces through it.
TEST(MappingFallback, DefaultPipelineIsTheSameAtAnyThreadCount) {
  TempDir dir;
  const std::string cage = Cage("catmark_cube.obj");
  const std::string sculpt = Turned(dir, MakeRefined(dir, cage, 3, Pattern::kDetail), 10);
  ExtractOptions two = Options(cage, sculpt, dir / "two.ptx", ExtractMethod::kMapping);
  ExtractOptions one = Options(cage, sculpt, dir / "one.ptx", ExtractMethod::kMapping);
  one.threads = 1;
  auto a = Extract(two);
  auto b = Extract(one);
  ASSERT_TRUE(a.ok() && b.ok()) << (a.ok() ? b.status().message() : a.status().message());
  EXPECT_EQ(a->method.used, ExtractMethod::kMapping);
  EXPECT_EQ(a->method.fallback_samples, b->method.fallback_samples);
  EXPECT_EQ(dispex::testing::Slurp(dir / "one.ptx"), dispex::testing::Slurp(dir / "two.ptx"));
}

// One sample per texel (2^(L+1) per side, fixed resolution, holes zero): a map's texels are
// its samples' answers.
ExtractOptions PerSample(ExtractOptions o, int levels) {
  o.oversample = 1 << (levels + 1);
  o.resolution_rule = ResolutionRule::kFixed;
  o.fixed_ulog2 = o.fixed_vlog2 = levels + 1;
  o.holes = HolePolicy::kZero;
  return o;
}

// Spot (`cage`) refined 3 times with the detail pattern, which folds: sculpt.obj in `dir`.
std::string MakeFoldingSpot(const TempDir& dir, const std::string& cage) {
  const std::string sculpt = dir / "sculpt.obj";
  auto made = MakeSculpt(dispex::testing::SculptOptions(cage, sculpt, 3, Pattern::kDetail, 0));
  EXPECT_TRUE(made.ok());
  EXPECT_GT(made.ok() ? made->folded_faces : 0u, 0u);
  return sculpt;
}

// Spot at level 3 with the detail pattern folds (MakeSculpt counts quads turned over): the faces
// around the folds go to the BVH whole, and samples farther away whose windows a folded sheet
// could reach go to it through the far-sheet check. Rejects a fold check that never fires, and
// any texel (one per sample) beyond rounding of the ray map's; with the automatic search
// distance too (AutomaticDistanceIsTheRayPaths).
TEST(MappingFallback, FoldsGoToTheBvh) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_quadrangulated.obj");
  const std::string sculpt = MakeFoldingSpot(dir, cage);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  auto given = [&](ExtractOptions o) {
    o = PerSample(o, 3);
    // Within the mapping's sheet bound (ExtractReport::method.sheet_bound, 0.08 here), which
    // cuts longer distances: hits beyond it are other sheets.
    o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0.05};
    return o;
  };
  auto [mapping, rays] = ExtractBothWays(cage, sculpt, dir, given);
  ASSERT_TRUE(mapping.ok() && rays.ok());
  EXPECT_GT(mapping->method.sheet_bound, 0.05);
  EXPECT_GT(mapping->method.fallback_faces, 0);
  EXPECT_EQ(mapping->settings.search_distance, rays->settings.search_distance);
  EXPECT_EQ(mapping->sampling.misses, rays->sampling.misses);
  const TexelComparison t = CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_GT(t.texels, 0u);
  EXPECT_EQ(t.beyond, 0u) << t.beyond << " of " << t.texels << " texels differ beyond rounding";
  EXPECT_LE(t.max_ulps, kUlps);
}

// The automatic search distance through the mapping answers the coarse samples it leaves
// undecided (near the folds) with a BVH, as the ray path answers every one: the same distance
// and the same map, beyond rounding, at default sampling. Rejects an estimate over the decided
// samples only, which gave 0.0469 here against the ray path's 0.0508, and maps that differed
// in a few texels.
TEST(MappingFallback, AutomaticDistanceIsTheRayPaths) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_quadrangulated.obj");
  const std::string sculpt = MakeFoldingSpot(dir, cage);
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  auto [mapping, rays] = ExtractBothWays(cage, sculpt, dir, [](ExtractOptions o) { return o; });
  ASSERT_TRUE(mapping.ok() && rays.ok());
  EXPECT_EQ(mapping->settings.search_distance, rays->settings.search_distance);
  const TexelComparison t = CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_EQ(t.beyond, 0u) << t.beyond << " of " << t.texels << " texels differ beyond rounding";
}

// Two 3 x 3-quad sheets over [0, 3]^2 as one cage of two components: the lower at z = 0, the
// upper at z = upper_z(i) over x = i.
template <typename Height>
std::string WriteSheets(const TempDir& dir, Height upper_z) {
  const std::string cage = dir / "sheets.obj";
  std::ofstream obj(cage);
  for (int s = 0; s < 2; ++s) {
    for (int j = 0; j <= 3; ++j) {
      for (int i = 0; i <= 3; ++i) obj << "v " << i << " " << j << " " << s * upper_z(i) << "\n";
    }
  }
  for (int s = 0; s < 2; ++s) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) {
        const int v = 16 * s + 4 * j + i + 1;
        obj << "f " << v << " " << v + 1 << " " << v + 5 << " " << v + 4 << "\n";
      }
    }
  }
  return cage;
}

// The sheets' cage refined 3 times, the lower sheet's sculpt (z < 0.01) lifted by `lift`
// (empty on failure).
std::string LiftLowerSheet(const TempDir& dir, const std::string& cage, float lift) {
  auto lifted = ReadMesh(MakeRefined(dir, cage, 3, Pattern::kNone));
  if (!lifted.ok()) return "";
  for (Float3& p : lifted->positions) {
    if (p.z < 0.01f) p.z += lift;
  }
  const std::string sculpt = dir / "lifted.obj";
  return WriteObj(sculpt, *lifted).ok() ? sculpt : "";
}

// The sheets' options: one sample per texel, a search distance of 0.12.
ExtractOptions SheetOptions(ExtractOptions o) {
  o = PerSample(o, 3);
  o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0.12};
  return o;
}

// The sheets through the mapping (`mapping`: its report) and through rays (ExtractBothWays):
// the mapping was used, the misses are the same and no texel differs beyond rounding.
void ExpectSheetsMatchRays(const TempDir& dir, const std::string& cage, const std::string& sculpt,
                           ExtractReport& mapping) {
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  auto [through_mapping, rays] = ExtractBothWays(cage, sculpt, dir, SheetOptions);
  ASSERT_TRUE(through_mapping.ok()) << through_mapping.status().message();
  ASSERT_TRUE(rays.ok()) << rays.status().message();
  mapping = *through_mapping;
  EXPECT_EQ(mapping.method.used, ExtractMethod::kMapping);
  EXPECT_EQ(mapping.sampling.misses, rays->sampling.misses);
  const TexelComparison t = CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_GT(t.texels, 0u);
  EXPECT_EQ(t.beyond, 0u) << t.beyond << " of " << t.texels << " texels differ beyond rounding";
}

// Two parallel 3 x 3-quad sheets 0.05 apart (two components of one cage); the sculpt is the
// cage refined 3 times with the lower sheet then lifted 0.08, over the upper one. A sample of
// the lower sheet's limit surface meets its own sculpt at t = 0.08 in its rings and the other
// sheet, of another component and outside every ring, at t = 0.05. Rejects a mapping that
// keeps the hit of its rings (the old rule: every texel of the lower sheet under the upper
// one differs) instead of sending the sample to the BVH, and a check that depends on the
// thread count.
TEST(MappingFallback, NearerSheetOfAnotherPartGoesToTheBvh) {
  TempDir dir;
  const std::string cage = WriteSheets(dir, [](int) { return 0.05; });
  const std::string sculpt = LiftLowerSheet(dir, cage, 0.08f);
  ASSERT_FALSE(sculpt.empty());
  ExtractReport mapping;
  ExpectSheetsMatchRays(dir, cage, sculpt, mapping);
  EXPECT_GT(mapping.method.fallback_samples, 0);
  EXPECT_LT(mapping.method.fallback_samples, mapping.sampling.samples);

  ExtractOptions one =
      SheetOptions(Options(cage, sculpt, dir / "one.ptx", ExtractMethod::kMapping));
  one.threads = 1;
  auto single = Extract(one);
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->method.fallback_samples, mapping.method.fallback_samples);
  EXPECT_EQ(dispex::testing::Slurp(dir / "one.ptx"), dispex::testing::Slurp(dir / "mapping.ptx"));
}

// The upper sheet tilted, z = 0.02 + 0.02 x, over the lower one lifted 0.03: a lower sample at
// x meets the upper sheet nearer than its own sculpt only where x < 0.5, 8 of its 48 columns
// (texel centres (i + 0.5) / 16). The upper sheet's blocks of 4 x 4 cells span 0.01 in z, so
// those over 0.5 < x < 1 reach below z = 0.03 too: their box meets the windows of 8 columns
// more, whose lines pass above them. Rejects a check by boxes alone (768 samples to the BVH)
// and one that misses a crossing (fewer than 384, and texels unlike the ray map's).
TEST(MappingFallback, OnlySamplesWhoseLinesCrossAnotherSheetGoToTheBvh) {
  TempDir dir;
  const std::string cage = WriteSheets(dir, [](int i) { return 0.02 + 0.02 * i; });
  const std::string sculpt = LiftLowerSheet(dir, cage, 0.03f);
  ASSERT_FALSE(sculpt.empty());
  ExtractReport mapping;
  ExpectSheetsMatchRays(dir, cage, sculpt, mapping);
  EXPECT_EQ(mapping.method.fallback_samples, 8 * 48);
}

// The tilted sheets of OnlySamplesWhoseLinesCrossAnotherSheetGoToTheBvh sampled 2 x 2 per face:
// each block of cells holds one sample, so every window is checked outside the check's groups
// of four. The lower sheet's samples at x = 0.25 (one column of 2 per face, over 3 faces) meet
// the upper sheet nearer than their own sculpt: 6 go to the BVH. Rejects a check that drops a
// block's last samples (0 to the BVH, texels unlike the ray map's).
TEST(MappingFallback, SamplesAfterTheLastGroupOfFourAreChecked) {
  TempDir dir;
  const std::string cage = WriteSheets(dir, [](int i) { return 0.02 + 0.02 * i; });
  const std::string sculpt = LiftLowerSheet(dir, cage, 0.03f);
  ASSERT_FALSE(sculpt.empty());
  auto base = ReadMesh(cage);
  ASSERT_TRUE(base.ok());
  auto [mapping, rays] = ExtractBothWays(cage, sculpt, dir, [](ExtractOptions o) {
    o = PerSample(o, 0);
    o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0.12};
    return o;
  });
  ASSERT_TRUE(mapping.ok()) << mapping.status().message();
  ASSERT_TRUE(rays.ok()) << rays.status().message();
  EXPECT_EQ(mapping->method.used, ExtractMethod::kMapping);
  EXPECT_EQ(mapping->method.fallback_samples, 6);
  const TexelComparison t = CompareTexels(dir / "mapping.ptx", dir / "rays.ptx", UlpOfScale(*base));
  EXPECT_TRUE(t.same_resolutions);
  EXPECT_GT(t.texels, 0u);
  EXPECT_EQ(t.beyond, 0u) << t.beyond << " of " << t.texels << " texels differ beyond rounding";
}

// ---- The command line -----------------------------------------------------------------------

// Rejects a --method the command line does not take, or one whose failure is not one line.
// DISPEX_MAPPING_KERNEL=sse2 keeps the 4-lane kernel, the report's tracer says which kernel
// ran, and the map is byte-identical to the default kernel's.
TEST(MappingCli, KernelVariable) {
  TempDir dir;
  const std::string cage = Cage("catmark_nonquads.obj");
  const std::string sculpt = MakeRefined(dir, cage, 3, Pattern::kDetail);
  auto run = [&](const std::string& name) {
    auto r = dispex::testing::RunDispex("extract " + cage + " " + sculpt + " -o " +
                                            (dir / (name + ".ptx")) + " --method mapping -q " +
                                            "--report " + (dir / (name + ".json")),
                                        dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(dispex::testing::Slurp(dir / (name + ".json")))["tracer"]
        .get<std::string>();
  };
  ASSERT_EQ(setenv("DISPEX_MAPPING_KERNEL", "sse2", 1), 0);
  const std::string single = run("single");
  unsetenv("DISPEX_MAPPING_KERNEL");
  const std::string chosen = run("chosen");
  EXPECT_NE(single.find("cells traced one at a time, SSE2"), std::string::npos) << single;
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_NE(chosen.find("cells traced two at a time, AVX2"), std::string::npos) << chosen;
  }
#endif
  EXPECT_TRUE(dispex::testing::Slurp(dir / "single.ptx") ==
              dispex::testing::Slurp(dir / "chosen.ptx"));
}

TEST(MappingCli, MethodFlag) {
  TempDir dir;
  const std::string cage = Cage("catmark_cube.obj");
  const std::string sculpt = MakeRefined(dir, cage, 2, Pattern::kSmooth);
  auto ok = dispex::testing::RunDispex("extract " + cage + " " + sculpt + " -o " + (dir / "m.ptx") +
                                           " --method mapping -q " + "--report " + (dir / "r.json"),
                                       dir);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  const nlohmann::json report = nlohmann::json::parse(dispex::testing::Slurp(dir / "r.json"));
  EXPECT_EQ(report["method"]["used"], "mapping");
  EXPECT_EQ(report["method"]["levels"], 2);
  auto bad = dispex::testing::RunDispex(
      "extract " + cage + " " + sculpt + " -o " + (dir / "b.ptx") + " --method bvh", dir);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("auto, rays, mapping or interpolate"), std::string::npos) << bad.err;
  auto unmatched =
      dispex::testing::RunDispex("extract " + cage + " " + Cage("catmark_nonquads.obj") + " -o " +
                                     (dir / "u.ptx") + " --method mapping",
                                 dir);
  EXPECT_EQ(unmatched.exit_code, 1) << unmatched.err;
  EXPECT_EQ(std::count(unmatched.err.begin(), unmatched.err.end(), '\n'), 1) << unmatched.err;
  EXPECT_NE(unmatched.err.find("method mapping: "), std::string::npos) << unmatched.err;
}

}  // namespace
}  // namespace dispex::extract
