// Rendering the surface: a flat grid cage with a known bump map seen from the side shows the
// bump's profile as its silhouette (checked against the bump's own shape, independently of
// the camera), nothing rises where there is no bump, shading responds to the bump seen from
// above, threads do not change pixels, and bad inputs are clear errors.
#include <gtest/gtest.h>

#include <cmath>

#include "dispex/render.h"
#include "render_test_util.h"

namespace dispex {
namespace {

using render_test::TempDir;
using Rgb = std::array<std::uint8_t, 3>;

constexpr int kGrid = 8;
constexpr double kAmplitude = 0.3, kRadius = 0.5;
constexpr Rgb kBackground = {44, 48, 56};

// The bump over the plane: A (1 - r^2/R^2)^2 inside radius R of the origin.
double Bump(double x, double z) {
  const double q = 1.0 - (x * x + z * z) / (kRadius * kRadius);
  return q > 0 ? kAmplitude * q * q : 0.0;
}

struct Scene {
  TempDir dir;
  Mesh base;
  std::optional<PtexFile> map;
  Scene() {
    render_test::WriteText(dir / "plane.obj", render_test::GridCageObj(kGrid));
    auto mesh = ReadMesh(dir / "plane.obj");
    EXPECT_TRUE(mesh.ok()) << mesh.status().message();
    base = std::move(*mesh);
    render_test::WriteMap(dir / "bump.ptx", kGrid * kGrid, 5, [](int f, double u, double v) {
      const int i = f / kGrid, j = f % kGrid;
      const double x = -1.0 + (i + v) * 2.0 / kGrid, z = -1.0 + (j + u) * 2.0 / kGrid;
      return static_cast<float>(Bump(x, z));
    });
    auto opened = PtexFile::Open(dir / "bump.ptx");
    EXPECT_TRUE(opened.ok()) << opened.status().message();
    map.emplace(std::move(*opened));
  }
};

SurfaceRenderOptions SideView() {
  SurfaceRenderOptions o;
  o.width = 400;
  o.height = 300;
  o.view.preset = ViewPreset::kFront;  // looking along -z: x to the right, y up
  o.view.projection = Projection::kOrthographic;
  o.supersample = 1;
  o.max_density = 32;
  return o;
}

// Topmost row of column x that is not background, or -1.
int TopRow(const Image& image, int x) {
  for (int y = 0; y < image.height; ++y) {
    if (image.at(x, y) != kBackground) return y;
  }
  return -1;
}

TEST(RenderSurface, SideViewSilhouetteIsTheBumpProfile) {
  Scene scene;
  const SurfaceRenderOptions options = SideView();
  auto image = RenderSurface(scene.base, &*scene.map, options);
  ASSERT_TRUE(image.ok()) << image.status().message();
  ASSERT_EQ(image->width, 400);
  ASSERT_EQ(image->height, 300);

  // The silhouette height in pixels above the plane's row, per column.
  const double plane_row = options.height / 2.0;  // the base box is flat: it is centred
  std::vector<double> rise(static_cast<std::size_t>(image->width), 0.0);
  int peak_column = -1;
  for (int x = 0; x < image->width; ++x) {
    const int top = TopRow(*image, x);
    if (top >= 0) rise[static_cast<std::size_t>(x)] = plane_row - top;
    if (peak_column < 0 ||
        rise[static_cast<std::size_t>(x)] > rise[static_cast<std::size_t>(peak_column)]) {
      peak_column = x;
    }
  }
  const double peak = rise[static_cast<std::size_t>(peak_column)];
  ASSERT_GT(peak, 20);
  // Nothing below the plane line: the plane seen edge-on is invisible.
  for (int x = 0; x < image->width; ++x) {
    for (int y = static_cast<int>(plane_row) + 1; y < image->height; ++y) {
      ASSERT_EQ(image->at(x, y), kBackground) << x << "," << y;
    }
  }
  // Its width at half height, against its height: for A (1 - x^2/R^2)^2 the half-height
  // points are at x = +-R sqrt(1 - 1/sqrt 2), so peak / width = A / (2 R sqrt(1 - 1/sqrt 2)).
  // An orthographic view keeps the ratio, whatever the framing.
  int first = -1, last = -1;
  for (int x = 0; x < image->width; ++x) {
    if (rise[static_cast<std::size_t>(x)] >= peak / 2) {
      if (first < 0) first = x;
      last = x;
    }
  }
  const double width = last - first + 1;
  EXPECT_NEAR((first + last + 1) / 2.0, image->width / 2.0, 1.5) << "the bump is centred";
  const double expected = kAmplitude / (2 * kRadius * std::sqrt(1 - 1 / std::sqrt(2.0)));
  EXPECT_NEAR(peak / width, expected, 0.05 * expected)
      << "peak " << peak << " px, width at half height " << width << " px";
  // And the profile follows the bump: rise(x) / peak = (1 - x^2/R^2)^2 with x measured in
  // units of the half-height width.
  const double pixels_per_unit = width / (2 * kRadius * std::sqrt(1 - 1 / std::sqrt(2.0)));
  for (int x = 0; x < image->width; x += 5) {
    const double world_x = (x + 0.5 - image->width / 2.0) / pixels_per_unit;
    const double want = Bump(world_x, 0) * pixels_per_unit;
    EXPECT_NEAR(rise[static_cast<std::size_t>(x)], want, 2.5) << "column " << x;
  }
  // The camera's own projection agrees: the bump's top projects to the silhouette's top.
  auto camera = FrameCamera(ComputeBounds(scene.base), options.view, options.width, options.height);
  ASSERT_TRUE(camera.ok());
  double px = 0, py = 0;
  ASSERT_TRUE(camera->Project({0, static_cast<float>(kAmplitude), 0}, px, py));
  EXPECT_NEAR(px, image->width / 2.0, 1e-3);
  EXPECT_NEAR(TopRow(*image, image->width / 2), py, 1.5);
}

TEST(RenderSurface, WithoutTheMapTheEdgeOnPlaneShowsNothing) {
  Scene scene;
  auto image = RenderSurface(scene.base, nullptr, SideView());
  ASSERT_TRUE(image.ok()) << image.status().message();
  int drawn = 0;
  for (int y = 0; y < image->height; ++y) {
    for (int x = 0; x < image->width; ++x) drawn += image->at(x, y) != kBackground;
  }
  EXPECT_EQ(drawn, 0);
}

TEST(RenderSurface, TopViewShadesTheBumpAndNotTheFlatPart) {
  Scene scene;
  SurfaceRenderOptions options = SideView();
  options.view.preset = ViewPreset::kTop;
  options.width = options.height = 200;
  auto flat = RenderSurface(scene.base, nullptr, options);
  auto bumped = RenderSurface(scene.base, &*scene.map, options);
  ASSERT_TRUE(flat.ok() && bumped.ok());
  auto camera = FrameCamera(ComputeBounds(scene.base), options.view, 200, 200);
  ASSERT_TRUE(camera.ok());
  int changed_inside = 0, inside = 0, changed_outside = 0, outside = 0;
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      // The point of the plane this pixel sees (top view, ortho: x right, -z up).
      Float3 o, d;
      camera->RayThrough(x + 0.5, y + 0.5, o, d);
      const double r = std::hypot(o.x, o.z);
      if (std::fabs(o.x) > 0.98 || std::fabs(o.z) > 0.98) continue;
      const bool differs = render_test::MaxChannelDifference(flat->at(x, y), bumped->at(x, y)) > 3;
      if (r < 0.8 * kRadius && r > 0.15 * kRadius) {
        ++inside;
        changed_inside += differs;
      } else if (r > 1.1 * kRadius) {
        ++outside;
        changed_outside += differs;
      }
    }
  }
  EXPECT_GT(changed_inside, 0.9 * inside);
  EXPECT_EQ(changed_outside, 0);
  // The flat plane is lit uniformly.
  EXPECT_EQ(flat->at(60, 60), flat->at(140, 150));
}

