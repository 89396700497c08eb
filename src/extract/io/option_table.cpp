// The extract options set by name, each declared once: its field name (manifests, the Python
// module's keyword arguments, the library's messages), its command-line flag with its --help
// line and default, the kind of value it takes, what it takes in words, and how a value as a
// manifest gives it (JSON) is parsed into ExtractOptions. SetExtractOption, manifests
// (manifest_fields.h), the Python module and the command line -- its flags, their help and its
// messages (tools/cmd_extract.cpp) -- all read this table: a new option is one entry here.
#include <fmt/format.h>

#include <bit>
#include <charconv>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "extract/io/extract_meta.h"
#include "extract/io/extract_names.h"
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

constexpr auto kSearchKindNames = EnumTable<SearchDistanceSpec::Kind>({
    {SearchDistanceSpec::Kind::kAuto, "auto"},
    {SearchDistanceSpec::Kind::kAbsolute, "absolute"},
    {SearchDistanceSpec::Kind::kRelative, "relative"},
});

// data_type as the command line and manifests spell it.
constexpr auto kDataTypeNames = EnumTable<PtexDataType>({
    {PtexDataType::kFloat, "float"},
    {PtexDataType::kHalf, "half"},
});
// data_type as maps record it: the names PtexDataTypeName gives.
constexpr auto kRecordedDataTypeNames = EnumTable<PtexDataType>({
    {PtexDataType::kFloat, "float32"},
    {PtexDataType::kHalf, "half"},
});

