// End to end: Spot with a generated sculpt (dispex make-sculpt) and its extracted map. The
// render of the base displaced by the map must look like the render of the sculpt itself;
// the commands write the same pixels as the library; errors are clear and leave no file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "dispex/verify.h"
#include "render_test_util.h"

namespace dispex {
namespace {

using render_test::DataPath;
using render_test::RunDispex;
using render_test::TempDir;
using testing::SculptOptions;
namespace fs = std::filesystem;

// The demo asset, made once for the whole suite.
class SpotRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("dispex_render_spot_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    base_path_ = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
    // The README demo (fine detail) and a large smooth displacement that moves the outline.
    Make(4, Pattern::kDetail, 0.005, "S.obj", "spot.ptx");
    Make(3, Pattern::kSmooth, 0.03, "M.obj", "smooth.ptx");
  }
  static void Make(int levels, Pattern pattern, double amplitude, const std::string& sculpt,
                   const std::string& map) {
    MakeSculptOptions make = SculptOptions(base_path_, Path(sculpt), levels, pattern, amplitude);
    auto made = MakeSculpt(make);
    ASSERT_TRUE(made.ok()) << made.status().message();
    ExtractOptions extract;
    extract.base_path = base_path_;
    extract.sculpt_path = make.output_path;
    extract.output_path = Path(map);
    auto report = Extract(extract);
    ASSERT_TRUE(report.ok()) << report.status().message();
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string Path(const std::string& name) { return (*dir_ / name).string(); }

  static fs::path* dir_;
  static std::string base_path_;
};
fs::path* SpotRender::dir_ = nullptr;
std::string SpotRender::base_path_;

struct PixelDifference {
  double within = 0;    // fraction of pixels whose channels all differ by <= the threshold
  double mean_abs = 0;  // mean over pixels of the largest channel difference
};

PixelDifference Compare(const Image& a, const Image& b, int threshold) {
  PixelDifference d;
  const int n = a.width * a.height;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const int diff = render_test::MaxChannelDifference(a.at(x, y), b.at(x, y));
      d.within += diff <= threshold;
      d.mean_abs += diff;
    }
  }
  d.within /= n;
  d.mean_abs /= n;
  return d;
}

TEST_F(SpotRender, DisplacedBaseLooksLikeTheSculpt) {
  auto base = ReadMesh(base_path_);
  ASSERT_TRUE(base.ok());
  for (auto [sculpt_name, map_name] :
       {std::pair{"S.obj", "spot.ptx"}, std::pair{"M.obj", "smooth.ptx"}}) {
    auto sculpt = ReadMesh(Path(sculpt_name));
    auto map = PtexFile::Open(Path(map_name));
    ASSERT_TRUE(sculpt.ok() && map.ok());
    for (ViewPreset view : {ViewPreset::kIso, ViewPreset::kFront, ViewPreset::kLeft}) {
      SCOPED_TRACE(std::string(map_name) + " " + std::string(ViewName(view)));
      SurfaceRenderOptions options;
      options.width = 480;
      options.height = 360;
      options.view.preset = view;
      auto with_map = RenderSurface(*base, &*map, options);
      auto without = RenderSurface(*base, nullptr, options);
      auto reference = RenderMesh(*sculpt, base->positions, options);
      ASSERT_TRUE(with_map.ok()) << with_map.status().message();
      ASSERT_TRUE(without.ok() && reference.ok());
      // Stated threshold: 95% of the pixels within 12/255 in every channel.
      const PixelDifference mapped = Compare(*with_map, *reference, 12);
      const PixelDifference plain = Compare(*without, *reference, 12);
      std::printf(
          "[ %-10s %-5s ] base+map vs sculpt: %.2f%% within 12/255, mean %.2f; "
          "base vs sculpt: %.2f%%, mean %.2f\n",
          map_name, std::string(ViewName(view)).c_str(), 100 * mapped.within, mapped.mean_abs,
          100 * plain.within, plain.mean_abs);
      EXPECT_GE(mapped.within, 0.95);
      // The map is what makes the difference: without it the render is further from the
      // sculpt.
      EXPECT_LT(mapped.mean_abs, 0.7 * plain.mean_abs);
      // The object fills a good part of the frame.
      int object = 0;
      for (int y = 0; y < with_map->height; ++y) {
        for (int x = 0; x < with_map->width; ++x) {
          object += with_map->at(x, y) != std::array<std::uint8_t, 3>{44, 48, 56};
        }
      }
      EXPECT_GT(object, with_map->width * with_map->height / 8);
      // Where the sculpt shows (the plain base differs from the sculpt by more than 6/255),
      // the map render matches the sculpt within 6/255.
      int detail = 0, reproduced = 0;
      for (int y = 0; y < with_map->height; ++y) {
        for (int x = 0; x < with_map->width; ++x) {
          if (render_test::MaxChannelDifference(without->at(x, y), reference->at(x, y)) <= 6) {
            continue;
          }
          ++detail;
          reproduced +=
              render_test::MaxChannelDifference(with_map->at(x, y), reference->at(x, y)) <= 6;
        }
      }
      std::printf(
          "[ %-10s %-5s ] pixels where the sculpt differs from the base: %d, "
          "reproduced by the map: %.1f%%\n",
          map_name, std::string(ViewName(view)).c_str(), detail,
          100.0 * reproduced / std::max(detail, 1));
      EXPECT_GT(detail, 500);
      EXPECT_GE(reproduced, 0.8 * detail);
    }
  }
}

