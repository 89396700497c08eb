// The fields manifests share (ReadExtractManifest's shapes, ReadBatchManifest's assets):
// options by their ExtractOptions names, and file paths relative to the manifest's folder.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "dispex/extract.h"

namespace dispex::extract {

// The JSON object in the file at `path`; errors name the file ("cannot be read", "not valid
// JSON", "not a JSON object").
StatusOr<nlohmann::json> ReadJsonObject(const std::string& path);

// Sets each option of the JSON object `options` ({"tolerance": 0.001, ...}, values as the
// command line takes them) over `o`; errors begin with `where`.
Status SetOptions(ExtractOptions& o, const nlohmann::json& options, const std::string& where);

// entry[key], a non-empty string, as a path relative to `folder` (unless absolute).
StatusOr<std::string> PathIn(const nlohmann::json& entry, const char* key,
                             const std::filesystem::path& folder, const std::string& where);

}  // namespace dispex::extract