// In the order of `dispex extract --help`; last, those set for one run only (not in manifests).
const Entry kEntries[] = {
    {{.name = "oversample",
      .flag = "--oversample",
      .kind = OptionKind::kIntegerOrAuto,
      .values = "auto or a power of two from 1 to 512",
      .in_manifest = true,
      .help = "samples per side of each face: 'auto' (from the sculpt's density) or a power of "
              "two 1..512",
      .default_text = "auto",
      .zero_is_auto = true},
     DISPEX_SETTER({
       if (v == "auto") {
         o.oversample = 0;
         return Status::Ok();
       }
       DISPEX_ASSIGN_OR_RETURN(o.oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["oversample"] = o.oversample == 0 ? json("auto") : json(o.oversample); })},
    {{.name = "max_oversample",
      .flag = "--max-oversample",
      .kind = OptionKind::kInteger,
      .values = "a power of two from 1 to 512",
      .in_manifest = true,
      .help = "cap for automatic oversampling",
      .default_text = "128"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.max_oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["max_oversample"] = o.max_oversample; })},
    {{.name = "min_oversample",
      .flag = "--min-oversample",
      .kind = OptionKind::kInteger,
      .values = "a power of two from 1 to max_oversample",
      .in_manifest = true,
      .help = "floor for automatic oversampling",
      .default_text = "4"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.min_oversample, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["min_oversample"] = o.min_oversample; })},
    {{.name = "search_distance",
      .flag = "--search-distance",
      .kind = OptionKind::kDistance,
      .values = "auto, a length, or a percentage of the base's diagonal (\"2%\")",
      .in_manifest = true,
      .help = "how far along ±normal to look: 'auto', a length, or N% of the base bounding-box "
              "diagonal",
      .default_text = "auto"},
     DISPEX_SETTER({
       const std::string text = v.is_string() ? v.get<std::string>() : v.dump();
       DISPEX_ASSIGN_OR_RETURN(o.search_distance, ParseSearchDistance(text));
       return Status::Ok();
     }),
     DISPEX_RECORD({
       j["search_distance"] = {
           {"kind", std::string(EnumName(kSearchKindNames, o.search_distance.kind))},
           {"value", o.search_distance.value}};
     }),
     DISPEX_SETTER({
       const std::string kind = v.is_object() ? v.value("kind", "") : "";
       DISPEX_ASSIGN_OR_RETURN(o.search_distance.kind,
                               ParseEnum(kSearchKindNames, "search distance kind", kind));
       if (!v.contains("value") || !v["value"].is_number()) {
         return Status::Error("no numeric value");
       }
       o.search_distance.value = v["value"].get<double>();
       return Status::Ok();
     })},
    {{.name = "ray_policy",
      .flag = "--ray-policy",
      .kind = OptionKind::kChoice,
      .values = "nearest, outside-first or inside-first",
      .in_manifest = true,
      .help = "hit kept when both directions hit: nearest, outside-first, inside-first",
      .default_text = "nearest"},
     DISPEX_SETTER({ return SetNamed(o.ray_policy, v, ParseHitPolicy); }),
     DISPEX_RECORD({ j["ray_policy"] = std::string(HitPolicyName(o.ray_policy)); })},
    {{.name = "tolerance",
      .flag = "--tolerance",
      .kind = OptionKind::kNumber,
      .values = "a length > 0 (0: automatic)",
      .in_manifest = true,
      .help = "largest allowed error per face, object units (default: --tolerance-fraction x the "
              "sculpt's median edge length)",
      .zero_is_auto = true},
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
    {{.name = "tolerance_fraction",
      .flag = "--tolerance-fraction",
      .kind = OptionKind::kNumber,
      .values = "a fraction of the sculpt's median edge > 0",
      .in_manifest = true,
      .help = "automatic tolerance as a fraction of the sculpt's median edge length",
      .default_text = "0.05"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.tolerance_fraction, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["tolerance_fraction"] = o.tolerance_fraction; })},
    {{.name = "resolution_rule",
      .flag = "--resolution-rule",
      .kind = OptionKind::kChoice,
      .values = "bound, nonzero or fixed",
      .in_manifest = true,
      .help = "per-face resolution: bound (error bound), nonzero (published rule), fixed",
      .default_text = "bound"},
     DISPEX_SETTER({ return SetNamed(o.resolution_rule, v, ParseResolutionRule); }),
     DISPEX_RECORD({ j["resolution_rule"] = std::string(ResolutionRuleName(o.resolution_rule)); })},
    {{.name = "nonzero_threshold",
      .flag = "--nonzero-threshold",
      .kind = OptionKind::kNumber,
      .values = "a length >= 0",
      .in_manifest = true,
      .help = "|DCT coefficient| counted as non-zero by --resolution-rule nonzero",
      .default_text = "0"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.nonzero_threshold, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["nonzero_threshold"] = o.nonzero_threshold; })},
    {{.name = "fixed_resolution",
      .flag = "--fixed-resolution",
      .kind = OptionKind::kText,
      .values = "WxH with powers of two, e.g. 64x64",
      .in_manifest = true,
      .help = "WxH for --resolution-rule fixed",
      .default_text = "64x64"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       unsigned w = 0, h = 0;
       char x = 0, extra = 0;
       if (std::sscanf(s.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' ||
           !std::has_single_bit(w) || !std::has_single_bit(h)) {
         return Status::Error(fmt::format("'{}': expected WxH with powers of two, e.g. 64x64", s));
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
    {{.name = "data_type",
      .flag = "--data-type",
      .kind = OptionKind::kChoice,
      .values = EnumNameListConstant<kDataTypeNames>(),
      .in_manifest = true,
      .help = "texel type: float or half",
      .default_text = "float"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       DISPEX_ASSIGN_OR_RETURN(o.data_type, ParseEnum(kDataTypeNames, "data type", s));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["data_type"] = std::string(PtexDataTypeName(o.data_type)); }),
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       DISPEX_ASSIGN_OR_RETURN(o.data_type, ParseEnum(kRecordedDataTypeNames, "data type", s));
       return Status::Ok();
     })},
    {{.name = "compression_level",
      .flag = "--compression-level",
      .kind = OptionKind::kInteger,
      .values = "-1 (the writer's default) or 0 to 12",
      .in_manifest = true,
      .help = "deflate level 0..12 (-1: default, 1)",
      .default_text = "-1"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.compression_level, IntValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["compression_level"] = o.compression_level; })},
    {{.name = "holes",
      .flag = "--holes",
      .kind = OptionKind::kChoice,
      .values = EnumNameListConstant<extract::kHolePolicyNames>(),
      .in_manifest = true,
      .help = "samples whose rays miss: fill (interpolate), fail (error), zero",
      .default_text = "fill"},
     DISPEX_SETTER({ return SetNamed(o.holes, v, ParseHolePolicy); }),
     DISPEX_RECORD({ j["holes"] = std::string(HolePolicyName(o.holes)); })},
    {{.name = "watertight",
      .flag = "--watertight",
      .kind = OptionKind::kChoice,
      .values = EnumNameListConstant<extract::kWatertightEdgesNames>(),
      .in_manifest = true,
      .help = "shared face edges meet within the tolerance for: filter (the Ptex library's "
              "filters), all (also readers that read each face on its own), off",
      .default_text = "filter"},
     DISPEX_SETTER({ return SetNamed(o.watertight, v, ParseWatertightEdges); }),
     DISPEX_RECORD({ j["watertight"] = std::string(WatertightEdgesName(o.watertight)); })},
    {{.name = "max_miss_fraction",
      .flag = "--max-miss-fraction",
      .kind = OptionKind::kNumber,
      .values = "a fraction in [0, 1]",
      .in_manifest = true,
      .help = "fail when more than this fraction of the samples miss the sculpt after the "
              "second search (0..1; 1: never)",
      .default_text = "0.05"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.max_miss_fraction, NumberValue(v));
       return Status::Ok();
     }),
     DISPEX_RECORD({ j["max_miss_fraction"] = o.max_miss_fraction; })},
    {{.name = "method",
      .flag = "--method",
      .kind = OptionKind::kChoice,
      .values = EnumNameListConstant<extract::kExtractMethodNames>(),
      .in_manifest = true,
      .help = "where values come from: auto (interpolate when the sculpt is the base refined, "
              "else rays), interpolate (the sculpt's vertex displacements interpolated through "
              "the subdivision correspondence, no rays), mapping (rays through the "
              "correspondence: the map follows the sculpt's flat quads), rays (a BVH of the "
              "sculpt); interpolate and mapping fail when the sculpt is not the base refined",
      .default_text = "auto"},
     DISPEX_SETTER({ return SetNamed(o.method, v, ParseExtractMethod); }),
     DISPEX_RECORD({
       // Only when given: maps made before the option existed keep their keys.
       if (o.method != ExtractMethod::kAuto) j["method"] = std::string(ExtractMethodName(o.method));
     })},
    {{.name = "bvh_quality",
      .flag = "--bvh-quality",
      .kind = OptionKind::kChoice,
      .values = "low, medium or high",
      .in_manifest = true,
      .help = "BVH build quality: low, medium, high",
      .default_text = "low"},
     DISPEX_SETTER({ return SetNamed(o.bvh_quality, v, ParseBuildQuality); }),
     DISPEX_RECORD({ j["bvh_quality"] = std::string(BuildQualityName(o.bvh_quality)); })},
    {{.name = "embree_isa",
      .flag = "--embree-isa",
      .kind = OptionKind::kText,
      .values = "sse2, sse4.2, avx, avx2 or avx512",
      .in_manifest = true,
      .help = "Embree kernels: sse2, sse4.2, avx, avx2, avx512 (default: $DISPEX_EMBREE_ISA, "
              "else the widest this CPU runs)"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.embree_isa, TextValue(v));
       return Status::Ok();
     })},
    {{.name = "max_memory",
      .flag = "--max-memory",
      .kind = OptionKind::kSize,
      .values = "bytes, or a size such as 8G or 512M (0: the memory available)",
      .in_manifest = true,
      .help = "keep within this memory (e.g. 8G; default: the memory available): a sculpt "
              "whose BVH would not fit is traced in parts, work that fits no plan is refused "
              "before it starts"},
     DISPEX_SETTER({
       if (v.is_number_unsigned()) {
         o.max_memory = v.get<std::uint64_t>();
         return Status::Ok();
       }
       DISPEX_ASSIGN_OR_RETURN(std::string size, TextValue(v));
       DISPEX_ASSIGN_OR_RETURN(o.max_memory, ParseByteSize(size));
       return Status::Ok();
     })},
    {{.name = "vector",
      .flag = "--vector",
      .kind = OptionKind::kChoice,
      .values = "off, tangent, parametric or object",
      .in_manifest = true,
      .help = "write a vector displacement map (3 channels: sculpt - limit surface) in this "
              "space: tangent (T, B, N), parametric (dP/du, dP/dv, N) or object (x, y, z); the "
              "sculpt must be the base refined (see `dispex match`)"},
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
    {{.name = "uv_maps_dir",
      .flag = "--uv-maps",
      .kind = OptionKind::kPath,
      .values = "a folder for the UDIM tiles",
      .in_manifest = true,
      .help = "also write UV-space maps: DIR/<map>.<UDIM>.exr (OpenEXR, one float channel, or R, "
              "G, B = x, y, z with --vector object) for every UDIM tile the base's UVs touch, "
              "extracted at each texel (UVs interpolated face-varying linearly; "
              "docs/UV_MAPS.md)"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_maps_dir, TextValue(v));
       return Status::Ok();
     })},
    {{.name = "uv_resolution",
      .flag = "--uv-resolution",
      .kind = OptionKind::kInteger,
      .values = "texels per tile side, 1..16384",
      .in_manifest = true,
      .help = "texels per side of each UDIM tile",
      .default_text = "1024"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_resolution, IntValue(v));
       return Status::Ok();
     })},
    {{.name = "uv_padding",
      .flag = "--uv-padding",
      .kind = OptionKind::kInteger,
      .values = "rings of texels >= 0",
      .in_manifest = true,
      .help = "texels of dilation outside the UV faces, so that filtering at seams never reads "
              "empty texels",
      .default_text = "16"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.uv_padding, IntValue(v));
       return Status::Ok();
     })},
    {{.name = "check_inputs",
      .flag = "--no-input-checks",
      .kind = OptionKind::kBool,
      .values = "true or false (the command line's flag turns it off)",
      .in_manifest = true,
      .help = "extract inputs that look like a mistake: a sculpt with fewer faces than its base, "
              "or one moved, scaled or turned against it as a whole",
      .default_text = "true"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.check_inputs, BoolValue(v));
       return Status::Ok();
     })},
    {{.name = "plan_only",
      .flag = "--plan",
      .kind = OptionKind::kBool,
      .values = "true: stop once the plan is made (which faces would run), writing nothing",
      .in_manifest = false,
      .help = "print the plan -- which faces would be traced and which copied, the method and "
              "what the BVH holds -- and stop: the inputs are read and matched, nothing is "
              "written (with --report, the report's \"plan\")",
      .default_text = "false"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.plan_only, BoolValue(v));
       return Status::Ok();
     })},
    {{.name = "threads",
      .flag = "--threads",
      .kind = OptionKind::kInteger,
      .values = "0 (all cores) to 4096",
      .in_manifest = false,
      .help = "worker threads (0: all cores)",
      .default_text = "0"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.threads, IntValue(v));
       if (o.threads < 0 || o.threads > 4096) {
         return Status::Error(fmt::format("{}: must be 0 (all cores) to 4096", o.threads));
       }
       return Status::Ok();
     })},
    {{.name = "incremental",
      .flag = "--incremental",
      .kind = OptionKind::kBool,
      .values = "true or false",
      .in_manifest = false,
      .help = "re-use the map at the output path: left as it is when made from the same inputs "
              "and options, else only the faces whose inputs changed are extracted (the result "
              "is the file a full extraction writes)",
      .default_text = "false"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.incremental, BoolValue(v));
       return Status::Ok();
     })},
    {{.name = "cache_dir",
      .flag = "--cache-dir",
      .kind = OptionKind::kText,
      .values = "a folder, or off",
      .in_manifest = true,
      .help = "where --incremental keeps the sculpt's adjacency for the next run after an edit "
              "(default: $XDG_CACHE_HOME/dispex, else ~/.cache/dispex; off: nothing kept)"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(o.cache_dir, TextValue(v));
       return Status::Ok();
     })},
    {{.name = "shard",
      .flag = "--shard",
      .kind = OptionKind::kText,
      .values = "I/N: the I-th of N farm shards",
      .in_manifest = false,
      .help = "I/N: extract only the I-th of N shards of the faces (balanced by estimated cost) "
              "into a part for `dispex merge` (docs/FARM.md)"},
     DISPEX_SETTER({
       DISPEX_ASSIGN_OR_RETURN(std::string s, TextValue(v));
       return ParseShard(s, o.shard_index, o.shard_count);
     })},
    {{.name = "shard_sculpt",
      .flag = "--shard-sculpt",
      .kind = OptionKind::kChoice,
      .values = EnumNameListConstant<extract::kShardSculptNames>(),
      .in_manifest = false,
      .help = "what a shard keeps of the sculpt: whole, or part (only what its faces' rays "
              "reach, an automatic search distance estimated in N parts: memory falls with N)",
      .default_text = "whole"},
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

// `text` in messages: '' when empty.
std::string Shown(const std::string& text) {
  return text.empty() ? "''" : text;
}

// The JSON value of a flag's text, as the option's kind reads it (SetExtractOptionText).
StatusOr<json> FlagTextJson(const ExtractOptionSpec& spec, const std::string& text) {
  const char* const end = text.data() + text.size();
  const auto refused = [&] {
    return Status::Error(
        fmt::format("{} must be greater than 0 (leave the option out{} for the automatic value)",
                    text, spec.kind == OptionKind::kIntegerOrAuto ? ", or give 'auto'," : ""));
  };
  switch (spec.kind) {
    case OptionKind::kInteger:
    case OptionKind::kIntegerOrAuto: {
      if (spec.kind == OptionKind::kIntegerOrAuto && text == "auto") return json("auto");
      int value = 0;
      const auto [stop, error] = std::from_chars(text.data(), end, value);
      if (text.empty() || error != std::errc() || stop != end) {
        return Status::Error(
            fmt::format("{} is not {}", Shown(text),
                        spec.kind == OptionKind::kInteger ? "an integer" : "'auto' or an integer"));
      }
      if (spec.zero_is_auto && value <= 0) return refused();
      return json(value);
    }
    case OptionKind::kNumber: {
      double value = 0;
      const auto [stop, error] = std::from_chars(text.data(), end, value);
      if (text.empty() || error != std::errc() || stop != end) {
        return Status::Error(fmt::format("{} is not a number", Shown(text)));
      }
      if (spec.zero_is_auto && !(value > 0)) return refused();
      return json(value);
    }
    case OptionKind::kBool:
      if (text == "true" || text == "false") return json(text == "true");
      return Status::Error(fmt::format("{} is not true or false", Shown(text)));
    case OptionKind::kText:
    case OptionKind::kPath:
    case OptionKind::kChoice:
    case OptionKind::kSize:
    case OptionKind::kDistance:
      break;
  }
  return json(text);
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

Status SetExtractOptionText(ExtractOptions& options, std::string_view name,
                            const std::string& text) {
  const Entry* entry = Find(name);
  if (entry == nullptr) {
    return Status::Error(
        StatusCode::kInvalidArgument,
        fmt::format("unknown option '{}' (known: {})", name, Names(/*manifest_only=*/false)));
  }
  const StatusOr<json> value = FlagTextJson(entry->spec, text);
  if (!value.ok()) return value.status().WithCode(StatusCode::kInvalidArgument);
  return entry->set(options, *value).WithCode(StatusCode::kInvalidArgument);
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
