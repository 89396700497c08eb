// UV-space maps beside the Ptex map (ExtractOptions::uv_maps_dir, docs/UV_MAPS.md): every texel
// centre of the UDIM tiles the base's UVs touch, placed on the limit surface through the UVs'
// linear face-varying interpolation, extracted there with the Ptex map's rays and settings, or,
// for an object-space vector map, read through the sculpt's correspondence (D = sculpt - limit).
#pragma once

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"

namespace dispex::extract {

// Writes uv_maps_dir/<shape>.<UDIM>.exr for every tile and removes tiles of the same shape a
// previous run left there that this one did not write. Builds the whole sculpt's tracer when
// the run's tracer holds only part of it (scalar maps traced by rays). Interpolated
// (ExtractSettings::interpolate) each texel is the sculpt's vertex displacements interpolated
// where it lies, as in the Ptex map. A vector map (ExtractOptions::vector, object space)
// reads the correspondence its Ptex map was read through. Fills the report's
// uv_* fields and warnings.
Status WriteUvMaps(const ExtractOptions& options, ExtractInputs& inputs,
                   const ExtractSettings& settings, ExtractReport& report);

}  // namespace dispex::extract
