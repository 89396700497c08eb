// Vector displacement frames: channel names and the conversions in both directions, in double.
#include "dispex/vector_space.h"

#include <fmt/format.h>

#include <cmath>

#include "core/enum_names.h"
#include "core/vec3.h"

namespace dispex {
namespace {

constexpr auto kSpaces = EnumTable<VectorSpace>({
    {VectorSpace::kTangent, "tangent"},
    {VectorSpace::kParametric, "parametric"},
    {VectorSpace::kObject, "object"},
});

// T = normalize(dP/du); where dP/du vanishes or is parallel to N, any unit vector orthogonal
// to N (the axis least aligned with it, projected).
Vec3d TangentAxis(const Vec3d& du, const Vec3d& n) {
  const Vec3d t = du - n * Dot(du, n);
  const double len = std::sqrt(Dot(t, t));
  if (len > 1e-30 * (1 + std::sqrt(Dot(du, du))) && std::isfinite(len)) return t * (1 / len);
  const Vec3d axis = std::fabs(n.x) < 0.6   ? Vec3d{1, 0, 0}
                     : std::fabs(n.y) < 0.6 ? Vec3d{0, 1, 0}
                                            : Vec3d{0, 0, 1};
  return Normalize(axis - n * Dot(axis, n));
}

}  // namespace

std::string_view VectorSpaceName(VectorSpace space) {
  return EnumName(kSpaces, space);
}

StatusOr<VectorSpace> ParseVectorSpace(std::string_view name) {
  return ParseEnum(kSpaces, "vector space", name);
}

std::string_view VectorSpaceFrame(VectorSpace space) {
  switch (space) {
    case VectorSpace::kTangent:
      return "D = c0 T + c1 B + c2 N; T = normalize(dP/du), N = the unit limit normal "
             "normalize(dP/du x dP/dv), B = N x T; P the Catmull-Clark limit surface, (u, v) "
             "the Ptex face's own coordinates in [0, 1]";
    case VectorSpace::kParametric:
      return "D = c0 dP/du + c1 dP/dv + c2 N; N = the unit limit normal normalize(dP/du x "
             "dP/dv); P the Catmull-Clark limit surface, (u, v) the Ptex face's own "
             "coordinates in [0, 1]";
    case VectorSpace::kObject:
      break;
  }
  return "D = (c0, c1, c2) in the base mesh's object space";
}

std::string_view VectorSpaceChannels(VectorSpace space) {
  switch (space) {
    case VectorSpace::kTangent:
      return "T,B,N";
    case VectorSpace::kParametric:
      return "a,b,n";
    case VectorSpace::kObject:
      break;
  }
  return "x,y,z";
}

Float3 VectorFromChannels(VectorSpace space, const SurfaceFrame& frame, const float c[3]) {
  const Vec3d n = ToVec3d(frame.normal);
  Vec3d d;
  switch (space) {
    case VectorSpace::kTangent: {
      const Vec3d t = TangentAxis(ToVec3d(frame.du), n);
      d = t * c[0] + Cross(n, t) * c[1] + n * c[2];
      break;
    }
    case VectorSpace::kParametric:
      d = ToVec3d(frame.du) * c[0] + ToVec3d(frame.dv) * c[1] + n * c[2];
      break;
    case VectorSpace::kObject:
      d = {c[0], c[1], c[2]};
      break;
  }
  return FromVec3d<Float3>(d);
}

void VectorsFromChannels(VectorSpace space, std::span<const float> du, std::span<const float> dv,
                         std::span<const float> normal, std::span<const float> channels,
                         std::span<float> x, std::span<float> y, std::span<float> z) {
  const bool constant = channels.size() == 3;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t k = 3 * i;
    const SurfaceFrame frame{{du[k], du[k + 1], du[k + 2]},
                             {dv[k], dv[k + 1], dv[k + 2]},
                             {normal[k], normal[k + 1], normal[k + 2]}};
    const Float3 d = VectorFromChannels(space, frame, &channels[constant ? 0 : k]);
    x[i] = d.x;
    y[i] = d.y;
    z[i] = d.z;
  }
}

void VectorToChannels(VectorSpace space, const SurfaceFrame& frame, const Float3& d_in,
                      float c[3]) {
  const Vec3d d = ToVec3d(d_in), n = ToVec3d(frame.normal);
  switch (space) {
    case VectorSpace::kTangent: {
      const Vec3d t = TangentAxis(ToVec3d(frame.du), n);
      c[0] = static_cast<float>(Dot(d, t));
      c[1] = static_cast<float>(Dot(d, Cross(n, t)));
      c[2] = static_cast<float>(Dot(d, n));
      return;
    }
    case VectorSpace::kParametric: {
      // Solve d = a du + b dv + c n: n is orthogonal to du and dv (it is their normalised
      // cross product), so c = d.n and (a, b) solve the 2x2 normal equations of the rest.
      const Vec3d du = ToVec3d(frame.du), dv = ToVec3d(frame.dv);
      const double dn = Dot(d, n);
      const Vec3d r = d - n * dn;
      const double g11 = Dot(du, du), g12 = Dot(du, dv), g22 = Dot(dv, dv);
      const double r1 = Dot(r, du), r2 = Dot(r, dv);
      const double det = g11 * g22 - g12 * g12;
      const bool ok = det > 1e-24 * g11 * g22 && std::isfinite(det);
      c[0] = ok ? static_cast<float>((r1 * g22 - r2 * g12) / det) : 0.0f;
      c[1] = ok ? static_cast<float>((r2 * g11 - r1 * g12) / det) : 0.0f;
      c[2] = static_cast<float>(dn);
      return;
    }
    case VectorSpace::kObject:
      c[0] = d_in.x;
      c[1] = d_in.y;
      c[2] = d_in.z;
      return;
  }
}

StatusOr<std::optional<VectorSpace>> DisplacementMapSpace(std::string_view map, int channels,
                                                          int alpha_channel,
                                                          const std::string* vector_space,
                                                          const std::string* channel_names) {
  if (channels == 1) {
    if (vector_space != nullptr) {
      return Status::Error(fmt::format("{}: 1 channel, but {} '{}' (a vector map has 3 channels)",
                                       map, kVectorSpaceMetaKey, *vector_space));
    }
    return std::optional<VectorSpace>();
  }
  if (channels != 3) {
    return Status::Error(
        fmt::format("{}: {} channels: a displacement map has 1 (scalar) or 3 (vector, with {})",
                    map, channels, kVectorSpaceMetaKey));
  }
  if (vector_space == nullptr) {
    return Status::Error(
        fmt::format("{}: 3 channels but no {} meta data: not a vector displacement map", map,
                    kVectorSpaceMetaKey));
  }
  StatusOr<VectorSpace> space = ParseVectorSpace(*vector_space);
  if (!space.ok())
    return space.status().WithPrefix(fmt::format("{}: {}", map, kVectorSpaceMetaKey));
  if (channel_names != nullptr && *channel_names != VectorSpaceChannels(*space)) {
    return Status::Error(fmt::format("{}: {} '{}' does not match {} '{}' (expected '{}')", map,
                                     kVectorChannelsMetaKey, *channel_names, kVectorSpaceMetaKey,
                                     *vector_space, VectorSpaceChannels(*space)));
  }
  if (alpha_channel != -1) {
    return Status::Error(fmt::format("{}: alpha channel {}: a vector displacement map has none",
                                     map, alpha_channel));
  }
  return std::optional<VectorSpace>(*space);
}

}  // namespace dispex
