// Assets of several shapes (docs/SHAPES.md): one map per shape, each shape's rays hitting only
// its own sculpt shape, the same maps whatever the order, selection or thread count, manifests
// of shapes in several files, and incremental re-extraction shape by shape.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::MapDifference;
using testing::Slurp;
using testing::TempDir;
namespace fs = std::filesystem;

// An OBJ holding `parts` as `o` groups, in order.
void WriteGroups(const std::string& path, const std::vector<std::pair<std::string, Mesh>>& parts) {
  std::ofstream out(path);
  std::size_t offset = 1;
  for (const auto& [name, mesh] : parts) {
    out << "o " << name << "\n";
    for (const Float3& p : mesh.positions) out << fmt::format("v {} {} {}\n", p.x, p.y, p.z);
    for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
      out << "f";
      for (std::int32_t v : mesh.face(f)) out << " " << offset + static_cast<std::size_t>(v);
      out << "\n";
    }
    offset += mesh.num_vertices();
  }
}

Mesh Read(const std::string& path) {
  auto mesh = ReadMesh(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(*mesh) : Mesh{};
}

class Shapes : public ::testing::Test {
 protected:
  // Two shapes in the same place: the Spot cage twice. "detail" is sculpted with detail;
  // "flat" is the limit surface itself, so a ray of "detail" that reached "flat"'s sculpt would
  // find it at t = 0, nearer than its own.
  void SetUp() override {
    cage_ = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
    detail_ = dir_ / "detail_sculpt.obj";
    flat_ = dir_ / "flat_sculpt.obj";
    ASSERT_TRUE(
        MakeSculpt(testing::SculptOptions(cage_, detail_, 3, Pattern::kDetail, 0.005)).ok());
    ASSERT_TRUE(MakeSculpt(testing::SculptOptions(cage_, flat_, 3, Pattern::kNone, 0.005)).ok());
    const Mesh cage = Read(cage_);
    base_ = dir_ / "asset.obj";
    sculpt_ = dir_ / "asset_sculpt.obj";
    WriteGroups(base_, {{"detail", cage}, {"flat", cage}});
    // The sculpt lists its shapes in another order: they pair by name.
    WriteGroups(sculpt_, {{"flat", Read(flat_)}, {"detail", Read(detail_)}});
  }

  ExtractAssetOptions Asset(const std::string& out_dir) const {
    ExtractAssetOptions o;
    o.options.base_path = base_;
    o.options.sculpt_path = sculpt_;
    o.output_dir = out_dir;
    return o;
  }

  // The map of one shape extracted on its own from its own files.
  std::string Alone(const std::string& sculpt, const std::string& name) const {
    ExtractOptions o;
    o.base_path = cage_;
    o.sculpt_path = sculpt;
    o.output_path = dir_ / (name + "_alone.ptx");
    auto r = Extract(o);
    EXPECT_TRUE(r.ok()) << r.status().message();
    return o.output_path;
  }

  TempDir dir_;
  std::string cage_, detail_, flat_, base_, sculpt_;
};

TEST_F(Shapes, EachShapeSeesOnlyItsOwnSculptShape) {
  auto report = ExtractAsset(Asset(dir_ / "maps"));
  ASSERT_TRUE(report.ok()) << report.status().message();
  ASSERT_EQ(report->shapes.size(), 2u);
  EXPECT_EQ(report->shapes[0].name, "detail");
  EXPECT_EQ(report->shapes[1].name, "flat");
  EXPECT_EQ(report->shapes[0].file, dir_ / "maps/detail.ptx");
  // The same faces as each shape extracted alone. Had the rays of "detail" met "flat" (the limit
  // surface's facets, within 2e-3 of it), they would have stopped there wherever "detail"
  // stands out by more.
  EXPECT_EQ(MapDifference(dir_ / "maps/detail.ptx", Alone(detail_, "detail"), true), "");
  EXPECT_EQ(MapDifference(dir_ / "maps/flat.ptx", Alone(flat_, "flat"), true), "");
  EXPECT_GT(report->shapes[0].report.displacement.max, 0.004);
  auto map = PtexFile::Open(dir_ / "maps/flat.ptx");
  ASSERT_TRUE(map.ok());
  ASSERT_NE(map->FindMetaData("dispex:shape"), nullptr);
  EXPECT_EQ(map->FindMetaData("dispex:shape")->AsString(), "flat");
}

TEST_F(Shapes, MapsDoNotDependOnSelectionOrderOrThreads) {
  ASSERT_TRUE(ExtractAsset(Asset(dir_ / "all")).ok());
  ExtractAssetOptions one = Asset(dir_ / "one");
  one.shapes = {"flat", "detail"};
  one.options.threads = 1;
  auto report = ExtractAsset(one);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_EQ(report->shapes[0].name, "detail");  // the base's order, not the selection's
  for (const char* name : {"detail.ptx", "flat.ptx"}) {
    EXPECT_EQ(Slurp(dir_ / ("all/" + std::string(name))),
              Slurp(dir_ / ("one/" + std::string(name))))
        << name;
  }
  ExtractAssetOptions only = Asset(dir_ / "only");
  only.shapes = {"flat"};
  ASSERT_TRUE(ExtractAsset(only).ok());
  EXPECT_FALSE(fs::exists(dir_ / "only/detail.ptx"));
  EXPECT_EQ(Slurp(dir_ / "all/flat.ptx"), Slurp(dir_ / "only/flat.ptx"));
}

TEST_F(Shapes, MismatchedNamesAndMultiShapeBasesAreClearErrors) {
  // One map for a base of two shapes.
  ExtractOptions single;
  single.base_path = base_;
  single.sculpt_path = sculpt_;
  single.output_path = dir_ / "one.ptx";
  auto r = Extract(single);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("2 shapes ('detail', 'flat')"), std::string::npos)
      << r.status().message();
  EXPECT_FALSE(fs::exists(single.output_path));

  // A sculpt shape whose name differs in letter case.
  WriteGroups(sculpt_, {{"Flat", Read(flat_)}, {"detail", Read(detail_)}});
  auto a = ExtractAsset(Asset(dir_ / "maps"));
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find("has no shape 'flat'"), std::string::npos)
      << a.status().message();
  EXPECT_NE(a.status().message().find("only in letter case or blanks"), std::string::npos);

  ExtractAssetOptions unknown = Asset(dir_ / "maps");
  unknown.shapes = {"belt"};
  auto u = ExtractAsset(unknown);
  ASSERT_FALSE(u.ok());
  EXPECT_NE(u.status().message().find("'belt'"), std::string::npos) << u.status().message();
}

