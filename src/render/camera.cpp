// Views and framing: a look-at camera on a sphere of directions around the box (azimuth about
// +y, elevation towards +y), moved back (perspective) or zoomed (orthographic) until the
// eight corners of the box fit in the image less the margin.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/vec3.h"
#include "dispex/render.h"

namespace dispex {

namespace {

void PresetAngles(ViewPreset preset, double& azimuth, double& elevation) {
  switch (preset) {
    case ViewPreset::kFront:
      azimuth = 0, elevation = 0;
      return;
    case ViewPreset::kBack:
      azimuth = 180, elevation = 0;
      return;
    case ViewPreset::kRight:
      azimuth = 90, elevation = 0;
      return;
    case ViewPreset::kLeft:
      azimuth = -90, elevation = 0;
      return;
    case ViewPreset::kTop:
      azimuth = 0, elevation = 90;
      return;
    case ViewPreset::kIso:
      azimuth = 45;
      elevation = std::atan(1.0 / std::sqrt(2.0)) * 180.0 / std::numbers::pi;
      return;
  }
}

// The view's azimuth and elevation in degrees (the preset's unless given), after checking
// them, the image size, the field of view and the margin.
Status CheckView(const ViewOptions& view, int width, int height, double& azimuth,
                 double& elevation) {
  if (width < 1 || height < 1) {
    return Status::Error(fmt::format("image size {}x{}: both sides must be >= 1", width, height));
  }
  PresetAngles(view.preset, azimuth, elevation);
  if (!std::isnan(view.azimuth)) azimuth = view.azimuth;
  if (!std::isnan(view.elevation)) elevation = view.elevation;
  if (!std::isfinite(azimuth)) return Status::Error("azimuth: must be a finite angle");
  if (!(elevation >= -90 && elevation <= 90)) {
    return Status::Error(
        fmt::format("elevation = {}: must be within [-90, 90] degrees", elevation));
  }
  if (!(view.fov_degrees >= 1 && view.fov_degrees <= 120)) {
    return Status::Error(fmt::format("fov_degrees = {}: must be 1..120 degrees", view.fov_degrees));
  }
  if (!(view.margin >= 0 && view.margin <= 0.45)) {
    return Status::Error(fmt::format("margin {}: must be 0..0.45", view.margin));
  }
  return Status::Ok();
}

// The box [lo, hi] of the (non-empty) points, which must all be finite.
Status BoundsOf(std::span<const Float3> points, Vec3d& lo, Vec3d& hi) {
  lo = ToVec3d(points[0]);
  hi = lo;
  for (const Float3& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return Status::Error("cannot frame a point that is not finite");
    }
    lo = {std::min(lo.x, double(p.x)), std::min(lo.y, double(p.y)), std::min(lo.z, double(p.z))};
    hi = {std::max(hi.x, double(p.x)), std::max(hi.y, double(p.y)), std::max(hi.z, double(p.z))};
  }
  return Status::Ok();
}

// The extent of the points seen from a distance, as [min, max] along right and up.
struct Extent {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  double half(double asp) const { return std::max((x1 - x0) / (2 * asp), (y1 - y0) / 2); }
};

// The camera's axes for the view's angles, looking at the centre of the points' box.
struct Framing {
  Framing(std::span<const Float3> framed, const Vec3d& lo, const Vec3d& hi, double azimuth,
          double elevation, double image_aspect, double usable_fraction)
      : points(framed),
        a(azimuth * std::numbers::pi / 180.0),
        e(elevation * std::numbers::pi / 180.0),
        towards_eye{std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)},
        right{std::cos(a), 0.0, -std::sin(a)},
        up(Cross(towards_eye, right)),
        centre((lo + hi) * 0.5),
        radius(std::max(0.5 * std::sqrt(Dot(hi - lo, hi - lo)), 1e-30)),
        aspect(image_aspect),
        usable(usable_fraction) {}

  // The extent seen from `distance` (perspective: x / depth), or without perspective when
  // distance is 0 (orthographic: x).
  Extent ExtentAt(double distance) const {
    Extent ext;
    for (const Float3& p : points) {
      const Vec3d rel = ToVec3d(p) - centre;
      double x = Dot(rel, right), y = Dot(rel, up);
      if (distance > 0) {
        const double depth = distance - Dot(rel, towards_eye);
        x /= depth;
        y /= depth;
      }
      ext.x0 = std::min(ext.x0, x), ext.x1 = std::max(ext.x1, x);
      ext.y0 = std::min(ext.y0, y), ext.y1 = std::max(ext.y1, y);
    }
    return ext;
  }

  std::span<const Float3> points;
  double a, e;  // azimuth and elevation, radians
  Vec3d towards_eye, right, up, centre;
  double radius;  // half the box's diagonal
  double aspect;  // image width / height
  double usable;  // the image's fraction inside the margins
};

