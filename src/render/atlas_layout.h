// Where the atlas puts each face's tile: tile sizes from the face resolutions, then shelf
// packing in face-id order, then the legend strip.
#pragma once

#include <vector>

#include "dispex/ptex.h"
#include "dispex/render.h"
#include "dispex/status.h"

namespace dispex::render {

// Legend geometry, in pixels.
struct LegendMetrics {
  int text_scale = 1;
  int height = 0;
  int min_width = 0;
};

// The layout of `map`'s tiles and legend for `options` (validated by the caller). range_min
// and range_max are left at 0. Fails when the image would exceed 2^27 pixels.
StatusOr<AtlasLayout> LayOutAtlas(const PtexFile& map, const AtlasOptions& options);

// Shown resolution of a face at a reduction: each side halved `reduction` times, at least 1.
inline int Reduced(int resolution, int reduction) {
  return resolution >> reduction > 0 ? resolution >> reduction : 1;
}

}  // namespace dispex::render
