// Batches and the farm through the command line (docs/FARM.md): `dispex batch` runs every asset
// and reports each, a failing one not stopping the others; `extract --shard` + `merge` give the
// map `extract` gives; `dispex farm slurm` writes job scripts that, run as Slurm would run them
// (SLURM_ARRAY_TASK_ID), produce the same maps, and submits them with the dependencies asked.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "../extract/e2e_support.h"
#include "dispex/mesh.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::RunDispex;
using testing::Slurp;
using testing::TempDir;
namespace fs = std::filesystem;

class Farm : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const auto& [name, cage] : {std::pair{"spot", "keenan_spot/spot_control_mesh.obj"},
                                     std::pair{"blub", "keenan_blub/blub_control_mesh.obj"}}) {
      ASSERT_TRUE(MakeSculpt(testing::SculptOptions(DataPath(std::string("meshes/") + cage),
                                                    dir_ / (std::string(name) + "_sculpt.obj"), 2,
                                                    Pattern::kDetail, 0.004))
                      .ok());
      fs::copy_file(DataPath(std::string("meshes/") + cage), dir_ / (std::string(name) + ".obj"));
    }
    Write("batch.json", R"({
      "options": {"search_distance": "1%", "method": "rays"},
      "assets": [
        {"name": "spot", "base": "spot.obj", "sculpt": "spot_sculpt.obj", "output_dir": "maps"},
        {"name": "blub", "base": "blub.obj", "sculpt": "blub_sculpt.obj", "output_dir": "maps",
         "options": {"data_type": "half"}}
      ]})");
  }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  // The map `dispex extract` writes for an asset of batch.json.
  std::string Expected(const std::string& name, const std::string& extra) {
    const std::string out = dir_ / ("expected_" + name + ".ptx");
    auto r = RunDispex(fmt(name) + " -o " + out + " --search-distance 1% --method rays -q " + extra,
                       dir_);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return Slurp(out);
  }
  std::string fmt(const std::string& name) const {
    return "extract " + (dir_ / (name + ".obj")) + " " + (dir_ / (name + "_sculpt.obj"));
  }

  TempDir dir_;
};

TEST_F(Farm, ABatchRunsEveryAssetAndAFailingOneDoesNotStopTheOthers) {
  Write("bad.json", R"({"assets": [
      {"name": "spot", "base": "spot.obj", "sculpt": "spot_sculpt.obj", "output_dir": "maps"},
      {"name": "gone", "base": "spot.obj", "sculpt": "missing.obj", "output_dir": "maps"},
      {"name": "blub", "base": "blub.obj", "sculpt": "blub_sculpt.obj", "output_dir": "maps"}]})");
  auto r = RunDispex("batch " + (dir_ / "bad.json") + " --report " + (dir_ / "report.json"), dir_);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("[1/3] spot: ok"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[2/3] gone: FAILED: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[3/3] blub: ok"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 of 3 assets failed"), std::string::npos) << r.err;
  const auto report = nlohmann::json::parse(Slurp(dir_ / "report.json"));
  EXPECT_EQ(report["failed"], 1);
  ASSERT_EQ(report["assets"].size(), 3u);
  EXPECT_EQ(report["assets"][0]["status"], "ok");
  EXPECT_EQ(report["assets"][1]["status"], "failed");
  EXPECT_EQ(report["assets"][2]["status"], "ok");
  EXPECT_TRUE(fs::exists(dir_ / "maps/spot.ptx"));
  EXPECT_TRUE(fs::exists(dir_ / "maps/blub.ptx"));
  EXPECT_FALSE(fs::exists(dir_ / "maps/gone.ptx"));

  // All good: exit 0, the maps `extract` writes.
  r = RunDispex("batch -q " + (dir_ / "batch.json"), dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Slurp(dir_ / "maps/spot.ptx") == Expected("spot", ""));
  EXPECT_TRUE(Slurp(dir_ / "maps/blub.ptx") == Expected("blub", "--data-type half"));
}

