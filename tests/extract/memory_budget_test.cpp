// A memory budget that is kept (ExtractOptions::max_memory): a rays extraction whose whole
// sculpt's BVH is estimated over the limit builds it compact where that fits, else traces in
// runs, a BVH of the sculpt within reach of one run of faces at a time, and must write the map,
// byte for byte, of the whole sculpt's BVH -- with the automatic search distance (estimated over
// the sculpt in parts too) and a given one, watertight edges on (the edge pass re-traces faces in
// runs) and off, half floats, UV-space tiles. Below what any plan needs, nothing is done and
// nothing is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/verify.h"
#include "e2e_support.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;
using testing::DataPath;
using testing::Slurp;
using testing::TempDir;

struct Variant {
  const char* name;
  bool auto_search_distance;
  WatertightEdges watertight;
  PtexDataType data_type;
  bool uv_maps;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.name;
}

class MemoryBudget : public ::testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    base_ = DataPath("meshes/keenan_spot/spot_quadrangulated.obj");
    sculpt_ = dir_ / "sculpt.ply";
    auto made = MakeSculpt(testing::SculptOptions(base_, sculpt_, 3, Pattern::kDetail, 0.005));
    ASSERT_TRUE(made.ok()) << made.status().message();
  }

  ExtractOptions Options(const std::string& name) const {
    ExtractOptions o;
    o.base_path = base_;
    o.sculpt_path = sculpt_;
    o.output_path = dir_ / (name + ".ptx");
    o.method = ExtractMethod::kRays;
    o.watertight = GetParam().watertight;
    o.data_type = GetParam().data_type;
    if (!GetParam().auto_search_distance) {
      o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
    }
    if (GetParam().uv_maps) {
      o.uv_maps_dir = dir_ / ("uv_" + name);
      o.uv_resolution = 256;
    }
    return o;
  }

  // The UV-space tiles of the map `name`, by their names less the map's.
  static std::map<std::string, std::string> Tiles(const std::string& folder,
                                                  const std::string& name) {
    std::map<std::string, std::string> out;
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string file = entry.path().filename().string();
      if (file.rfind(name + ".", 0) == 0) out[file.substr(name.size())] = Slurp(entry.path());
    }
    return out;
  }

  TempDir dir_;
  std::string base_, sculpt_;
};

bool SaysInAWarning(const ExtractReport& report, const std::string& said) {
  return std::any_of(report.warnings.begin(), report.warnings.end(),
                     [&](const std::string& w) { return w.find(said) != std::string::npos; });
}