TEST_F(SpotRender, CommandsWriteTheLibrarysPixels) {
  TempDir dir;
  auto map = PtexFile::Open(Path("spot.ptx"));
  auto base = ReadMesh(base_path_);
  ASSERT_TRUE(map.ok() && base.ok());

  auto r = RunDispex(
      "preview " + Path("spot.ptx") + " -o " + (dir / "atlas.png") + " --mode grey --labels", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  AtlasOptions atlas;
  atlas.mode = AtlasMode::kGrey;
  atlas.labels = true;
  auto expected_atlas = RenderAtlas(*map, atlas);
  auto written_atlas = ReadPng(dir / "atlas.png");
  ASSERT_TRUE(expected_atlas.ok() && written_atlas.ok());
  EXPECT_EQ(written_atlas->width, expected_atlas->width);
  EXPECT_EQ(written_atlas->rgb, expected_atlas->rgb);

  r = RunDispex("render " + base_path_ + " " + Path("spot.ptx") + " -o " + (dir / "r.png") +
                    " --size 320x240 --view front --ao 4 --threads 1",
                dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  SurfaceRenderOptions options;
  options.width = 320;
  options.height = 240;
  options.view.preset = ViewPreset::kFront;
  options.ao_samples = 4;
  options.threads = 2;  // a different thread count: the same pixels
  auto expected = RenderSurface(*base, &*map, options);
  auto written = ReadPng(dir / "r.png");
  ASSERT_TRUE(expected.ok() && written.ok());
  EXPECT_EQ(written->rgb, expected->rgb);

  r = RunDispex("render " + base_path_ + " " + Path("spot.ptx") + " --compare --sculpt " +
                    Path("S.obj") + " -o " + (dir / "c.png") + " --size 960x360",
                dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto compare = ReadPng(dir / "c.png");
  ASSERT_TRUE(compare.ok());
  EXPECT_EQ(compare->width, 960);
  EXPECT_EQ(compare->height, 360);

  r = RunDispex("render " + base_path_ + " -o " + (dir / "plain.png") + " --density 4 -q", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(ReadPng(dir / "plain.png").ok());
}

// `dispex render --per-face` writes the library's per-face pixels, which differ from the
// default's where the map's faces disagree (one face of the cube raised).
TEST(RenderCommand, PerFaceWritesEachFaceDisplacedOnItsOwn) {
  TempDir dir;
  const std::string cube = DataPath("meshes/opensubdiv/catmark_cube.obj");
  render_test::WriteMap(dir / "raised.ptx", 6, 2,
                        [](int f, double, double) { return f == 0 ? 0.3f : 0.f; });
  const std::string common = " --size 240x180 --ao 2 -q";
  const std::string inputs = "render " + cube + " " + (dir / "raised.ptx");
  auto r = RunDispex(inputs + " --per-face --threads 1 -o " + (dir / "own.png") + common, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunDispex(inputs + " -o " + (dir / "mean.png") + common, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto own = ReadPng(dir / "own.png");
  auto mean = ReadPng(dir / "mean.png");
  ASSERT_TRUE(own.ok() && mean.ok());
  EXPECT_EQ(own->width, 240);
  EXPECT_EQ(own->height, 180);

  auto base = ReadMesh(cube);
  auto map = PtexFile::Open(dir / "raised.ptx");
  ASSERT_TRUE(base.ok() && map.ok());
  SurfaceRenderOptions options;
  options.width = 240;
  options.height = 180;
  options.ao_samples = 2;
  options.threads = 2;
  options.per_face_displacement = true;
  auto expected = RenderSurface(*base, &*map, options);
  ASSERT_TRUE(expected.ok()) << expected.status().message();
  EXPECT_EQ(own->rgb, expected->rgb);
  int differ = 0;
  for (int y = 0; y < own->height; ++y) {
    for (int x = 0; x < own->width; ++x) differ += own->at(x, y) != mean->at(x, y);
  }
  EXPECT_GT(differ, 100) << "--per-face made no visible difference";
}

TEST_F(SpotRender, WritePreviewsWritesTheAtlasAndTheComparison) {
  TempDir dir;
  const std::string out = dir / "previews/nested";
  ASSERT_TRUE(WritePreviews(base_path_, Path("spot.ptx"), out).ok());
  auto atlas = ReadPng(out + "/spot_atlas.png");
  auto compare = ReadPng(out + "/spot_compare.png");
  ASSERT_TRUE(atlas.ok()) << atlas.status().message();
  ASSERT_TRUE(compare.ok()) << compare.status().message();
  EXPECT_EQ(compare->width, 960);
  EXPECT_EQ(compare->height, 360);
  auto map = PtexFile::Open(Path("spot.ptx"));
  ASSERT_TRUE(map.ok());
  auto expected = RenderAtlas(*map, AtlasOptions{});
  ASSERT_TRUE(expected.ok());
  EXPECT_EQ(atlas->rgb, expected->rgb);

  Status missing = WritePreviews(dir / "nope.obj", Path("spot.ptx"), dir / "p2");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("nope.obj"), std::string::npos);
}

TEST_F(SpotRender, ErrorsAreClearAndLeaveNoFile) {
  TempDir dir;
  struct Case {
    std::string args;
    int exit_code;
    std::string message;  // expected in stderr
  };
  const std::string map = Path("spot.ptx");
  const std::string out = dir / "out.png";
  // A map for another mesh: 6 faces.
  render_test::WriteMap(dir / "cube.ptx", 6, 1, [](int, double, double) { return 0.f; });
  const Case cases[] = {
      {"render " + (dir / "missing.obj") + " -o " + out, 1, "missing.obj"},
      {"render " + base_path_ + " " + (dir / "missing.ptx") + " -o " + out, 1, "missing.ptx"},
      {"render " + base_path_ + " -o " + out + " --size 0x100", 2, "--size"},
      {"render " + base_path_ + " -o " + out + " --size big", 2, "WxH"},
      {"render " + base_path_ + " " + (dir / "cube.ptx") + " -o " + out, 1,
       "6 Ptex faces, but the base mesh"},
      {"render " + base_path_ + " -o " + (dir / "cube.ptx/dir/out.png"), 2,
       "cube.ptx is not a folder"},
      {"render " + base_path_ + " -o " + out + " --compare", 2, "--compare needs a map"},
      {"render " + base_path_ + " " + map + " -o " + out + " --sculpt " + Path("S.obj"), 2,
       "--sculpt"},
      {"render " + base_path_ + " -o " + out + " --view bottom", 2, "unknown view"},
      {"render " + base_path_ + " -o " + out + " --elevation 95", 2, "--elevation"},
      {"render " + base_path_ + " -o " + out + " --supersample 0", 2, "--supersample"},
      {"preview " + map + " -o " + out + " --tile 1", 2, "--tile"},
      {"preview " + (dir / "missing.ptx") + " -o " + out, 1, "missing.ptx"},
      {"preview " + map + " -o " + out + " --range -1", 2, "--range"},
      {"preview " + map + " -o " + out + " --mode rainbow", 2, "--mode"},
      {"preview " + map + " -o " + map, 2, "must differ"},
      {"preview " + base_path_ + " -o " + out, 1, "spot_control_mesh.obj"},
  };
  for (const Case& c : cases) {
    auto r = RunDispex(c.args, dir);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("dispex: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  // Nothing but the inputs written by the test is left in the folder.
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1u);  // cube.ptx
}

}  // namespace
}  // namespace dispex