// The UV-space options too: a batch writes the UDIM tiles `extract --uv-maps` writes, into the
// folder named relative to the manifest.
TEST_F(Farm, ManifestsTakeTheUvOptions) {
  Write("uv.json", R"({"assets": [
      {"name": "spot", "base": "spot.obj", "sculpt": "spot_sculpt.obj", "output_dir": "maps",
       "options": {"uv_maps_dir": "tiles", "uv_resolution": 64, "uv_padding": 2,
                   "max_memory": "64G", "check_inputs": true}}]})");
  auto r = RunDispex("batch -q " + (dir_ / "uv.json"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto direct = RunDispex(fmt("spot") + " -o " + (dir_ / "direct.ptx") + " -q --uv-maps " +
                                    (dir_ / "direct") + " --uv-resolution 64 --uv-padding 2",
                                dir_);
  ASSERT_EQ(direct.exit_code, 0) << direct.err;
  std::size_t tiles = 0;
  for (const auto& entry : fs::directory_iterator(dir_ / "tiles")) {
    const std::string name = entry.path().filename().string();
    ASSERT_EQ(name.rfind("spot.", 0), 0u) << name;
    EXPECT_TRUE(Slurp(entry.path()) == Slurp(dir_ / ("direct/direct." + name.substr(5)))) << name;
    ++tiles;
  }
  EXPECT_GT(tiles, 0u);
}

TEST_F(Farm, BadManifestsFailInOneLineNamingTheEntry) {
  for (const auto& [text, needle] :
       {std::pair{R"({"assets": []})", "\"assets\" must be a non-empty list"},
        std::pair{R"({"assets": [{"name": "a b", "base": "x", "sculpt": "y", "output_dir": "m"}]})",
                  "assets[0]: \"name\" must be"},
        std::pair{R"({"assets": [{"name": "a", "base": "x", "output_dir": "m"}]})",
                  "assets[0]: no \"sculpt\" file"},
        std::pair{R"({"assets": [{"name": "a", "base": "x", "sculpt": "y", "output_dir": "m",
                     "options": {"tolerance": "big"}}]})",
                  "assets[0].options.tolerance"},
        std::pair{R"({"assets": [{"name": "a", "base": "x", "sculpt": "y", "output_dir": "m",
                     "options": {"max_memory": "8X"}}]})",
                  "assets[0].options.max_memory: '8X': unknown unit"},
        std::pair{R"({"asets": []})", "unknown key \"asets\""}}) {
    Write("m.json", text);
    for (const std::string command : {"batch ", "farm slurm --dry-run "}) {
      auto r = RunDispex(command + (dir_ / "m.json"), dir_);
      EXPECT_EQ(r.exit_code, 2) << command << text;
      EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    }
  }
}