TEST_F(Shapes, UnsafeNamesBecomeDistinctFileNames) {
  const Mesh cage = Read(cage_);
  WriteGroups(base_, {{"left arm/1", cage}, {"Left arm_1", cage}});
  WriteGroups(sculpt_, {{"left arm/1", Read(detail_)}, {"Left arm_1", Read(flat_)}});
  auto report = ExtractAsset(Asset(dir_ / "maps"));
  ASSERT_TRUE(report.ok()) << report.status().message();
  ASSERT_EQ(report->shapes.size(), 2u);
  EXPECT_NE(report->shapes[0].file, report->shapes[1].file);
  for (const auto& shape : report->shapes) {
    EXPECT_TRUE(fs::exists(shape.file)) << shape.file;
    EXPECT_EQ(fs::path(shape.file).filename().string().find_first_of(" /"), std::string::npos);
  }
}

TEST_F(Shapes, ManifestNamesShapesInSeveralFilesWithTheirOwnOptions) {
  const std::string manifest = dir_ / "asset.json";
  std::ofstream(manifest) << R"({
    "output_dir": "from_manifest",
    "options": {"max_oversample": 64},
    "shapes": [
      {"name": "detail", "base": ")"
                          << cage_ << R"(", "sculpt": "detail_sculpt.obj",
       "options": {"tolerance": 0.002, "watertight": "off"}},
      {"name": "flat", "base": "asset.obj", "sculpt": "asset_sculpt.obj",
       "options": {"resolution_rule": "fixed", "fixed_resolution": "8x16"}}
    ]
  })";
  auto options = ReadExtractManifest(manifest, ExtractAssetOptions{});
  ASSERT_TRUE(options.ok()) << options.status().message();
  auto report = ExtractAsset(*options);
  ASSERT_TRUE(report.ok()) << report.status().message();
  ASSERT_EQ(report->shapes.size(), 2u);
  EXPECT_EQ(report->shapes[0].report.settings.tolerance, 0.002);
  EXPECT_EQ(report->shapes[0].report.edges.rule, WatertightEdges::kOff);
  EXPECT_EQ(report->shapes[1].report.options.max_oversample, 64);
  EXPECT_EQ(report->shapes[1].report.spectral.ulog2_faces[3], 252);
  EXPECT_EQ(report->shapes[1].report.spectral.vlog2_faces[4], 252);
  EXPECT_TRUE(fs::exists(dir_ / "from_manifest/detail.ptx"));
  EXPECT_TRUE(fs::exists(dir_ / "from_manifest/flat.ptx"));

  std::ofstream(manifest) << R"({"shapes": [{"name": "x", "base": "a.obj", "sculpt": "b.obj",
                                             "options": {"tolerence": 1}}]})";
  auto bad = ReadExtractManifest(manifest, ExtractAssetOptions{});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("shapes[0].options.tolerence: unknown option"),
            std::string::npos)
      << bad.status().message();
}

