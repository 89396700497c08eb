// Farm shards (docs/FARM.md): the parts of N shards, merged in any order, must be byte for byte
// the map one extraction writes, for N = 1, 2, 3, 5 -- with automatic and given settings, rays
// (shards of the whole sculpt, and of only their part of it, the automatic search distance
// then estimated in parts) and the subdivision correspondence, watertight edges (which cross
// shard boundaries) on and off. A shard is
// idempotent; a merge with a part missing, given twice or made from other inputs or options fails
// naming it and writes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "e2e_support.h"
#include "extract/io/extract_meta.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;
using testing::DataPath;
using testing::Slurp;
using testing::TempDir;

struct Variant {
  const char* name;
  const char* cage;  // under tests/data/meshes
  int levels;
  PtexDataType data_type;
  WatertightEdges watertight;
  bool auto_search_distance;
  ExtractMethod method;
  ShardSculpt shard_sculpt;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.name;
}

class Shards : public ::testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    base_ = dir_ / "base.obj";
    sculpt_ = dir_ / "sculpt.obj";
    auto cage = ReadMesh(DataPath("meshes/") + GetParam().cage);
    ASSERT_TRUE(cage.ok()) << cage.status().message();
    ASSERT_TRUE(WriteObj(base_, *cage).ok());
    auto made = MakeSculpt(
        testing::SculptOptions(base_, sculpt_, GetParam().levels, Pattern::kDetail, 0.005));
    ASSERT_TRUE(made.ok()) << made.status().message();
  }

  ExtractOptions Options(const std::string& output) const {
    ExtractOptions o;
    o.base_path = base_;
    o.sculpt_path = sculpt_;
    o.output_path = output;
    o.data_type = GetParam().data_type;
    o.watertight = GetParam().watertight;
    o.method = GetParam().method;
    if (!GetParam().auto_search_distance) {
      o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
    }
    return o;
  }

  // Runs shard i/n into dir/part_i_of_n.ptx.
  StatusOr<ExtractReport> Shard(int i, int n, const ExtractOptions& base_options) const {
    ExtractOptions o = base_options;
    o.output_path = dir_ / ("part_" + std::to_string(i) + "_of_" + std::to_string(n) + ".ptx");
    o.shard_index = i;
    o.shard_count = n;
    o.shard_sculpt = GetParam().shard_sculpt;
    return Extract(o);
  }
  bool TracesPart() const { return GetParam().shard_sculpt == ShardSculpt::kPart; }
  std::string PartPath(int i, int n) const {
    return dir_ / ("part_" + std::to_string(i) + "_of_" + std::to_string(n) + ".ptx");
  }

  TempDir dir_;
  std::string base_, sculpt_;
};

// K and N of ", K of N sculpt faces" in a tracer of part of the sculpt (ExtractReport::tracer);
// nullopt when the tracer does not say so.
struct PartCount {
  long long kept = 0, total = 0;
};
std::optional<PartCount> PartOfSculpt(const std::string& tracer) {
  for (std::size_t at = tracer.find(", "); at != std::string::npos;
       at = tracer.find(", ", at + 1)) {
    PartCount count;
    int end = 0;
    if (std::sscanf(tracer.c_str() + at, ", %lld of %lld sculpt faces%n", &count.kept, &count.total,
                    &end) == 2 &&
        end > 0) {
      return count;
    }
  }
  return std::nullopt;
}

