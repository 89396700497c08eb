// What an extraction records about itself: in the Ptex file's meta data (only what is
// deterministic, so the file's bytes depend on inputs and options alone) and in the JSON
// report (everything, timings included).
#pragma once

#include <nlohmann/json.hpp>

#include "core/hash128.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "extract/face_pipeline.h"

namespace dispex::extract {

// Every option that affects the output (not threads, progress or paths).
nlohmann::json ExtractOptionsJson(const ExtractOptions& options);
// The options ExtractOptionsJson wrote (paths, threads and the like left at their defaults).
StatusOr<ExtractOptions> ExtractOptionsFromJson(const nlohmann::json& json);
// The JSON report of one map (ExtractReportJson, and each shape of AssetReportJson).
nlohmann::json ExtractReportObject(const ExtractReport& report);
// Resolved settings and statistics that do not depend on timing or thread count.
nlohmann::json ExtractStatisticsJson(const ExtractReport& report);

// Adds the standard mesh meta data (PtexFaceVertCounts, ...) and dispex's own keys:
// dispex:version, dispex:shape (when part of an asset), dispex:base, dispex:base_fingerprint,
// dispex:sculpt, dispex:sculpt_fingerprint, dispex:options (JSON), dispex:statistics (JSON),
// dispex:tolerance, dispex:search_distance, dispex:discontinuous_faces (int32 Ptex face
// ids whose data may jump at their edges; when there are any), and what an incremental
// extraction re-uses: dispex:inputs_key, dispex:face_keys (16 bytes per face) and
// dispex:face_records_v1 (each face's first pass; a vector map's dispex:vector_face_records_v1,
// then its dispex:vector_space, channel names and frame) and, when the edges were made
// watertight, dispex:first_round_edge_steps (`first_round_edge_steps`: 8 doubles per face) --
// these only when `face_keys` is not empty.
Status AddExtractMetaData(PtexWriter& writer, const Mesh& base, const ExtractReport& report,
                          std::span<const Hash128> face_keys, std::span<const FaceStats> first_pass,
                          std::span<const EdgeMeans> edge_means,
                          std::span<const double> first_round_edge_steps);

// The key of everything the map is made from: version, options, both meshes' content and the
// names the meta data records.
Hash128 InputsKey(const ExtractReport& report);

}  // namespace dispex::extract
