// ReadExtractManifest: an asset's shapes from several files, each with its own options.
#include <fmt/format.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dispex/extract.h"
#include "extract/io/manifest_fields.h"

namespace dispex {

namespace fs = std::filesystem;
using nlohmann::json;

namespace extract {

StatusOr<std::string> PathIn(const json& entry, const char* key, const fs::path& folder,
                             const std::string& where) {
  if (!entry.contains(key) || !entry[key].is_string() || entry[key].get<std::string>().empty()) {
    return Status::Error(fmt::format("{}: no \"{}\" file", where, key));
  }
  const fs::path p(entry[key].get<std::string>());
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

StatusOr<json> ReadJsonObject(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(fmt::format("{}: cannot be read", path));
  std::stringstream text;
  text << in.rdbuf();
  json value = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) return Status::Error(fmt::format("{}: not valid JSON", path));
  if (!value.is_object()) return Status::Error(fmt::format("{}: not a JSON object", path));
  return value;
}

}  // namespace extract

using extract::PathIn;
using extract::SetOptions;

StatusOr<ExtractAssetOptions> ReadExtractManifest(const std::string& path,
                                                  const ExtractAssetOptions& defaults) {
  DISPEX_ASSIGN_OR_RETURN(const json manifest, extract::ReadJsonObject(path));
  const fs::path folder = fs::path(path).parent_path();
  ExtractAssetOptions out = defaults;
  out.manifest.clear();
  for (const auto& [key, value] : manifest.items()) {
    if (key != "output_dir" && key != "options" && key != "shapes") {
      return Status::Error(
          fmt::format("{}: unknown key \"{}\" (known: output_dir, options, shapes)", path, key));
    }
  }
  if (manifest.contains("output_dir") && out.output_dir.empty()) {
    if (!manifest["output_dir"].is_string()) {
      return Status::Error(fmt::format("{}: output_dir is not a string", path));
    }
    const fs::path dir(manifest["output_dir"].get<std::string>());
    out.output_dir = (dir.is_absolute() ? dir : folder / dir).lexically_normal().string();
  }
  if (manifest.contains("options")) {
    DISPEX_RETURN_IF_ERROR(SetOptions(out.options, manifest["options"], path + ": options"));
  }
  if (!manifest.contains("shapes") || !manifest["shapes"].is_array() ||
      manifest["shapes"].empty()) {
    return Status::Error(fmt::format("{}: \"shapes\" must be a non-empty list", path));
  }
  for (std::size_t i = 0; i < manifest["shapes"].size(); ++i) {
    const json& entry = manifest["shapes"][i];
    const std::string where = fmt::format("{}: shapes[{}]", path, i);
    if (!entry.is_object()) return Status::Error(where + ": not an object");
    for (const auto& [key, value] : entry.items()) {
      if (key != "name" && key != "base" && key != "sculpt" && key != "options") {
        return Status::Error(
            fmt::format("{}: unknown key \"{}\" (known: name, base, sculpt, options)", where, key));
      }
    }
    AssetShapeSpec spec;
    if (!entry.contains("name") || !entry["name"].is_string()) {
      return Status::Error(where + ": no \"name\"");
    }
    spec.name = entry["name"].get<std::string>();
    DISPEX_ASSIGN_OR_RETURN(spec.base_path, PathIn(entry, "base", folder, where));
    DISPEX_ASSIGN_OR_RETURN(spec.sculpt_path, PathIn(entry, "sculpt", folder, where));
    spec.options = out.options;
    if (entry.contains("options")) {
      DISPEX_RETURN_IF_ERROR(SetOptions(spec.options, entry["options"], where + ".options"));
    }
    for (const AssetShapeSpec& other : out.manifest) {
      if (other.name == spec.name) {
        return Status::Error(fmt::format("{}: shape '{}' is named twice", where, spec.name));
      }
    }
    out.manifest.push_back(std::move(spec));
  }
  return out;
}

}  // namespace dispex