TEST_P(MemoryBudget, CompactOrInPartsIsTheMapOfTheWholeSculpt) {
  const ExtractOptions whole = Options("whole");
  auto expected = Extract(whole);
  ASSERT_TRUE(expected.ok()) << expected.status().message();
  EXPECT_EQ(expected->plan.tracer, ExtractPlan::Tracer::kWholeSculpt);
  EXPECT_FALSE(expected->plan.compact_bvh);
  EXPECT_EQ(expected->plan.sculpt_parts, 0);
  const std::uint64_t one_pass = expected->plan.memory_estimate;
  ASSERT_GT(one_pass, 0u);
  if (GetParam().watertight != WatertightEdges::kOff) {
    EXPECT_GT(expected->edges.raised_faces, 0);  // the edge pass runs, in runs of faces
  }
  auto same_map = [&](const ExtractOptions& limited, const std::string& name) {
    EXPECT_TRUE(Slurp(limited.output_path) == Slurp(whole.output_path))
        << name << ": the map differs from the whole BVH's";
    if (GetParam().uv_maps) {
      const auto tiles = Tiles(limited.uv_maps_dir, name);
      EXPECT_FALSE(tiles.empty());
      EXPECT_TRUE(tiles == Tiles(whole.uv_maps_dir, "whole")) << name << ": the tiles differ";
    }
  };

  // A little under the one pass: the whole sculpt's BVH built compact.
  ExtractOptions compact = Options("compact");
  compact.max_memory = static_cast<std::uint64_t>(0.9 * double(one_pass));
  auto report = Extract(compact);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->plan.tracer, ExtractPlan::Tracer::kWholeSculpt);
  EXPECT_TRUE(report->plan.compact_bvh);
  EXPECT_EQ(report->plan.sculpt_parts, 0);
  EXPECT_LE(report->plan.memory_estimate, compact.max_memory);
  EXPECT_EQ(report->settings.search_distance, expected->settings.search_distance);
  EXPECT_TRUE(SaysInAWarning(*report, "built compact at medium quality"));
  same_map(compact, "compact");
  const std::uint64_t compact_pass = report->plan.memory_estimate;

  // Under what the compact BVH needs: traced in runs.
  int last_parts = 1;
  for (double fraction : {0.85, 0.7}) {
    ExtractOptions limited = Options("parts");
    limited.max_memory = static_cast<std::uint64_t>(fraction * double(compact_pass));
    report = Extract(limited);
    ASSERT_TRUE(report.ok()) << report.status().message();
    EXPECT_EQ(report->plan.tracer, ExtractPlan::Tracer::kInParts);
    EXPECT_FALSE(report->plan.compact_bvh);
    EXPECT_GT(report->plan.sculpt_parts, last_parts) << "a smaller budget, more parts";
    last_parts = report->plan.sculpt_parts;
    EXPECT_LE(report->plan.memory_estimate, limited.max_memory);
    EXPECT_EQ(report->plan.memory_limit, limited.max_memory);
    EXPECT_EQ(report->settings.search_distance, expected->settings.search_distance);
    same_map(limited, "parts");
    const std::string said = "traced in " + std::to_string(report->plan.sculpt_parts) + " parts";
    EXPECT_TRUE(SaysInAWarning(*report, said)) << "no warning says: " << said;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Variants, MemoryBudget,
    ::testing::Values(
        Variant{"auto_distance", true, WatertightEdges::kFilter, PtexDataType::kFloat, false},
        Variant{"given_distance_edges_off", false, WatertightEdges::kOff, PtexDataType::kFloat,
                false},
        Variant{"auto_distance_half", true, WatertightEdges::kFilter, PtexDataType::kHalf, false},
        Variant{"auto_distance_uv_maps", true, WatertightEdges::kFilter, PtexDataType::kFloat,
                true}),
    [](const ::testing::TestParamInfo<Variant>& param) { return std::string(param.param.name); });

// Spot's cage with a level-3 sculpt of it in `dir`, through rays.
ExtractOptions RaysOnSpot(const TempDir& dir) {
  ExtractOptions o;
  o.base_path = DataPath("meshes/keenan_spot/spot_quadrangulated.obj");
  o.sculpt_path = dir / "sculpt.ply";
  o.output_path = dir / "map.ptx";
  o.method = ExtractMethod::kRays;
  auto made =
      MakeSculpt(testing::SculptOptions(o.base_path, o.sculpt_path, 3, Pattern::kDetail, 0.005));
  EXPECT_TRUE(made.ok()) << made.status().message();
  return o;
}

TEST(MemoryBudgetRefusal, BelowWhatEveryPlanNeedsNothingIsDoneAndNothingWritten) {
  TempDir dir;
  ExtractOptions o = RaysOnSpot(dir);
  auto whole = Extract(o);
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  fs::remove(o.output_path);
  // The sculpt's arrays and the output are needed whatever the parts: a tenth of the one-pass
  // need is below them.
  o.max_memory = whole->plan.memory_estimate / 10;
  auto refused = Extract(o);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kOverBudget);
  EXPECT_NE(refused.status().message().find("max_memory"), std::string::npos)
      << refused.status().message();
  EXPECT_FALSE(fs::exists(o.output_path));
}