// Orthographic: zoomed until the points fit; the eye outside the box. Returns their extent.
Extent FrameOrthographic(const Framing& f, Camera& camera) {
  const Extent ext = f.ExtentAt(0);
  camera.half_height = std::max(ext.half(f.aspect) / f.usable, 1e-9 * f.radius);
  camera.eye = FromVec3d<Float3>(f.centre + f.towards_eye * (2.0 * f.radius));
  return ext;
}

// Perspective: far enough that the points fit even around the centre; then the nearest
// distance at which their (shifted) extent still fits, by bisection. Returns their extent
// from there.
Extent FramePerspective(const Framing& f, double fov_degrees, Camera& camera) {
  const double tan_half = std::tan(0.5 * fov_degrees * std::numbers::pi / 180.0);
  const double target = tan_half * f.usable;
  double max_depth_offset = -f.radius, far = 0;
  for (const Float3& p : f.points) {
    const Vec3d rel = ToVec3d(p) - f.centre;
    const double z = Dot(rel, f.towards_eye);
    max_depth_offset = std::max(max_depth_offset, z);
    far = std::max({far, z + std::fabs(Dot(rel, f.up)) / target,
                    z + std::fabs(Dot(rel, f.right)) / (target * f.aspect)});
  }
  double near = max_depth_offset + 1e-3 * f.radius;
  far = std::max(far, near);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (near + far);
    if (f.ExtentAt(mid).half(f.aspect) <= target) {
      far = mid;
    } else {
      near = mid;
    }
  }
  camera.half_height = tan_half;
  camera.eye = FromVec3d<Float3>(f.centre + f.towards_eye * far);
  return f.ExtentAt(far);
}

}  // namespace

void Camera::RayThrough(double px, double py, Float3& origin, Float3& direction) const {
  const double aspect = double(width) / double(height);
  const double sx = (2.0 * px / width - 1.0) * aspect * half_height + shift_x;
  const double sy = (1.0 - 2.0 * py / height) * half_height + shift_y;
  const Vec3d e = ToVec3d(eye), f = ToVec3d(forward), r = ToVec3d(right), u = ToVec3d(up);
  if (projection == Projection::kOrthographic) {
    origin = FromVec3d<Float3>(e + r * sx + u * sy);
    direction = forward;
  } else {
    origin = eye;
    direction = FromVec3d<Float3>(Normalize(f + r * sx + u * sy));
  }
}

bool Camera::Project(const Float3& point, double& px, double& py) const {
  const double aspect = double(width) / double(height);
  const Vec3d rel = ToVec3d(point) - ToVec3d(eye);
  double x = Dot(rel, ToVec3d(right)), y = Dot(rel, ToVec3d(up));
  if (projection == Projection::kPerspective) {
    const double z = Dot(rel, ToVec3d(forward));
    if (!(z > 0)) return false;
    x /= z;
    y /= z;
  }
  px = ((x - shift_x) / (half_height * aspect) + 1.0) * 0.5 * width;
  py = (1.0 - (y - shift_y) / half_height) * 0.5 * height;
  return true;
}

StatusOr<Camera> FrameCamera(std::span<const Float3> points, const ViewOptions& view, int width,
                             int height) {
  double azimuth = 0, elevation = 0;
  DISPEX_RETURN_IF_ERROR(CheckView(view, width, height, azimuth, elevation));
  if (points.empty()) return Status::Error("nothing to frame: no points");
  Vec3d lo, hi;
  DISPEX_RETURN_IF_ERROR(BoundsOf(points, lo, hi));
  const Framing framing(points, lo, hi, azimuth, elevation, double(width) / double(height),
                        1.0 - 2.0 * view.margin);

  Camera camera;
  camera.projection = view.projection;
  camera.width = width;
  camera.height = height;
  camera.forward = FromVec3d<Float3>(framing.towards_eye * -1.0);
  camera.right = FromVec3d<Float3>(framing.right);
  camera.up = FromVec3d<Float3>(framing.up);
  const Extent ext = view.projection == Projection::kOrthographic
                         ? FrameOrthographic(framing, camera)
                         : FramePerspective(framing, view.fov_degrees, camera);
  camera.shift_x = 0.5 * (ext.x0 + ext.x1);
  camera.shift_y = 0.5 * (ext.y0 + ext.y1);
  return camera;
}

StatusOr<Camera> FrameCamera(const BoundingBox& box, const ViewOptions& view, int width,
                             int height) {
  std::array<Float3, 8> corners;
  for (int c = 0; c < 8; ++c) {
    corners[static_cast<std::size_t>(c)] = {c & 1 ? box.max.x : box.min.x,
                                            c & 2 ? box.max.y : box.min.y,
                                            c & 4 ? box.max.z : box.min.z};
  }
  return FrameCamera(corners, view, width, height);
}

}  // namespace dispex