TEST_F(Shapes, IncrementalRedoesOnlyTheShapeThatChanged) {
  ExtractAssetOptions o = Asset(dir_ / "maps");
  o.options.incremental = true;
  ASSERT_TRUE(ExtractAsset(o).ok());
  const auto flat_time = fs::last_write_time(dir_ / "maps/flat.ptx");
  // The detail shape re-sculpted with another pattern; flat unchanged.
  ASSERT_TRUE(MakeSculpt(testing::SculptOptions(cage_, detail_, 3, Pattern::kSmooth, 0.005)).ok());
  WriteGroups(sculpt_, {{"flat", Read(flat_)}, {"detail", Read(detail_)}});
  auto report = ExtractAsset(o);
  ASSERT_TRUE(report.ok()) << report.status().message();
  EXPECT_FALSE(report->shapes[0].report.incremental.unchanged);
  EXPECT_TRUE(report->shapes[1].report.incremental.unchanged);
  EXPECT_EQ(fs::last_write_time(dir_ / "maps/flat.ptx"), flat_time);
  ExtractAssetOptions full = Asset(dir_ / "full");
  ASSERT_TRUE(ExtractAsset(full).ok());
  for (const char* name : {"detail.ptx", "flat.ptx"}) {
    EXPECT_EQ(Slurp(dir_ / ("maps/" + std::string(name))),
              Slurp(dir_ / ("full/" + std::string(name))))
        << name;
  }
}

TEST_F(Shapes, AddedAndRemovedShapesLeaveTheOthersUntouched) {
  ExtractAssetOptions o = Asset(dir_ / "maps");
  o.options.incremental = true;
  ASSERT_TRUE(ExtractAsset(o).ok());
  const auto detail_time = fs::last_write_time(dir_ / "maps/detail.ptx");
  const Mesh cage = Read(cage_);
  // "flat" removed: "detail" is up to date; flat.ptx stays where it was.
  WriteGroups(base_, {{"detail", cage}});
  auto removed = ExtractAsset(o);
  ASSERT_TRUE(removed.ok()) << removed.status().message();
  ASSERT_EQ(removed->shapes.size(), 1u);
  EXPECT_TRUE(removed->shapes[0].report.incremental.unchanged);
  EXPECT_EQ(fs::last_write_time(dir_ / "maps/detail.ptx"), detail_time);
  // "flat" back and a third shape added (a sculpt shape of the same name exists now).
  WriteGroups(base_, {{"detail", cage}, {"flat", cage}, {"again", cage}});
  WriteGroups(sculpt_,
              {{"flat", Read(flat_)}, {"detail", Read(detail_)}, {"again", Read(detail_)}});
  auto added = ExtractAsset(o);
  ASSERT_TRUE(added.ok()) << added.status().message();
  ASSERT_EQ(added->shapes.size(), 3u);
  EXPECT_TRUE(added->shapes[0].report.incremental.unchanged);
  EXPECT_TRUE(added->shapes[1].report.incremental.unchanged);
  EXPECT_EQ(added->shapes[2].report.incremental.redo_reason, "no previous map");
  ASSERT_TRUE(ExtractAsset(Asset(dir_ / "full")).ok());
  for (const char* name : {"detail.ptx", "flat.ptx", "again.ptx"}) {
    EXPECT_EQ(Slurp(dir_ / ("maps/" + std::string(name))),
              Slurp(dir_ / ("full/" + std::string(name))))
        << name;
  }
}

}  // namespace
}  // namespace dispex