TEST_P(Shards, MergedPartsEqualOneExtractionForAnyCountAndOrder) {
  const ExtractOptions full = Options(dir_ / "full.ptx");
  auto expected = Extract(full);
  ASSERT_TRUE(expected.ok()) << expected.status().message();
  const std::string full_bytes = Slurp(full.output_path);
  if (GetParam().watertight != WatertightEdges::kOff) {
    // The edge pass, which crosses shards, raises faces: the merge must run it over all faces.
    EXPECT_GT(expected->edges.raised_faces, 0);
  }
  const auto surface_faces =
      static_cast<std::int64_t>(expected->inputs.ptex_faces - expected->inputs.hole_faces);

  for (int n : {1, 2, 3, 5}) {
    std::vector<std::string> parts;
    std::int64_t extracted = 0, next = 0;
    for (int i = 1; i <= n; ++i) {
      auto shard = Shard(i, n, full);
      ASSERT_TRUE(shard.ok()) << i << "/" << n << ": " << shard.status().message();
      EXPECT_EQ(shard->shard.begin, next) << i << "/" << n;
      if (TracesPart()) {
        // The shard traces, and keeps, only the sculpt within reach of its faces; the tie
        // rule keeps its hits those of the whole sculpt.
        const std::optional<PartCount> part = PartOfSculpt(shard->tracer);
        ASSERT_TRUE(part.has_value()) << shard->tracer;
        // Spot's faces are large, each reaching far: only five shards stay clear of the whole.
        if (n == 5) {
          EXPECT_LT(part->kept, part->total) << i << "/" << n << ": " << shard->tracer;
        }
        // No BVH of the whole sculpt for the automatic search distance either.
        EXPECT_EQ(shard->plan.search_estimate_parts, GetParam().auto_search_distance ? n : 0);
        EXPECT_EQ(shard->settings.search_distance, expected->settings.search_distance);
      }
      next = shard->shard.end;
      extracted += shard->incremental.faces_extracted;
      parts.push_back(PartPath(i, n));
    }
    EXPECT_EQ(next, static_cast<std::int64_t>(expected->inputs.ptex_faces));
    EXPECT_EQ(extracted, surface_faces) << "every face extracted by exactly one shard";
    // Any order: reversed, and shuffled.
    std::reverse(parts.begin(), parts.end());
    std::shuffle(parts.begin(), parts.end(), std::mt19937(static_cast<unsigned>(n)));
    MergeOptions merge;
    merge.parts = parts;
    merge.output_path = dir_ / ("merged_" + std::to_string(n) + ".ptx");
    auto merged = MergeShards(merge);
    ASSERT_TRUE(merged.ok()) << n << " shards: " << merged.status().message();
    EXPECT_EQ(merged->shard.parts_merged, n);
    EXPECT_EQ(merged->incremental.faces_copied, surface_faces);
    EXPECT_TRUE(Slurp(merge.output_path) == full_bytes)
        << n << " shards: the merged map differs from one extraction: "
        << testing::MapDifference(merge.output_path, full.output_path);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cages, Shards,
    ::testing::Values(
        // Rays, a given search distance (the merge traces only the faces the edges raise); the
        // edge pass raises faces across shards.
        Variant{"spot_rays_given_distance_filter", "keenan_spot/spot_control_mesh.obj", 3,
                PtexDataType::kFloat, WatertightEdges::kFilter, false, ExtractMethod::kRays,
                ShardSculpt::kPart},
        // Automatic settings measured by every shard over the whole sculpt; the correspondence.
        // (Level 4: at level 3 the interpolated map meets at every edge with no face raised.)
        Variant{"spot_auto_half_all", "keenan_spot/spot_control_mesh.obj", 4, PtexDataType::kHalf,
                WatertightEdges::kAll, true, ExtractMethod::kAuto, ShardSculpt::kWhole},
        // N-gons, boundaries, no edge pass; rays from shards of their part of the sculpt, the
        // automatic search distance estimated in parts.
        Variant{"car_ngons_boundary_off_part", "opensubdiv/catmark_car.obj", 3,
                PtexDataType::kFloat, WatertightEdges::kOff, true, ExtractMethod::kRays,
                ShardSculpt::kPart}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

class ShardParts : public ::testing::Test {
 protected:
  void SetUp() override {
    sculpt_ = dir_ / "sculpt.obj";
    ASSERT_TRUE(
        MakeSculpt(testing::SculptOptions(base_, sculpt_, 2, Pattern::kDetail, 0.005)).ok());
  }
  ExtractOptions Options(int i, int n, const std::string& name) const {
    ExtractOptions o;
    o.base_path = base_;
    o.sculpt_path = sculpt_;
    o.output_path = dir_ / name;
    o.shard_index = i;
    o.shard_count = n;
    o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
    return o;
  }
  // The merge fails with a message holding `needle`, and writes nothing.
  void ExpectMergeFails(const std::vector<std::string>& parts, const std::string& needle) {
    MergeOptions merge;
    for (const std::string& p : parts) merge.parts.push_back(dir_ / p);
    merge.output_path = dir_ / "merged.ptx";
    auto r = MergeShards(merge);
    ASSERT_FALSE(r.ok()) << "merged " << parts.size() << " parts, expected: " << needle;
    EXPECT_NE(r.status().message().find(needle), std::string::npos) << r.status().message();
    EXPECT_EQ(r.status().message().find('\n'), std::string::npos) << "one line";
    EXPECT_FALSE(fs::exists(merge.output_path));
  }

  TempDir dir_;
  std::string base_ = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  std::string sculpt_;
};

TEST_F(ShardParts, AShardRunAgainWritesTheSameBytes) {
  ASSERT_TRUE(Extract(Options(2, 3, "a.ptx")).ok());
  ASSERT_TRUE(Extract(Options(2, 3, "b.ptx")).ok());
  EXPECT_TRUE(Slurp(dir_ / "a.ptx") == Slurp(dir_ / "b.ptx"));
  // Another shard of the same extraction is another part.
  ASSERT_TRUE(Extract(Options(3, 3, "c.ptx")).ok());
  EXPECT_FALSE(Slurp(dir_ / "a.ptx") == Slurp(dir_ / "c.ptx"));
}

TEST_F(ShardParts, AnIncrementalShardWithUnchangedInputsFinishesAtOnce) {
  ExtractOptions o = Options(1, 2, "part.ptx");
  o.incremental = true;
  auto first = Extract(o);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_FALSE(first->incremental.unchanged);
  const auto written = fs::last_write_time(o.output_path);
  auto again = Extract(o);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_TRUE(again->incremental.unchanged);
  EXPECT_EQ(fs::last_write_time(o.output_path), written);
  // Another shard at the same path is not up to date: its faces are other faces.
  o.shard_index = 2;
  auto other = Extract(o);
  ASSERT_TRUE(other.ok()) << other.status().message();
  EXPECT_FALSE(other->incremental.unchanged);
  EXPECT_GT(other->incremental.faces_extracted, 0);
}

TEST_F(ShardParts, AMergeOfPartsThatDoNotBelongTogetherFailsNamingThePart) {
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(Extract(Options(i, 3, "p" + std::to_string(i) + ".ptx")).ok());
  }
  ASSERT_TRUE(Extract(Options(1, 2, "two1.ptx")).ok());
  ExtractOptions other_tolerance = Options(3, 3, "tol3.ptx");
  other_tolerance.tolerance = 0.001;
  ASSERT_TRUE(Extract(other_tolerance).ok());

  ExpectMergeFails({"p1.ptx", "p3.ptx"}, "shard 2/3 is missing");
  ExpectMergeFails({"p1.ptx", "p2.ptx", "p3.ptx", "p2.ptx"}, "are both shard 2/3");
  ExpectMergeFails({"p1.ptx", "p2.ptx", "tol3.ptx"}, "tol3.ptx: made with other options than");
  ExpectMergeFails({"p1.ptx", "p2.ptx", "tol3.ptx"}, "(tolerance)");
  ExpectMergeFails({"p1.ptx", "p2.ptx", "p3.ptx", "two1.ptx"}, "two1.ptx: one of 2 shards");
  ExpectMergeFails({"p1.ptx", "p2.ptx", "nonexistent.ptx"}, "nonexistent.ptx");

  // A part made from another sculpt.
  const std::string first_sculpt = Slurp(sculpt_);
  ASSERT_TRUE(MakeSculpt(testing::SculptOptions(base_, sculpt_, 2, Pattern::kDetail, 0.007)).ok());
  ASSERT_TRUE(Extract(Options(3, 3, "new3.ptx")).ok());
  ExpectMergeFails({"p1.ptx", "p2.ptx", "new3.ptx"}, "new3.ptx: made from another sculpt than");
  // Parts made from the sculpt as it was: the sculpt there now is another.
  ExpectMergeFails({"p1.ptx", "p2.ptx", "p3.ptx"}, "than the file there now");
  { std::ofstream(sculpt_, std::ios::binary) << first_sculpt; }

  // A map that is not a part, and a part damaged since.
  ExtractOptions whole = Options(0, 0, "whole.ptx");
  ASSERT_TRUE(Extract(whole).ok());
  ExpectMergeFails({"p1.ptx", "p2.ptx", "whole.ptx"}, "whole.ptx: not a part written by a shard");
  std::string bytes = Slurp(dir_ / "p2.ptx");
  bytes[bytes.size() - 50] ^= 0x5a;
  { std::ofstream(dir_ / "bad2.ptx", std::ios::binary) << bytes; }
  ExpectMergeFails({"p1.ptx", "bad2.ptx", "p3.ptx"}, "bad2.ptx");

  // And the good parts still merge.
  MergeOptions merge;
  merge.parts = {dir_ / "p3.ptx", dir_ / "p1.ptx", dir_ / "p2.ptx"};
  merge.output_path = dir_ / "merged.ptx";
  auto merged = MergeShards(merge);
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  ASSERT_TRUE(Extract(Options(0, 0, "full.ptx")).ok());
  EXPECT_TRUE(Slurp(dir_ / "merged.ptx") == Slurp(dir_ / "full.ptx"));
}

// The merge reads the options back from the parts: every option a map records must come back
// as it was (a lost one would make the merge's map another map).
TEST(ShardOptions, OptionsReadBackFromTheirJsonAreTheSame) {
  ExtractOptions o;
  o.oversample = 16;
  o.max_oversample = 64;
  o.min_oversample = 8;
  o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0.125};
  o.ray_policy = HitPolicy::kOutsideFirst;
  o.tolerance = 0.0007;
  o.tolerance_fraction = 0.03;
  o.resolution_rule = ResolutionRule::kFixed;
  o.nonzero_threshold = 0.25;
  o.fixed_ulog2 = 3;
  o.fixed_vlog2 = 5;
  o.watertight = WatertightEdges::kAll;
  o.data_type = PtexDataType::kHalf;
  o.compression_level = 9;
  o.holes = HolePolicy::kZero;
  o.max_miss_fraction = 0.5;
  o.bvh_quality = BuildQuality::kHigh;
  o.method = ExtractMethod::kMapping;
  o.vector = VectorSpace::kObject;
  for (const ExtractOptions& options : {ExtractOptions{}, o}) {
    const nlohmann::json json = extract::ExtractOptionsJson(options);
    auto read = extract::ExtractOptionsFromJson(json);
    ASSERT_TRUE(read.ok()) << read.status().message();
    EXPECT_EQ(extract::ExtractOptionsJson(*read), json);
  }
  nlohmann::json bad = extract::ExtractOptionsJson(o);
  bad["data_type"] = "double";
  EXPECT_FALSE(extract::ExtractOptionsFromJson(bad).ok());
  bad = extract::ExtractOptionsJson(o);
  bad["unknown"] = 1;
  EXPECT_FALSE(extract::ExtractOptionsFromJson(bad).ok());
}

TEST(ShardOptions, BadShardsAndVectorMapsAreRefused) {
  ExtractOptions o;
  o.base_path = "b.obj";
  o.sculpt_path = "s.obj";
  o.output_path = "o.ptx";
  o.shard_count = 3;
  o.shard_index = 4;
  EXPECT_FALSE(ValidateExtractOptions(o).ok());
  o.shard_index = 0;
  EXPECT_FALSE(ValidateExtractOptions(o).ok());
  o.shard_index = 3;
  EXPECT_TRUE(ValidateExtractOptions(o).ok());
  o.vector = VectorSpace::kTangent;
  EXPECT_NE(ValidateExtractOptions(o).message().find("vector maps are not made in shards"),
            std::string::npos);
  o.vector.reset();
  // A shard of part of the sculpt, with any method and search distance.
  o.shard_sculpt = ShardSculpt::kPart;
  EXPECT_TRUE(ValidateExtractOptions(o).ok());
  o.shard_sculpt = ShardSculpt::kWhole;
  o.uv_maps_dir = "uv";
  EXPECT_EQ(ValidateExtractOptions(o).message(),
            "uv_maps_dir: UV-space maps are not made in shards (docs/FARM.md)");
  int i = 0, n = 0;
  EXPECT_TRUE(ParseShard("2/8", i, n).ok());
  EXPECT_EQ(i, 2);
  EXPECT_EQ(n, 8);
  for (const char* bad : {"0/3", "4/3", "1/0", "2", "a/b", "1/2x", "-1/2"}) {
    EXPECT_FALSE(ParseShard(bad, i, n).ok()) << bad;
  }
}

}  // namespace
}  // namespace dispex