// A PLY sculpt is refused by its header's counts before it is read: here 200K quads whose
// corners are all -1, so a run that read the file would fail on the first face instead.
TEST(MemoryBudgetRefusal, APlySculptOverTheBudgetIsRefusedByItsHeader) {
  TempDir dir;
  ExtractOptions o = RaysOnSpot(dir);
  constexpr int kQuads = 200000;
  {
    std::ofstream out(o.sculpt_path, std::ios::binary | std::ios::trunc);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << kQuads
        << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << kQuads
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    out << std::string(12 * kQuads, '\0');
    const std::string face = std::string(1, '\4') + std::string(16, '\xff');
    for (int f = 0; f < kQuads; ++f) out << face;
  }
  // The arrays alone take 12 + 4 + 12 bytes a quad at least (5.6 MB), more than reading the
  // 5.8 MB file is estimated at; the correspondence 40 more.
  o.max_memory = 5'000'000;
  for (ExtractMethod method : {ExtractMethod::kRays, ExtractMethod::kAuto}) {
    o.method = method;
    auto refused = Extract(o);
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.status().code(), StatusCode::kOverBudget) << refused.status().message();
    EXPECT_NE(refused.status().message().find("a sculpt of 200000 faces"), std::string::npos)
        << refused.status().message();
    EXPECT_EQ(refused.status().message().find("its correspondence") != std::string::npos,
              method == ExtractMethod::kAuto)
        << refused.status().message();
  }
  // Within the budget the reader is reached, and says what is wrong with the file.
  o.max_memory = 64'000'000;
  auto read = Extract(o);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().code(), StatusCode::kOverBudget) << read.status().message();
  EXPECT_FALSE(fs::exists(o.output_path));
}

// A search distance so long that one face's rays reach most of the sculpt: no run of faces
// keeps within the budget, so the extraction is refused once the reach is known, before any
// face is traced, naming the face and what to change.
TEST(MemoryBudgetRefusal, AReachLargerThanAPartIsRefusedBeforeTracing) {
  TempDir dir;
  ExtractOptions o = RaysOnSpot(dir);
  o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.3};
  o.plan_only = true;
  auto planned = Extract(o);
  ASSERT_TRUE(planned.ok()) << planned.status().message();
  o.plan_only = false;
  o.max_memory = planned->plan.memory_estimate / 2;
  auto refused = Extract(o);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kOverBudget);
  EXPECT_NE(refused.status().message().find("within reach of Ptex face"), std::string::npos)
      << refused.status().message();
  EXPECT_NE(refused.status().message().find("search_distance"), std::string::npos);
  EXPECT_FALSE(fs::exists(o.output_path));
}

// Shards of their part of the sculpt under a budget their part's BVH does not fit in trace it in
// runs too, the automatic search distance estimated in as many parts; merged under the same
// budget, the parts are the map of one extraction without any.
TEST(MemoryBudgetShards, PartShardsWithinABudgetMergeIntoTheWholeMap) {
  TempDir dir;
  const ExtractOptions whole = RaysOnSpot(dir);
  auto expected = Extract(whole);
  ASSERT_TRUE(expected.ok()) << expected.status().message();
  const std::uint64_t budget = expected->plan.memory_estimate / 2;
  MergeOptions merge;
  merge.output_path = dir / "merged.ptx";
  merge.max_memory = budget;
  for (int i = 1; i <= 2; ++i) {
    ExtractOptions shard = whole;
    shard.output_path = dir / ("part" + std::to_string(i) + ".ptx");
    shard.shard_index = i;
    shard.shard_count = 2;
    shard.shard_sculpt = ShardSculpt::kPart;
    shard.max_memory = budget;
    auto report = Extract(shard);
    ASSERT_TRUE(report.ok()) << report.status().message();
    EXPECT_EQ(report->plan.tracer, ExtractPlan::Tracer::kInParts);
    EXPECT_LE(report->plan.memory_estimate, budget);
    EXPECT_EQ(report->plan.search_estimate_parts, report->plan.sculpt_parts);
    merge.parts.push_back(shard.output_path);
  }
  auto merged = MergeShards(merge);
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  EXPECT_EQ(merged->plan.tracer, ExtractPlan::Tracer::kInParts);
  EXPECT_TRUE(Slurp(merge.output_path) == Slurp(whole.output_path))
      << "merged part shards within a budget differ from the whole BVH's map";
}

}  // namespace
}  // namespace dispex
