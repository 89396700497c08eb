// ReadExtractManifest: an asset's shapes from several files, each with its own options.
#include <fmt/format.h>

#include <bit>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dispex/extract.h"
#include "extract/manifest_fields.h"

namespace dispex {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

StatusOr<int> IntValue(const json& v) {
  if (!v.is_number_integer()) return Status::Error(fmt::format("{} is not an integer", v.dump()));
  return v.get<int>();
}

StatusOr<double> NumberValue(const json& v) {
  if (!v.is_number()) return Status::Error(fmt::format("{} is not a number", v.dump()));
  return v.get<double>();
}

StatusOr<std::string> TextValue(const json& v) {
  if (!v.is_string()) return Status::Error(fmt::format("{} is not a string", v.dump()));
  return v.get<std::string>();
}

// A field set from a name ("nearest", "fill"...) by its Parse function.
template <class Field, class Parse>
Status SetNamed(Field& field, const json& v, Parse parse) {
  DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
  DISPEX_ASSIGN_OR_RETURN(field, parse(s));
  return Status::Ok();
}

// Sets one option by its ExtractOptions field name, from a value as the command line takes it.
Status SetOption(ExtractOptions& o, const std::string& name, const json& v) {
  auto text = [&]() { return v.is_string() ? v.get<std::string>() : v.dump(); };
  if (name == "oversample") {
    if (v == "auto") {
      o.oversample = 0;
      return Status::Ok();
    }
    DISPEX_ASSIGN_OR_RETURN(o.oversample, IntValue(v));
  } else if (name == "max_oversample") {
    DISPEX_ASSIGN_OR_RETURN(o.max_oversample, IntValue(v));
  } else if (name == "min_oversample") {
    DISPEX_ASSIGN_OR_RETURN(o.min_oversample, IntValue(v));
  } else if (name == "search_distance") {
    DISPEX_ASSIGN_OR_RETURN(o.search_distance, ParseSearchDistance(text()));
  } else if (name == "ray_policy") {
    return SetNamed(o.ray_policy, v, ParseHitPolicy);
  } else if (name == "tolerance") {
    DISPEX_ASSIGN_OR_RETURN(o.tolerance, NumberValue(v));
  } else if (name == "tolerance_fraction") {
    DISPEX_ASSIGN_OR_RETURN(o.tolerance_fraction, NumberValue(v));
  } else if (name == "resolution_rule") {
    return SetNamed(o.resolution_rule, v, ParseResolutionRule);
  } else if (name == "fixed_resolution") {
    DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
    unsigned w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(s.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
        !std::has_single_bit(w) || !std::has_single_bit(h)) {
      return Status::Error(fmt::format("'{}': WxH with powers of two, e.g. 64x64", s));
    }
    o.fixed_ulog2 = std::countr_zero(w);
    o.fixed_vlog2 = std::countr_zero(h);
  } else if (name == "nonzero_threshold") {
    DISPEX_ASSIGN_OR_RETURN(o.nonzero_threshold, NumberValue(v));
  } else if (name == "data_type") {
    DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
    if (s != "float" && s != "half") return Status::Error(fmt::format("'{}': float or half", s));
    o.data_type = s == "half" ? PtexDataType::kHalf : PtexDataType::kFloat;
  } else if (name == "compression_level") {
    DISPEX_ASSIGN_OR_RETURN(o.compression_level, IntValue(v));
  } else if (name == "holes") {
    return SetNamed(o.holes, v, ParseHolePolicy);
  } else if (name == "watertight") {
    return SetNamed(o.watertight, v, ParseWatertightEdges);
  } else if (name == "max_miss_fraction") {
    DISPEX_ASSIGN_OR_RETURN(o.max_miss_fraction, NumberValue(v));
  } else if (name == "bvh_quality") {
    return SetNamed(o.bvh_quality, v, ParseBuildQuality);
  } else if (name == "method") {
    return SetNamed(o.method, v, ParseExtractMethod);
  } else if (name == "uv_maps_dir") {
    DISPEX_ASSIGN_OR_RETURN(o.uv_maps_dir, TextValue(v));
  } else if (name == "uv_resolution") {
    DISPEX_ASSIGN_OR_RETURN(o.uv_resolution, IntValue(v));
  } else if (name == "uv_padding") {
    DISPEX_ASSIGN_OR_RETURN(o.uv_padding, IntValue(v));
  } else if (name == "max_memory") {
    if (v.is_number_unsigned()) {
      o.max_memory = v.get<std::uint64_t>();
    } else {
      DISPEX_ASSIGN_OR_RETURN(std::string size, TextValue(v));
      DISPEX_ASSIGN_OR_RETURN(o.max_memory, ParseByteSize(size));
    }
  } else if (name == "embree_isa") {
    DISPEX_ASSIGN_OR_RETURN(o.embree_isa, TextValue(v));
  } else if (name == "check_inputs") {
    if (!v.is_boolean()) return Status::Error(fmt::format("{} is not true or false", v.dump()));
    o.check_inputs = v.get<bool>();
  } else if (name == "vector") {
    if (v == "off") {
      o.vector.reset();
      return Status::Ok();
    }
    VectorSpace space{};
    DISPEX_RETURN_IF_ERROR(SetNamed(space, v, ParseVectorSpace));
    o.vector = space;
  } else {
    return Status::Error("unknown option (known: " + ExtractOptionNames() + ")");
  }
  return Status::Ok();
}

}  // namespace

namespace extract {

Status SetOptions(ExtractOptions& o, const json& options, const std::string& where) {
  if (!options.is_object()) return Status::Error(where + ": not an object");
  for (const auto& [name, value] : options.items()) {
    Status s = SetOption(o, name, value);
    if (!s.ok()) return s.WithPrefix(fmt::format("{}.{}", where, name));
  }
  return Status::Ok();
}

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

std::string ExtractOptionNames() {
  return "oversample, max_oversample, min_oversample, search_distance, ray_policy, tolerance, "
         "tolerance_fraction, resolution_rule, fixed_resolution, nonzero_threshold, data_type, "
         "compression_level, holes, watertight, max_miss_fraction, bvh_quality, method, vector, "
         "uv_maps_dir, uv_resolution, uv_padding, max_memory, embree_isa, check_inputs";
}

Status SetExtractOption(ExtractOptions& options, const std::string& name,
                        const std::string& json_value) {
  const json value = json::parse(json_value, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) return Status::Error(name + ": not a JSON value: " + json_value);
  return SetOption(options, name, value).WithPrefix(name);
}

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