TEST(RenderSurface, SamePixelsWithOneOrTwoThreads) {
  Scene scene;
  SurfaceRenderOptions options;
  options.width = 160;
  options.height = 120;
  options.ao_samples = 4;
  options.threads = 1;
  auto one = RenderSurface(scene.base, &*scene.map, options);
  options.threads = 2;
  auto two = RenderSurface(scene.base, &*scene.map, options);
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(one->rgb, two->rgb);
}

// Per-face displacement changes nothing where the faces' values agree along their edges: the
// surface, its normals and so the pixels are the mean's.
TEST(RenderSurface, PerFaceDisplacementIsTheMeanWhereFacesAgree) {
  TempDir dir;
  const std::string cube = render_test::DataPath("meshes/opensubdiv/catmark_cube.obj");
  auto base = ReadMesh(cube);
  ASSERT_TRUE(base.ok());
  render_test::WriteMap(dir / "c.ptx", 6, 3, [](int, double, double) { return 0.2f; });
  auto map = PtexFile::Open(dir / "c.ptx");
  ASSERT_TRUE(map.ok());
  SurfaceRenderOptions options;
  options.width = 200;
  options.height = 150;
  options.ao_samples = 4;
  auto mean = RenderSurface(*base, &*map, options);
  options.per_face_displacement = true;
  auto own = RenderSurface(*base, &*map, options);
  ASSERT_TRUE(mean.ok() && own.ok());
  EXPECT_EQ(own->rgb, mean->rgb);
  // The constant moved the surface: the picture is not the undisplaced one.
  auto plain = RenderSurface(*base, nullptr, options);
  ASSERT_TRUE(plain.ok());
  EXPECT_NE(own->rgb, plain->rgb);
}

