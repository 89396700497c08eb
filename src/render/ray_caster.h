// Ray-casting one panel: camera rays through a Tracer into a ShadedMesh, clay shading.
#pragma once

#include <array>
#include <cstdint>

#include "dispex/render.h"
#include "dispex/trace.h"
#include "render/tessellation.h"

namespace dispex::render {

struct ShadingOptions {
  int supersample = 2;     // s x s rays per pixel on a fixed grid
  int ao_samples = 0;      // ambient occlusion rays per camera hit (0: off)
  float ao_distance = 0;   // their length, object units
  std::uint32_t seed = 1;  // of the AO directions (a fixed sequence per pixel)
};

inline constexpr std::array<std::uint8_t, 3> kPanelBackground = {44, 48, 56};

// Renders `mesh` (whose triangles `tracer` was built on, prim i = triangle i) as seen by
// `camera` into a camera.width x camera.height image: per hit, the normal interpolated from
// the vertex normals of the hit triangle (flipped towards the viewer on back faces, which get
// a cooler tint), lit by a headlight, a key light from the upper left and a fill light from
// the right (all fixed to the camera), a little Blinn specular from the key, and optionally
// ambient occlusion. Rows run in parallel; the result does not depend on the thread count.
// Fails when the tracer reports an error.
StatusOr<Image> CastPanel(const ShadedMesh& mesh, const Tracer& tracer, const Camera& camera,
                          const ShadingOptions& options);

}  // namespace dispex::render
