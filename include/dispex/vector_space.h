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
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

enum class VectorSpace : std::uint8_t { kTangent, kParametric, kObject };
// "tangent", "parametric", "object".
std::string_view VectorSpaceName(VectorSpace space);
// The frame's definition in one line, as maps record it (dispex:frame).
std::string_view VectorSpaceFrame(VectorSpace space);
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
// VectorFromChannels at x.size() points: their frames as 3 floats per point in du, dv and
// normal, their channels as 3 per point in `channels` (or 3 in all: one value for every point,
// a constant face's), D's components into x, y and z.
void VectorsFromChannels(VectorSpace space, std::span<const float> du, std::span<const float> dv,
                         std::span<const float> normal, std::span<const float> channels,
                         std::span<float> x, std::span<float> y, std::span<float> z);

// ---- Scalar or vector: what a displacement map holds -----------------------------------------

// The meta data (strings) that make a 3-channel map a vector map: the space's name
// (VectorSpaceName) and the names of its channels (VectorSpaceChannels).
inline constexpr std::string_view kVectorSpaceMetaKey = "dispex:vector_space";
inline constexpr std::string_view kVectorChannelsMetaKey = "dispex:channels";

// What a displacement map holds, from its channel count, alpha channel and the values of its
// dispex:vector_space and dispex:channels meta data (nullptr when the map has no such item):
//  - 1 channel, without dispex:vector_space: a scalar map, displaced by h N (nullopt);
//  - 3 channels, no alpha, dispex:vector_space naming a space and dispex:channels, when present,
//    equal to VectorSpaceChannels of it: a vector map in that space.
// Anything else fails with one line that starts with `map` (the file's name): a 3-channel map
// without dispex:vector_space, any other channel count, an unknown space, mismatched channel
// names, an alpha channel, a 1-channel map that claims a vector space.
StatusOr<std::optional<VectorSpace>> DisplacementMapSpace(std::string_view map, int channels,
                                                          int alpha_channel,
                                                          const std::string* vector_space,
                                                          const std::string* channel_names);

}  // namespace dispex
