// The extract options set by name, each declared once: its field name (manifests, the Python
// module's keyword arguments, the library's messages), its command-line flag, the kind of
// value it takes, what it takes in words, and how a value as a manifest gives it (JSON) is
// parsed into ExtractOptions. SetExtractOption, manifests (manifest_fields.h), the Python
// module and the command line's messages all read this table.
#include <fmt/format.h>

#include <bit>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "extract/io/extract_meta.h"
#include "extract/io/manifest_fields.h"

namespace dispex {

namespace {

using nlohmann::json;

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

StatusOr<bool> BoolValue(const json& v) {
  if (!v.is_boolean()) return Status::Error(fmt::format("{} is not true or false", v.dump()));
  return v.get<bool>();
}

// A field set from a name ("nearest", "fill"...) by its Parse function.
template <class Field, class Parse>
Status SetNamed(Field& field, const json& v, Parse parse) {
  DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
  DISPEX_ASSIGN_OR_RETURN(field, parse(s));
  return Status::Ok();
}

using Setter = Status (*)(ExtractOptions&, const json&);
// Adds the option to the options a map records (dispex:options, its inputs key).
using Recorder = void (*)(const ExtractOptions&, json&);

struct Entry {
  ExtractOptionSpec spec;
  Setter set;
  // Null: not an option of the map (threads, paths of other outputs, memory, checks).
  Recorder record = nullptr;
  // Reads what `record` wrote back; null: `set` reads it.
  Setter restore = nullptr;
};

#define DISPEX_SETTER(...) [](ExtractOptions & o, const json& v) -> Status __VA_ARGS__
#define DISPEX_RECORD(...) [](const ExtractOptions& o, json& j) __VA_ARGS__

std::string_view SearchKindName(SearchDistanceSpec::Kind kind) {
  switch (kind) {
    case SearchDistanceSpec::Kind::kAuto:
      return "auto";
    case SearchDistanceSpec::Kind::kAbsolute:
      return "absolute";
    case SearchDistanceSpec::Kind::kRelative:
      return "relative";
  }
  return "auto";
}

const Entry kEntries[] = {
    {{"oversample", "--oversample", OptionKind::kIntegerOrAuto,
      "auto or a power of two from 1 to 512", true},
     DISPEX_SETTER({
       if (v == "auto") {
         o.oversample = 0;
         return Status::Ok();
       }
       DISPEX_ASSIGN_OR_RETURN(o.oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["oversample"] = o.oversample == 0 ? json("auto") : json(o.oversample); })},
    {{"max_oversample", "--max-oversample", OptionKind::kInteger, "a power of two from 1 to 512",
      true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.max_oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["max_oversample"] = o.max_oversample; })},
    {{"min_oversample", "--min-oversample", OptionKind::kInteger,
      "a power of two from 1 to max_oversample", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.min_oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["min_oversample"] = o.min_oversample; })},
    {{"search_distance", "--search-distance", OptionKind::kDistance,
      "auto, a length, or a percentage of the base's diagonal (\"2%\")", true},
     DISPEX_SETTER({
       const std::string text = v.is_string() ? v.get<std::string>() : v.dump();
       DISPEX_ASSIGN_OR_RETURN(o.search_distance, ParseSearchDistance(text));
       return Status::Ok();
     }),
     DISPEX_RECORD({
       j["search_distance"] = {{"kind", std::string(SearchKindName(o.search_distance.kind))},
                               {"value", o.search_distance.value}};
     }),
     DISPEX_SETTER({
       const std::string kind = v.is_object() ? v.value("kind", "") : "";
       o.search_distance.kind = kind == "absolute"   ? SearchDistanceSpec::Kind::kAbsolute
                                : kind == "relative" ? SearchDistanceSpec::Kind::kRelative
                                                     : SearchDistanceSpec::Kind::kAuto;
       if (kind != "auto" && kind != "absolute" && kind != "relative") {
         return Status::Error("kind must be auto, absolute or relative");
       }
       if (!v.contains("value") || !v["value"].is_number()) {
         return Status::Error("no numeric value");
       }
       o.search_distance.value = v["value"].get<double>();
       return Status::Ok();
     })},
    {{"ray_policy", "--ray-policy", OptionKind::kChoice, "nearest, outside-first or inside-first",
      true},
     DISPEX_SETTER({ return SetNamed(o.ray_policy, v, ParseHitPolicy); }),
     DISPEX_RECORD({ j["ray_policy"] = std::string(HitPolicyName(o.ray_policy)); })},
    {{"tolerance", "--tolerance", OptionKind::kNumber, "a length > 0 (0: automatic)", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.tolerance, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["tolerance"] = o.tolerance == 0 ? json("auto") : json(o.tolerance); }),
     DISPEX_SETTER({
       if (v == "auto") {
         o.tolerance = 0;
         return Status::Ok();
       }
       DISPEX_ASSIGN_OR_RETURN(o.tolerance, NumberValue(v));
       return Status::Ok();
     })},
    {{"tolerance_fraction", "--tolerance-fraction", OptionKind::kNumber,
      "a fraction of the sculpt's median edge > 0", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.tolerance_fraction, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["tolerance_fraction"] = o.tolerance_fraction; })},
    {{"resolution_rule", "--resolution-rule", OptionKind::kChoice, "bound, nonzero or fixed", true},
     DISPEX_SETTER({ return SetNamed(o.resolution_rule, v, ParseResolutionRule); }),
     DISPEX_RECORD({ j["resolution_rule"] = std::string(ResolutionRuleName(o.resolution_rule)); })},
    {{"fixed_resolution", "--fixed-resolution", OptionKind::kText,
      "WxH with powers of two, e.g. 64x64", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       unsigned w = 0, h = 0;
       char x = 0, extra = 0;
       if (std::sscanf(s.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
           !std::has_single_bit(w) || !std::has_single_bit(h)) {
         return Status::Error(fmt::format("'{}': WxH with powers of two, e.g. 64x64", s));
       }
       o.fixed_ulog2 = std::countr_zero(w);
       o.fixed_vlog2 = std::countr_zero(h);
       return Status::Ok();
     }),
     DISPEX_RECORD({
       j["fixed_resolution"] = {1 << o.fixed_ulog2, 1 << o.fixed_vlog2};
     }),
     DISPEX_SETTER({
       if (!v.is_array() || v.size() != 2 || !v[0].is_number_integer() ||
           !v[1].is_number_integer() || v[0].get<int>() < 1 || v[1].get<int>() < 1) {
         return Status::Error("not [width, height]");
       }
       o.fixed_ulog2 = std::bit_width(v[0].get<unsigned>()) - 1;
       o.fixed_vlog2 = std::bit_width(v[1].get<unsigned>()) - 1;
       return Status::Ok();
     })},
    {{"nonzero_threshold", "--nonzero-threshold", OptionKind::kNumber, "a length >= 0", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.nonzero_threshold, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["nonzero_threshold"] = o.nonzero_threshold; })},
    {{"data_type", "--data-type", OptionKind::kChoice, "float or half", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       if (s != "float" && s != "half") return Status::Error(fmt::format("'{}': float or half", s));
       o.data_type = s == "half" ? PtexDataType::kHalf : PtexDataType::kFloat;
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["data_type"] = std::string(PtexDataTypeName(o.data_type)); }),
     DISPEX_SETTER({
       for (PtexDataType type : {PtexDataType::kHalf, PtexDataType::kFloat}) {
         if (v == PtexDataTypeName(type)) {
           o.data_type = type;
           return Status::Ok();
         }
       }
       return Status::Error("float32 or half");
     })},
    {{"compression_level", "--compression-level", OptionKind::kInteger,
      "-1 (the writer's default) or 0 to 12", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.compression_level, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["compression_level"] = o.compression_level; })},
    {{"holes", "--holes", OptionKind::kChoice, "fill, fail or zero", true},
     DISPEX_SETTER({ return SetNamed(o.holes, v, ParseHolePolicy); }),
     DISPEX_RECORD({ j["holes"] = std::string(HolePolicyName(o.holes)); })},
    {{"watertight", "--watertight", OptionKind::kChoice, "all, filter or off", true},
     DISPEX_SETTER({ return SetNamed(o.watertight, v, ParseWatertightEdges); }),
     DISPEX_RECORD({ j["watertight"] = std::string(WatertightEdgesName(o.watertight)); })},
    {{"max_miss_fraction", "--max-miss-fraction", OptionKind::kNumber, "a fraction in [0, 1]",
      true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.max_miss_fraction, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["max_miss_fraction"] = o.max_miss_fraction; })},
    {{"bvh_quality", "--bvh-quality", OptionKind::kChoice, "low, medium or high", true},
     DISPEX_SETTER({ return SetNamed(o.bvh_quality, v, ParseBuildQuality); }),
     DISPEX_RECORD({ j["bvh_quality"] = std::string(BuildQualityName(o.bvh_quality)); })},
    {{"method", "--method", OptionKind::kChoice, "auto, rays, mapping or interpolate", true},
     DISPEX_SETTER({ return SetNamed(o.method, v, ParseExtractMethod); }),
     DISPEX_RECORD({
       // Only when given: maps made before the option existed keep their keys.
       if (o.method != ExtractMethod::kAuto) j["method"] = std::string(ExtractMethodName(o.method));
     })},
    {{"vector", "--vector", OptionKind::kChoice, "off, tangent, parametric or object", true},
     DISPEX_SETTER({
       if (v == "off") {
         o.vector.reset();
         return Status::Ok();
       }
       VectorSpace space{};
       DISPEX_RETURN_IF_ERROR(SetNamed(space, v, ParseVectorSpace));
       o.vector = space;
       return Status::Ok();
     }),
     DISPEX_RECORD({
       // Only on vector maps, so that scalar maps keep their keys (incremental re-use).
       if (o.vector) j["vector"] = std::string(VectorSpaceName(*o.vector));
     })},
    {{"uv_maps_dir", "--uv-maps", OptionKind::kPath, "a folder for the UDIM tiles", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_maps_dir, TextValue(v));
       return Status::Ok();
     })},
    {{"uv_resolution", "--uv-resolution", OptionKind::kInteger, "texels per tile side, 1..16384",
      true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_resolution, IntValue(v));
       return Status::Ok();
     })},
    {{"uv_padding", "--uv-padding", OptionKind::kInteger, "rings of texels >= 0", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_padding, IntValue(v));
       return Status::Ok();
     })},
    {{"max_memory", "--max-memory", OptionKind::kSize,
      "bytes, or a size such as 8G or 512M (0: the memory available)", true},
     DISPEX_SETTER({
       if (v.is_number_unsigned()) {
         o.max_memory = v.get<std::uint64_t>();
         return Status::Ok();
       }
       DISPEX_ASSIGN_OR_RETURN(std::string size, TextValue(v));
       DISPEX_ASSIGN_OR_RETURN(o.max_memory, ParseByteSize(size));
       return Status::Ok();
     })},
    {{"embree_isa", "--embree-isa", OptionKind::kText, "sse2, sse4.2, avx, avx2 or avx512", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.embree_isa, TextValue(v));
       return Status::Ok();
     })},
    {{"check_inputs", "--no-input-checks", OptionKind::kBool,
      "true or false (the command line's flag turns it off)", true},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.check_inputs, BoolValue(v));
       return Status::Ok();
     })},
    {{"threads", "--threads", OptionKind::kInteger, "0 (all cores) to 4096", false}, DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.threads, IntValue(v));
       if (o.threads < 0 || o.threads > 4096) {
         return Status::Error(fmt::format("{}: must be 0 (all cores) to 4096", o.threads));
       }
       return Status::Ok();
     })},
    {{"incremental", "--incremental", OptionKind::kBool, "true or false", false}, DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.incremental, BoolValue(v));
       return Status::Ok();
     })},
    {{"shard", "--shard", OptionKind::kText, "I/N: the I-th of N farm shards", false},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       return ParseShard(s, o.shard_index, o.shard_count);
     })},
    {{"plan_only", "--plan", OptionKind::kBool,
      "true: stop once the plan is made (which faces would run), writing nothing", false},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.plan_only, BoolValue(v));
       return Status::Ok();
     })},
    {{"shard_sculpt", "--shard-sculpt", OptionKind::kChoice, "whole or part", false},
     DISPEX_SETTER({ return SetNamed(o.shard_sculpt, v, ParseShardSculpt); })},
};

