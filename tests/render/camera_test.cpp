// Camera presets, framing and the ray/projection pair; option parsers.
#include <gtest/gtest.h>

#include <cmath>

#include "dispex/render.h"

namespace dispex {
namespace {

void ExpectNear(const Float3& a, const Float3& b, double tol = 1e-6) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

BoundingBox Box() {
  BoundingBox box;
  box.min = {-1, -0.5f, -2};
  box.max = {3, 1.5f, 0.5f};
  return box;
}

TEST(Camera, PresetsLookFromTheirSide) {
  struct Case {
    ViewPreset preset;
    Float3 forward, right, up;
  };
  const Case cases[] = {
      {ViewPreset::kFront, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}},
      {ViewPreset::kBack, {0, 0, 1}, {-1, 0, 0}, {0, 1, 0}},
      {ViewPreset::kRight, {-1, 0, 0}, {0, 0, -1}, {0, 1, 0}},
      {ViewPreset::kLeft, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {ViewPreset::kTop, {0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
  };
  for (const Case& c : cases) {
    ViewOptions view;
    view.preset = c.preset;
    auto camera = FrameCamera(Box(), view, 200, 100);
    ASSERT_TRUE(camera.ok()) << camera.status().message();
    SCOPED_TRACE(std::string(ViewName(c.preset)));
    ExpectNear(camera->forward, c.forward);
    ExpectNear(camera->right, c.right);
    ExpectNear(camera->up, c.up);
  }
  ViewOptions iso;
  auto camera = FrameCamera(Box(), iso, 200, 100);
  ASSERT_TRUE(camera.ok());
  const float k = static_cast<float>(-1.0 / std::sqrt(3.0));
  ExpectNear(camera->forward, {k, k, k});
}

TEST(Camera, AnglesOverrideThePreset) {
  ViewOptions view;
  view.preset = ViewPreset::kTop;
  view.azimuth = 90;
  view.elevation = 0;
  auto camera = FrameCamera(Box(), view, 64, 64);
  ASSERT_TRUE(camera.ok());
  ExpectNear(camera->forward, {-1, 0, 0});
}

TEST(Camera, RayThroughAndProjectAreInverse) {
  for (Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    ViewOptions view;
    view.projection = projection;
    view.azimuth = 30;
    view.elevation = -20;
    auto camera = FrameCamera(Box(), view, 320, 180);
    ASSERT_TRUE(camera.ok());
    for (double px : {0.0, 13.5, 160.0, 319.9}) {
      for (double py : {0.0, 90.0, 177.25}) {
        Float3 o, d;
        camera->RayThrough(px, py, o, d);
        EXPECT_NEAR(d.x * d.x + d.y * d.y + d.z * d.z, 1.0, 1e-6);
        const Float3 p = {o.x + 3 * d.x, o.y + 3 * d.y, o.z + 3 * d.z};
        double qx = 0, qy = 0;
        ASSERT_TRUE(camera->Project(p, qx, qy));
        EXPECT_NEAR(qx, px, 1e-3);
        EXPECT_NEAR(qy, py, 1e-3);
      }
    }
  }
}

TEST(Camera, FramesAllCornersWithinTheMarginAndTightly) {
  const BoundingBox box = Box();
  for (Projection projection : {Projection::kPerspective, Projection::kOrthographic}) {
    for (ViewPreset preset :
         {ViewPreset::kFront, ViewPreset::kRight, ViewPreset::kTop, ViewPreset::kIso}) {
      for (auto [w, h] : {std::pair{400, 300}, std::pair{100, 400}}) {
        ViewOptions view;
        view.preset = preset;
        view.projection = projection;
        view.margin = 0.1;
        auto camera = FrameCamera(box, view, w, h);
        ASSERT_TRUE(camera.ok());
        double slack = 1e9;  // the smallest distance from a corner to the margin line, pixels
        for (int c = 0; c < 8; ++c) {
          const Float3 p = {c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y,
                            c & 4 ? box.max.z : box.min.z};
          double px = 0, py = 0;
          ASSERT_TRUE(camera->Project(p, px, py));
          EXPECT_GE(px, 0.1 * w - 1e-3);
          EXPECT_LE(px, 0.9 * w + 1e-3);
          EXPECT_GE(py, 0.1 * h - 1e-3);
          EXPECT_LE(py, 0.9 * h + 1e-3);
          slack = std::min({slack, px - 0.1 * w, 0.9 * w - px, py - 0.1 * h, 0.9 * h - py});
        }
        // Orthographic framing is exact; a perspective camera looking at the centre leaves
        // a little room on the far side.
        EXPECT_LT(slack, projection == Projection::kOrthographic ? 1e-3 : 0.1 * std::min(w, h))
            << ViewName(preset) << " " << ProjectionName(projection) << " " << w << "x" << h;
      }
    }
  }
}

TEST(Camera, BadViewsAreErrors) {
  ViewOptions view;
  view.elevation = 91;
  EXPECT_FALSE(FrameCamera(Box(), view, 10, 10).ok());
  view = {};
  view.azimuth = INFINITY;
  EXPECT_FALSE(FrameCamera(Box(), view, 10, 10).ok());
  view = {};
  view.fov_degrees = 0;
  EXPECT_FALSE(FrameCamera(Box(), view, 10, 10).ok());
  view = {};
  view.margin = 0.5;
  EXPECT_FALSE(FrameCamera(Box(), view, 10, 10).ok());
  EXPECT_FALSE(FrameCamera(Box(), ViewOptions{}, 0, 10).ok());
  BoundingBox bad = Box();
  bad.max.x = NAN;
  EXPECT_FALSE(FrameCamera(bad, ViewOptions{}, 10, 10).ok());
}

TEST(RenderNames, ParseImageSize) {
  auto size = ParseImageSize("960x360");
  ASSERT_TRUE(size.ok());
  EXPECT_EQ((*size)[0], 960);
  EXPECT_EQ((*size)[1], 360);
  for (const char* bad : {"", "960", "x360", "960x", "0x10", "10x0", "-5x5", "5x-5", "10x10x",
                          "16385x10", "ax b", "9 x9", "1e3x5", "99999999999x1"}) {
    auto r = ParseImageSize(bad);
    EXPECT_FALSE(r.ok()) << bad;
    if (!r.ok()) {
      EXPECT_NE(r.status().message().find("WxH"), std::string::npos);
    }
  }
}

TEST(RenderNames, ViewsAndProjections) {
  for (const char* name : {"front", "back", "left", "right", "top", "iso"}) {
    auto v = ParseView(name);
    ASSERT_TRUE(v.ok()) << name;
    EXPECT_EQ(ViewName(*v), name);
  }
  EXPECT_FALSE(ParseView("bottom").ok());
  EXPECT_EQ(*ParseProjection("ortho"), Projection::kOrthographic);
  EXPECT_EQ(*ParseProjection("perspective"), Projection::kPerspective);
  EXPECT_FALSE(ParseProjection("fisheye").ok());
}

}  // namespace
}  // namespace dispex
