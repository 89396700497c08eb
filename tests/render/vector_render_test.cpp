// Rendering vector maps: the base displaced by P + D shows the vector-displaced surface (the
// sculpt of a vector pattern), unlike the scalar map of the same sculpt; the pixels do not
// depend on the thread count; the command line takes vector maps with no new flag and rejects
// maps that are neither scalar nor vector.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>

#include "../verify/vector_map_support.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"
#include "render_test_util.h"

namespace dispex {
namespace {

using render_test::RunDispex;
using render_test::TempDir;
using testing::PatternMapOptions;
using testing::WritePatternMap;

// Fraction of the pixels whose channels differ by more than `threshold`.
double Differing(const Image& a, const Image& b, int threshold) {
  int count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      count += render_test::MaxChannelDifference(a.at(x, y), b.at(x, y)) > threshold;
    }
  }
  return double(count) / (a.width * a.height);
}

// An 8 x 8 grid over [-1, 1]^2 with the overhang pattern (refined 3 times, amplitude 0.08: lambda
// 0.5, the shear up to 0.16 along (0.8, 0, 0.36), folding where the waves run back), and its
// maps at 16 x 16 texels per face: tangent vector, scalar h = D.N, and the tangent map without
// its tangential channels.
class OverhangRender : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = dir_ / "grid.obj";
    render_test::WriteText(cage_, render_test::GridCageObj(8));
    MakeSculptOptions make =
        testing::SculptOptions(cage_, dir_ / "s.obj", 3, Pattern::kOverhang, 0.08);
    auto made = MakeSculpt(make);
    ASSERT_TRUE(made.ok()) << made.status().message();
    ASSERT_GT(made->folded_faces, 0u);
    PatternMapOptions o;
    WritePatternMap(cage_, Pattern::kOverhang, made->frame, dir_ / "vector.ptx", o);
    o.drop_tangential = true;
    WritePatternMap(cage_, Pattern::kOverhang, made->frame, dir_ / "normal.ptx", o);
    o = {};
    o.space = std::nullopt;
    WritePatternMap(cage_, Pattern::kOverhang, made->frame, dir_ / "scalar.ptx", o);
    auto base = ReadMesh(cage_);
    auto sculpt = ReadMesh(dir_ / "s.obj");
    ASSERT_TRUE(base.ok() && sculpt.ok());
    base_ = std::move(*base);
    sculpt_ = std::move(*sculpt);
    options_.width = 360;
    options_.height = 270;
    options_.view.azimuth = 20;
    options_.view.elevation = 30;
  }

  Image Render(const std::string& map, SurfaceRenderOptions options) const {
    auto opened = PtexFile::Open(dir_ / map);
    EXPECT_TRUE(opened.ok()) << opened.status().message();
    auto image = RenderSurface(base_, &*opened, options);
    EXPECT_TRUE(image.ok()) << image.status().message();
    return image.ok() ? *image : Image();
  }

  TempDir dir_;
  std::string cage_;
  Mesh base_, sculpt_;
  SurfaceRenderOptions options_;
};

// The vector map's render differs from the scalar map's by the tangential part: without its
// tangential channels the vector map renders as the scalar map does (to rounding), with them
// it looks like the sculpt, which the scalar map's render does not. Rejects a renderer that
// displaces a vector map along N (by any one channel) or ignores the map's space.
TEST_F(OverhangRender, VectorMapShowsTheVectorDisplacedSurface) {
  const Image vector = Render("vector.ptx", options_);
  const Image normal = Render("normal.ptx", options_);
  const Image scalar = Render("scalar.ptx", options_);
  auto reference = RenderMesh(sculpt_, base_.positions, options_);
  ASSERT_TRUE(reference.ok());
  const double tangential = Differing(vector, scalar, 16);
  const double rounding = Differing(normal, scalar, 16);
  const double vector_off = Differing(vector, *reference, 16);
  const double scalar_off = Differing(scalar, *reference, 16);
  // Measured: 13.8% and 0.00%; against the sculpt 0.5% and 13.7%.
  EXPECT_GT(tangential, 0.1);
  EXPECT_LT(rounding, 0.005);
  EXPECT_LT(vector_off, 0.5 * scalar_off);
}

// The same pixels with one thread or two, with the mean and per-face displacement.
TEST_F(OverhangRender, PixelsDoNotDependOnThreads) {
  for (bool per_face : {false, true}) {
    SurfaceRenderOptions options = options_;
    options.per_face_displacement = per_face;
    options.threads = 1;
    const Image one = Render("vector.ptx", options);
    options.threads = 2;
    const Image two = Render("vector.ptx", options);
    EXPECT_EQ(one.rgb, two.rgb) << (per_face ? "per face" : "mean");
  }
}

// `dispex render` takes a vector map as it is and writes the library's pixels; a 3-channel map
// without dispex:vector_space is an error naming it (one line, no image) unless --channel
// picks a channel to displace along the normal.
TEST_F(OverhangRender, CommandLine) {
  auto r = RunDispex("render " + cage_ + " " + (dir_ / "vector.ptx") + " -o " + (dir_ / "v.png") +
                         " --size 360x270 --azimuth 20 --elevation 30",
                     dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto written = ReadPng(dir_ / "v.png");
  ASSERT_TRUE(written.ok());
  EXPECT_EQ(written->rgb, Render("vector.ptx", options_).rgb);

  auto map = PtexFile::Open(dir_ / "vector.ptx");
  ASSERT_TRUE(map.ok());
  PtexWriterOptions w;
  w.num_channels = 3;
  auto writer = PtexWriter::Create(dir_ / "bare.ptx", w, map->num_faces());
  ASSERT_TRUE(writer.ok());
  std::vector<float> texels;
  for (int f = 0; f < map->num_faces(); ++f) {
    ASSERT_TRUE(map->ReadFace(PtexFaceId(f), 0, texels).ok());
    ASSERT_TRUE(writer->SetFace(PtexFaceId(f), map->face_info(PtexFaceId(f)), texels).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
  r = RunDispex("render " + cage_ + " " + (dir_ / "bare.ptx") + " -o " + (dir_ / "b.png"), dir_);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err, "dispex: " + (dir_ / "bare.ptx") +
                       ": 3 channels but no dispex:vector_space meta data: not a vector "
                       "displacement map\n");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "b.png"));
  r = RunDispex("render " + cage_ + " " + (dir_ / "bare.ptx") + " --channel 2 -o " +
                    (dir_ / "b.png") + " --size 160x120 -q",
                dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "b.png"));
}

}  // namespace
}  // namespace dispex