TEST_F(Farm, ShardsThroughTheCommandLineMergeIntoTheMapExtractWrites) {
  std::string parts;
  for (const std::string i : {"1", "2", "3"}) {
    const std::string part = dir_ / ("p" + i + ".ptx");
    std::string args = fmt("spot");
    args += " -o " + part + " --search-distance 1% --method rays --shard " + i + "/3";
    // What a shard keeps of the sculpt is not an option of the map: parts of either kind merge.
    if (i == "2") args += " --shard-sculpt part";
    auto r = RunDispex(args, dir_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("shard " + i + "/3"), std::string::npos) << r.err;
    parts.insert(0, part + " ");
  }
  auto r = RunDispex("merge " + parts + "-o " + (dir_ / "merged.ptx") + " --max-memory 1x", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "dispex: --max-memory: '1x': unknown unit 'x' (K, M, G, T)\n");
  r = RunDispex("merge " + parts + "-o " + (dir_ / "merged.ptx") + " --max-memory 1G", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("merged 3 parts"), std::string::npos) << r.err;
  EXPECT_TRUE(Slurp(dir_ / "merged.ptx") == Expected("spot", ""));

  r = RunDispex(
      "merge " + (dir_ / "p1.ptx") + " " + (dir_ / "p3.ptx") + " -o " + (dir_ / "two.ptx"), dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "dispex: shard 2/3 is missing (2 of 3 parts given)\n");
  EXPECT_FALSE(fs::exists(dir_ / "two.ptx"));
  r = RunDispex(fmt("spot") + " -o " + (dir_ / "x.ptx") + " --shard 4/3", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--shard: '4/3': expected I/N"), std::string::npos) << r.err;
  r = RunDispex(fmt("spot") + " -o " + (dir_ / "x.ptx") + " --shard 1/2 --vector tangent", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("vector maps are not made in shards"), std::string::npos) << r.err;
  r = RunDispex(fmt("spot") + " --out-dir " + (dir_ / "d") + " --shard 1/2", dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("not made in shards"), std::string::npos) << r.err;
}

// The scripts, run as Slurm runs them -- each array task with its SLURM_ARRAY_TASK_ID, then each
// merge -- make the maps `extract` makes, the shards keeping only their part of the sculpt.
TEST_F(Farm, SlurmScriptsRunAsSlurmWouldMakeTheMaps) {
  const fs::path work = dir_ / "work";
  auto r = RunDispex("farm slurm " + (dir_ / "batch.json") +
                         " --shards 3 --partition render --cpus 2 --mem 4G --time 1:00:00 "
                         "--sbatch-arg=--account=fx --shard-sculpt part --dry-run --work-dir " +
                         work.string(),
                     dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string shards = Slurp(work / "shards.sbatch");
  for (const std::string line :
       {"#SBATCH --array=0-5\n", "#SBATCH --partition=render\n", "#SBATCH --cpus-per-task=2\n",
        "#SBATCH --mem=4G\n", "#SBATCH --time=1:00:00\n", "#SBATCH --account=fx\n",
        "#SBATCH --requeue\n", "assets=('spot' 'blub')\n", "sculpts=(part part)\n", "shards=3\n",
        " --shard-sculpt \"$sculpt\" "}) {
    EXPECT_NE(shards.find(line), std::string::npos) << line << " not in\n" << shards;
  }
  EXPECT_NE(shards.find(std::string("'") + DISPEX_EXE), std::string::npos)
      << "the jobs run this dispex by absolute path:\n"
      << shards;
  const std::string merge = Slurp(work / "merge-blub.sbatch");
  EXPECT_NE(merge.find("blub.part-3-of-3.ptx"), std::string::npos) << merge;
  EXPECT_NE(merge.find(" -o '" + (dir_ / "maps/blub.ptx") + "'"), std::string::npos) << merge;

  for (int task = 0; task < 6; ++task) {
    const std::string command = "cd " + dir_.path().string() +
                                " && SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " bash " +
                                (work / "shards.sbatch").string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  EXPECT_TRUE(fs::exists(work / "parts/spot.part-2-of-3.ptx"));
  for (const std::string name : {"spot", "blub"}) {
    const std::string command = "bash " + (work / ("merge-" + name + ".sbatch")).string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  EXPECT_TRUE(Slurp(dir_ / "maps/spot.ptx") == Expected("spot", ""));
  EXPECT_TRUE(Slurp(dir_ / "maps/blub.ptx") == Expected("blub", "--data-type half"));
}

// By default an asset whose one extraction is estimated at more than --mem (Slurm's units:
// megabytes without a suffix) keeps the whole sculpt where its BVH built compact fits, else is
// sharded in parts of its sculpt, and one that no shard can hold is refused before anything is
// written. (Spot's sculpt: 2,928 quads, about 595 KiB through rays, 366 KiB compact; blub's:
// 1,776, about 361 KiB, 222 KiB compact.)
TEST_F(Farm, SlurmShardsKeepTheirPartOfTheSculptWhenANodeHasTooLittleMemory) {
  const fs::path work = dir_ / "work";
  const std::string farm = "farm slurm " + (dir_ / "batch.json") +
                           " --shards 3 --dry-run --work-dir " + work.string() + " --mem ";
  // What stderr says of an asset: nothing when its one extraction fits, else how its shards keep
  // within --mem.
  const auto said = [](const std::string& err, const std::string& asset) -> std::string {
    const std::size_t at = err.find("dispex: asset " + asset + ": one extraction is estimated");
    if (at == std::string::npos) return "";
    const std::string line = err.substr(at, err.find('\n', at) - at);
    if (line.find("build its BVH compact") != std::string::npos) return "compact";
    return line.find("(--shard-sculpt part)") != std::string::npos ? "part" : line;
  };
  for (const auto& [mem, sculpts, spot, blub] :
       {std::tuple{"4000", "(whole whole)", "", ""},
        std::tuple{"400K", "(whole whole)", "compact", ""},
        std::tuple{"300K", "(part whole)", "part", "compact"},
        std::tuple{"200K", "(part part)", "part", "part"}}) {
    auto r = RunDispex(farm + mem, dir_);
    ASSERT_EQ(r.exit_code, 0) << mem << ": " << r.err;
    EXPECT_NE(Slurp(work / "shards.sbatch").find(std::string("sculpts=") + sculpts + "\n"),
              std::string::npos)
        << mem << ":\n"
        << Slurp(work / "shards.sbatch");
    EXPECT_EQ(said(r.err, "spot"), spot) << mem << ": " << r.err;
    EXPECT_EQ(said(r.err, "blub"), blub) << mem << ": " << r.err;
  }
  // Told, the shards keep what they are told.
  auto r = RunDispex(farm + "500K --shard-sculpt whole", dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(Slurp(work / "shards.sbatch").find("sculpts=(whole whole)\n"), std::string::npos);
  fs::remove_all(work);
  r = RunDispex(farm + "100K", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("batch.json: asset spot (--mem 100K): "), std::string::npos) << r.err;
  EXPECT_NE(
      r.err.find("in any shard (reading it, its arrays, the output) but a node has 100.0 KiB"),
      std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(work / "shards.sbatch"));
  r = RunDispex(farm + "4X", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "dispex: --mem: '4X': unknown unit 'X' (K, M, G, T)\n");
}

// Submission through a stand-in sbatch that records its arguments: the array job first, then
// each asset's merge after exactly its own shards' tasks.
TEST_F(Farm, SubmissionMakesEachMergeWaitForItsOwnShards) {
  Write("sbatch", "#!/bin/bash\necho \"$@\" >> " + (dir_ / "calls.txt") + "\nn=$(wc -l < " +
                      (dir_ / "calls.txt") + ")\necho \"$((40 + n));cluster\"\n");
  fs::permissions(dir_ / "sbatch", fs::perms::owner_all);
  auto r = RunDispex(
      "farm slurm " + (dir_ / "batch.json") + " --shards 2 --sbatch " + (dir_ / "sbatch"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "shards 41\nmerge spot 42\nmerge blub 43\n");
  const std::string calls = Slurp(dir_ / "calls.txt");
  const std::string work = (dir_ / "dispex-farm");
  EXPECT_EQ(calls, "--parsable " + work + "/shards.sbatch\n" +
                       "--parsable --dependency=afterok:41_0:41_1 " + work +
                       "/merge-spot.sbatch\n" + "--parsable --dependency=afterok:41_2:41_3 " +
                       work + "/merge-blub.sbatch\n");
  // An sbatch that fails: its message, non-zero.
  Write("sbatch", "#!/bin/bash\necho 'sbatch: error: invalid partition specified' >&2\nexit 1\n");
  r = RunDispex("farm slurm " + (dir_ / "batch.json") + " --sbatch " + (dir_ / "sbatch"), dir_);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("invalid partition specified"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dispex