// One face of the plane raised by a constant, seen from above at an angle: displaced per face,
// the raised face stands apart from its neighbours and the background shows through the gap
// along its near edges; the mean joins it to them with slopes and leaves no such hole.
TEST(RenderSurface, PerFaceDisplacementShowsTheGapsAroundARaisedFace) {
  Scene scene;
  constexpr int kRaised = 3 * kGrid + 4;
  render_test::WriteMap(scene.dir / "raised.ptx", kGrid * kGrid, 2,
                        [](int f, double, double) { return f == kRaised ? 0.25f : 0.f; });
  auto map = PtexFile::Open(scene.dir / "raised.ptx");
  ASSERT_TRUE(map.ok());
  SurfaceRenderOptions options;
  options.width = 320;
  options.height = 240;
  options.view.preset = ViewPreset::kFront;
  options.view.elevation = 30;
  options.view.azimuth = 0;
  auto mean = RenderSurface(scene.base, &*map, options);
  options.per_face_displacement = true;
  auto own = RenderSurface(scene.base, &*map, options);
  options.threads = 1;
  auto own_one_thread = RenderSurface(scene.base, &*map, options);
  ASSERT_TRUE(mean.ok() && own.ok() && own_one_thread.ok());
  EXPECT_EQ(own->rgb, own_one_thread->rgb);
  // Background pixels with surface both above and below them in their column: holes in the
  // plane as seen.
  auto holes = [](const Image& image) {
    int count = 0;
    for (int x = 0; x < image.width; ++x) {
      int top = -1, bottom = -1;
      for (int y = 0; y < image.height; ++y) {
        if (image.at(x, y) == kBackground) continue;
        if (top < 0) top = y;
        bottom = y;
      }
      for (int y = top + 1; y < bottom; ++y) count += image.at(x, y) == kBackground;
    }
    return count;
  };
  EXPECT_EQ(holes(*mean), 0);
  EXPECT_GT(holes(*own), 50);
}

TEST(RenderSurface, MapOfAnotherMeshIsAnError) {
  Scene scene;
  render_test::WriteMap(scene.dir / "small.ptx", 10, 1, [](int, double, double) { return 0.f; });
  auto small = PtexFile::Open(scene.dir / "small.ptx");
  ASSERT_TRUE(small.ok());
  auto image = RenderSurface(scene.base, &*small, SideView());
  ASSERT_FALSE(image.ok());
  const std::string& m = image.status().message();
  EXPECT_NE(m.find("small.ptx"), std::string::npos) << m;
  EXPECT_NE(m.find("10 Ptex faces"), std::string::npos) << m;
  EXPECT_NE(m.find("64"), std::string::npos) << m;
  auto compare = RenderComparison(scene.base, *small, nullptr, SideView());
  EXPECT_FALSE(compare.ok());
}

