// The frames of vector displacement maps: how a map's three channels c = (c0, c1, c2) at a
// point of the limit surface give the object-space displacement D there, with P the limit
// point, dP/du and dP/dv its derivatives in the Ptex face's own (u, v) and N its unit normal
// (LimitEvaluator::EvaluateGridFrames):
//   tangent:     D = c0 T + c1 B + c2 N,  T = normalize(dP/du), B = N x T  (channels T, B, N)
//   parametric:  D = c0 dP/du + c1 dP/dv + c2 N                          (channels a, b, n)
//   object:      D = (c0, c1, c2)                                          (channels x, y, z)
// The displaced surface is P + D. Tangent and parametric maps turn with the face's (u, v)
// from face to face, so they are written with Ptex's tangent-vector edge filter mode.
#pragma once

#include <cstdint>
#include <string_view>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

enum class VectorSpace : std::uint8_t { kTangent, kParametric, kObject };
// "tangent", "parametric", "object".
std::string_view VectorSpaceName(VectorSpace space);
StatusOr<VectorSpace> ParseVectorSpace(std::string_view name);
// The channel names in order, comma-separated: "T,B,N", "a,b,n", "x,y,z".
std::string_view VectorSpaceChannels(VectorSpace space);

// The frame at one point of the limit surface.
struct SurfaceFrame {
  Float3 du, dv, normal;
};

// D from the channels, and the channels from D (the inverse: exact up to rounding where
// dP/du and dP/dv are independent; with degenerate derivatives the parametric channels of D's
// tangential part are 0 and a tangent frame falls back to any unit vector orthogonal to N).
Float3 VectorFromChannels(VectorSpace space, const SurfaceFrame& frame, const float c[3]);
void VectorToChannels(VectorSpace space, const SurfaceFrame& frame, const Float3& d, float c[3]);

}  // namespace dispex
