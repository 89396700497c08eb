// UV-space maps beside the Ptex map (ExtractOptions::uv_maps_dir, docs/UV_MAPS.md): every texel
// centre of the UDIM tiles the base's UVs touch, placed on the limit surface through the UVs'
// linear face-varying interpolation, extracted there with the Ptex map's rays and settings, or,
// for an object-space vector map, read through the sculpt's correspondence (D = sculpt - limit).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"

namespace dispex::extract {

// What an incremental run may take from the tiles the run before wrote: the inputs key of the
// map they were written with, and per Ptex face whether its key is the same as then. Tiles of
// that key, resolution and channels give those faces' texels, unless their rays missed then
// or the tiles are half floats (whose rounding dilation would read).
struct UvPrevious {
  std::string inputs_key;
  std::vector<std::uint8_t> same_key;
};

// Whether the tiles in uv_maps_dir were written with the map of `inputs_key` at this resolution
// (an incremental run whose map is up to date is then done).
bool UvTilesCurrent(const ExtractOptions& options, const std::string& inputs_key);

// Writes uv_maps_dir/<shape>.<UDIM>.exr for every tile and removes tiles of the same shape a
// previous run left there that this one did not write. Builds the whole sculpt's tracer when
// the run's tracer holds only part of it (scalar maps traced by rays). Interpolated
// (ExtractSettings::interpolate) each texel is the sculpt's vertex displacements interpolated
// where it lies, as in the Ptex map. A vector map (ExtractOptions::vector, object space)
// reads the correspondence its Ptex map was read through. Fills the report's
// uv_* fields and warnings.
// With `previous`, the texels of faces whose key is unchanged are copied from the previous
// tiles (the result is the same tiles).
Status WriteUvMaps(const ExtractOptions& options, ExtractInputs& inputs,
                   const ExtractSettings& settings, const UvPrevious* previous,
                   ExtractReport& report);

}  // namespace dispex::extract