TEST(RenderSurface, MapValuesThatAreNotFiniteAreAnErrorNamingTheFace) {
  Scene scene;
  const std::string path = scene.dir / "nan.ptx";
  PtexWriterOptions options;
  options.data_type = PtexDataType::kHalf;
  auto writer = PtexWriter::Create(path, options, kGrid * kGrid);
  ASSERT_TRUE(writer.ok());
  PtexFaceInfo info;
  info.ulog2 = info.vlog2 = 1;
  const std::uint16_t zero = FloatToHalf(0.0f), nan = 0x7e00;
  for (int f = 0; f < kGrid * kGrid; ++f) {
    const std::uint16_t raw[4] = {zero, zero, f == 37 ? nan : zero, zero};
    ASSERT_TRUE(writer
                    ->SetFaceRaw(PtexFaceId(f), info,
                                 {reinterpret_cast<const std::uint8_t*>(raw), sizeof raw})
                    .ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
  auto map = PtexFile::Open(path);
  ASSERT_TRUE(map.ok());
  for (bool per_face : {false, true}) {
    for (int threads : {1, 2}) {
      SurfaceRenderOptions o = SideView();
      o.threads = threads;
      o.per_face_displacement = per_face;
      auto image = RenderSurface(scene.base, &*map, o);
      ASSERT_FALSE(image.ok());
      EXPECT_NE(image.status().message().find("nan.ptx: face 37 "), std::string::npos)
          << image.status().message();
    }
  }
}

TEST(RenderSurface, BadOptionsAreErrors) {
  Scene scene;
  SurfaceRenderOptions o;
  o.width = 0;
  EXPECT_FALSE(RenderSurface(scene.base, nullptr, o).ok());
  o = {};
  o.supersample = 9;
  EXPECT_FALSE(RenderSurface(scene.base, nullptr, o).ok());
  o = {};
  o.min_density = 32;
  o.max_density = 16;
  EXPECT_FALSE(RenderSurface(scene.base, nullptr, o).ok());
  o = {};
  o.channel = 2;
  auto r = RenderSurface(scene.base, &*scene.map, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("channel 2"), std::string::npos);
  o = {};
  o.width = 30;  // three panels of 10 pixels
  Mesh sculpt = scene.base;
  EXPECT_FALSE(RenderComparison(scene.base, *scene.map, &sculpt, o).ok());
}

TEST(RenderComparison, PanelsAreLabelledAndMatchTheSingleRenders) {
  Scene scene;
  SurfaceRenderOptions options;
  options.width = 600;
  options.height = 260;
  options.view.preset = ViewPreset::kIso;
  Mesh sculpt = scene.base;
  auto image = RenderComparison(scene.base, *scene.map, &sculpt, options);
  ASSERT_TRUE(image.ok()) << image.status().message();
  EXPECT_EQ(image->width, 600);
  EXPECT_EQ(image->height, 260);
  // Each panel is 200 wide; its label strip on top holds light text, centred.
  for (int k = 0; k < 3; ++k) {
    int text = 0;
    for (int y = 0; y < 20; ++y) {
      for (int x = 200 * k; x < 200 * k + 200; ++x) text += image->at(x, y) == Rgb{235, 235, 235};
    }
    EXPECT_GT(text, 20) << "panel " << k;
  }
  // The second panel is the map render at the panel's size, below the strip.
  const int strip = 2 * 8 + 12;  // font height 8 at scale 2, plus 6 px per scale unit
  SurfaceRenderOptions single = options;
  single.width = 200;
  single.height = 260 - strip;
  auto alone = RenderSurface(scene.base, &*scene.map, single);
  ASSERT_TRUE(alone.ok());
  int differ = 0;
  for (int y = 0; y < single.height; ++y) {
    for (int x = 0; x < 200; ++x) differ += alone->at(x, y) != image->at(200 + x, strip + y);
  }
  EXPECT_EQ(differ, 0);
  // The sculpt panel (here the flat cage itself, faceted) differs from the bump render.
  int sculpt_differs = 0;
  for (int y = strip; y < 260; ++y) {
    for (int x = 0; x < 200; ++x) {
      sculpt_differs +=
          render_test::MaxChannelDifference(image->at(400 + x, y), image->at(200 + x, y)) > 12;
    }
  }
  EXPECT_GT(sculpt_differs, 100);
}

}  // namespace
}  // namespace dispex
