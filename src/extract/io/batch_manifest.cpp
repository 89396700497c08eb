// ReadBatchManifest: the assets a batch or a farm job extracts, one map each.
#include <fmt/format.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "dispex/extract.h"
#include "extract/io/manifest_fields.h"

namespace dispex {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Names become file names and words of job scripts.
bool SafeName(const std::string& name) {
  if (name.empty() || name.size() > 200 || name[0] == '.' || name[0] == '-') return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') {
      return false;
    }
  }
  return true;
}

Status OnlyKeys(const json& object, std::initializer_list<const char*> known,
                const std::string& where) {
  for (const auto& [key, value] : object.items()) {
    bool ok = false;
    std::string list;
    for (const char* k : known) {
      ok = ok || key == k;
      list += (list.empty() ? "" : ", ") + std::string(k);
    }
    if (!ok)
      return Status::Error(fmt::format("{}: unknown key \"{}\" (known: {})", where, key, list));
  }
  return Status::Ok();
}

}  // namespace

StatusOr<std::vector<BatchAsset>> ReadBatchManifest(const std::string& path,
                                                    const ExtractOptions& defaults) {
  DISPEX_ASSIGN_OR_RETURN(const json manifest, extract::ReadJsonObject(path));
  DISPEX_RETURN_IF_ERROR(OnlyKeys(manifest, {"options", "assets"}, path));
  const fs::path folder = fs::path(path).parent_path();
  ExtractOptions common = defaults;
  if (manifest.contains("options")) {
    DISPEX_RETURN_IF_ERROR(extract::SetOptions(common, manifest["options"], path + ": options"));
  }
  if (!manifest.contains("assets") || !manifest["assets"].is_array() ||
      manifest["assets"].empty()) {
    return Status::Error(fmt::format("{}: \"assets\" must be a non-empty list", path));
  }
  std::vector<BatchAsset> out;
  for (std::size_t i = 0; i < manifest["assets"].size(); ++i) {
    const json& entry = manifest["assets"][i];
    const std::string where = fmt::format("{}: assets[{}]", path, i);
    if (!entry.is_object()) return Status::Error(where + ": not an object");
    DISPEX_RETURN_IF_ERROR(
        OnlyKeys(entry, {"name", "base", "sculpt", "output_dir", "options"}, where));
    BatchAsset asset;
    if (!entry.contains("name") || !entry["name"].is_string() ||
        !SafeName(entry["name"].get<std::string>())) {
      return Status::Error(where +
                           ": \"name\" must be letters, digits, '_', '-' or '.' (not first)");
    }
    asset.name = entry["name"].get<std::string>();
    for (const BatchAsset& other : out) {
      if (other.name == asset.name) {
        return Status::Error(fmt::format("{}: asset '{}' is named twice", where, asset.name));
      }
    }
    asset.options = common;
    if (entry.contains("options")) {
      DISPEX_RETURN_IF_ERROR(
          extract::SetOptions(asset.options, entry["options"], where + ".options"));
    }
    DISPEX_ASSIGN_OR_RETURN(asset.options.base_path, extract::PathIn(entry, "base", folder, where));
    DISPEX_ASSIGN_OR_RETURN(asset.options.sculpt_path,
                            extract::PathIn(entry, "sculpt", folder, where));
    DISPEX_ASSIGN_OR_RETURN(const std::string output_dir,
                            extract::PathIn(entry, "output_dir", folder, where));
    asset.options.output_path = (fs::path(output_dir) / (asset.name + ".ptx")).string();
    // A manifest's folders, like its files, are relative to the manifest.
    if (!asset.options.uv_maps_dir.empty() && fs::path(asset.options.uv_maps_dir).is_relative()) {
      asset.options.uv_maps_dir = (folder / asset.options.uv_maps_dir).lexically_normal().string();
    }
    Status valid = ValidateExtractOptions(asset.options);
    if (!valid.ok()) return valid.WithPrefix(where);
    out.push_back(std::move(asset));
  }
  return out;
}

}  // namespace dispex
