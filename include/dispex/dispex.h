// dispex's front door: what a studio program calls to make, merge, check and read displacement
// maps, in one include. Extract (one shape), ExtractAsset (every shape of an asset, or a
// manifest), MergeShards (a farm's parts) and their ExtractReport (dispex/extract.h); Verify and
// MakeSculpt (dispex/verify.h); the maps read back: Ptex (dispex/ptex.h) and UDIM tiles
// (dispex/uv_map.h); Status and its StatusCode (dispex/status.h); cancellation and progress
// (dispex/cancel.h, dispex/progress.h); atomic outputs (dispex/files.h); the version.
//
// The other headers of include/dispex are public on purpose too, one per module, for programs
// built on one stage (a mesh reader, the limit surface, the tracer, the spectral analysis, the
// Ptex sampler, pictures, review pages): docs/LIBRARY.md lists them. Everything under src/ is
// internal.
#pragma once

#include "dispex/cancel.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/progress.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "dispex/uv_map.h"
#include "dispex/verify.h"
#include "dispex/version.h"