#undef DISPEX_SETTER
#undef DISPEX_RECORD

const Entry* Find(std::string_view name) {
  for (const Entry& e : kEntries) {
    if (e.spec.name == name) return &e;
  }
  return nullptr;
}

std::string Names(bool manifest_only) {
  std::string names;
  for (const Entry& e : kEntries) {
    if (manifest_only && !e.spec.in_manifest) continue;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", e.spec.name);
  }
  return names;
}

Status Set(ExtractOptions& o, const std::string& name, const json& value, bool manifest) {
  const Entry* entry = Find(name);
  if (entry == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("unknown option (known: {})", Names(manifest)));
  }
  if (manifest && !entry->spec.in_manifest) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "set for one run (on the command line or in the call), not in a manifest");
  }
  return entry->set(o, value).WithCode(StatusCode::kInvalidArgument);
}

}  // namespace

std::span<const ExtractOptionSpec> ExtractOptionSpecs() {
  static const std::vector<ExtractOptionSpec> specs = [] {
    std::vector<ExtractOptionSpec> out;
    for (const Entry& e : kEntries) {
      out.push_back(e.spec);
      out.back().in_map = e.record != nullptr;
    }
    return out;
  }();
  return specs;
}

std::string ExtractOptionNames() {
  return Names(/*manifest_only=*/false);
}

