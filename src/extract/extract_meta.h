// What an extraction records about itself: in the Ptex file's meta data (only what is
// deterministic, so the file's bytes depend on inputs and options alone) and in the JSON
// report (everything, timings included).
#pragma once

#include <nlohmann/json.hpp>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"

namespace dispex::extract {

// Every option that affects the output (not threads, progress or paths).
nlohmann::json ExtractOptionsJson(const ExtractOptions& options);
// Resolved settings and statistics that do not depend on timing or thread count.
nlohmann::json ExtractStatisticsJson(const ExtractReport& report);

// Adds the standard mesh meta data (PtexFaceVertCounts, ...) and dispex's own keys:
// dispex:version, dispex:base, dispex:base_fingerprint, dispex:sculpt,
// dispex:sculpt_fingerprint, dispex:options (JSON), dispex:statistics (JSON),
// dispex:tolerance, dispex:search_distance, and dispex:discontinuous_faces (int32 Ptex face
// ids whose data may jump at their edges; when there are any).
Status AddExtractMetaData(PtexWriter& writer, const Mesh& base, const ExtractReport& report);

}  // namespace dispex::extract