Status SetExtractOption(ExtractOptions& options, const std::string& name,
                        const std::string& json_value) {
  const json value = json::parse(json_value, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) {
    return Status::Error(StatusCode::kInvalidArgument, name + ": not a JSON value: " + json_value);
  }
  return Set(options, name, value, /*manifest=*/false).WithPrefix(name);
}

namespace extract {

json ExtractOptionsJson(const ExtractOptions& options) {
  json j = json::object();
  for (const Entry& e : kEntries) {
    if (e.record) e.record(options, j);
  }
  return j;
}

StatusOr<ExtractOptions> ExtractOptionsFromJson(const json& j) {
  if (!j.is_object()) return Status::Error("options: not a JSON object");
  ExtractOptions o;
  for (const auto& [key, value] : j.items()) {
    const Entry* entry = Find(key);
    Status s = entry == nullptr || entry->record == nullptr
                   ? Status::Error("unknown option")
                   : (entry->restore ? entry->restore : entry->set)(o, value);
    if (!s.ok()) return s.WithPrefix("options." + key);
  }
  return o;
}

Status SetOptions(ExtractOptions& o, const json& options, const std::string& where) {
  if (!options.is_object()) return Status::Error(StatusCode::kBadInput, where + ": not an object");
  for (const auto& [name, value] : options.items()) {
    Status s = Set(o, name, value, /*manifest=*/true);
    if (!s.ok()) return s.WithPrefix(fmt::format("{}.{}", where, name));
  }
  return Status::Ok();
}

}  // namespace extract

}  // namespace dispex
