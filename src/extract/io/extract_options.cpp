#include <fmt/format.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/vector_space.h"
#include "extract/io/extract_names.h"

namespace dispex {

std::string_view HolePolicyName(HolePolicy policy) {
  return EnumName(extract::kHolePolicyNames, policy);
}

StatusOr<HolePolicy> ParseHolePolicy(std::string_view name) {
  return ParseEnum(extract::kHolePolicyNames, "hole policy", name);
}

std::string_view WatertightEdgesName(WatertightEdges mode) {
  return EnumName(extract::kWatertightEdgesNames, mode);
}

StatusOr<WatertightEdges> ParseWatertightEdges(std::string_view name) {
  return ParseEnum(extract::kWatertightEdgesNames, "watertight mode", name);
}

std::string_view ExtractMethodName(ExtractMethod method) {
  return EnumName(extract::kExtractMethodNames, method);
}

StatusOr<ExtractMethod> ParseExtractMethod(std::string_view name) {
  return ParseEnum(extract::kExtractMethodNames, "method", name);
}

std::string_view ShardSculptName(ShardSculpt s) {
  return EnumName(extract::kShardSculptNames, s);
}

StatusOr<ShardSculpt> ParseShardSculpt(std::string_view name) {
  return ParseEnum(extract::kShardSculptNames, "shard sculpt", name);
}

namespace {
bool IsPowerOfTwoIn(int v, int lo, int hi) {
  return v >= lo && v <= hi && std::has_single_bit(static_cast<unsigned>(v));
}
}  // namespace

Status CheckMapName(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const std::pair<const char*, const char*> kOtherFormats[] = {
      {".exr", "OpenEXR (UV-space tiles are written to uv_maps_dir)"},
      {".png", "PNG"},
      {".tif", "TIFF"},
      {".tiff", "TIFF"},
      {".jpg", "JPEG"},
      {".jpeg", "JPEG"},
      {".tx", "a mipmapped texture (maketx)"},
      {".tex", "a RenderMan texture"},
      {".obj", "a mesh (OBJ)"},
      {".ply", "a mesh (PLY)"},
      {".json", "JSON"},
  };
  for (const auto& [other, format] : kOtherFormats) {
    if (extension == other) {
      return Status::Error(fmt::format(
          "output_path {}: the name says {}, and the map is written as Ptex: name it .ptx", path,
          format));
    }
  }
  return Status::Ok();
}

namespace {

// The inputs and the output are given, and the output is neither input.
Status CheckFilesGiven(const ExtractOptions& o) {
  if (o.base_path.empty() && !o.base_mesh) return Status::Error("no base mesh given");
  if (o.sculpt_path.empty() && !o.sculpt_mesh) return Status::Error("no sculpt mesh given");
  if (o.output_path.empty()) return Status::Error("no output file given (output_path)");
  if ((!o.base_mesh && o.output_path == o.base_path) ||
      (!o.sculpt_mesh && o.output_path == o.sculpt_path)) {
    return Status::Error(
        fmt::format("output {} is also an input; refusing to overwrite it", o.output_path));
  }
  return Status::Ok();
}

// Oversampling, tolerance and search distance.
Status CheckSampling(const ExtractOptions& o) {
  if (o.oversample != 0 && !IsPowerOfTwoIn(o.oversample, 1, kMaxSpectralSize)) {
    return Status::Error(
        fmt::format("oversample = {}: must be 0 (automatic) or a power of two from 1 to {}",
                    o.oversample, kMaxSpectralSize));
  }
  if (!IsPowerOfTwoIn(o.max_oversample, 1, kMaxSpectralSize)) {
    return Status::Error(fmt::format("max_oversample = {}: must be a power of two from 1 to {}",
                                     o.max_oversample, kMaxSpectralSize));
  }
  if (!IsPowerOfTwoIn(o.min_oversample, 1, o.max_oversample)) {
    return Status::Error(
        fmt::format("min_oversample = {}: must be a power of two from 1 to max_oversample ({})",
                    o.min_oversample, o.max_oversample));
  }
  if (!(std::isfinite(o.tolerance) && o.tolerance >= 0)) {
    return Status::Error(fmt::format("tolerance = {}: must be a finite length > 0", o.tolerance));
  }
  if (!(std::isfinite(o.tolerance_fraction) && o.tolerance_fraction > 0)) {
    return Status::Error(fmt::format("tolerance_fraction = {}: must be > 0", o.tolerance_fraction));
  }
  if (o.search_distance.kind != SearchDistanceSpec::Kind::kAuto &&
      !(std::isfinite(o.search_distance.value) && o.search_distance.value > 0)) {
    return Status::Error(fmt::format("search_distance = {}: must be > 0", o.search_distance.value));
  }
  return Status::Ok();
}

// The map's data type and compression, the miss limit, the threads and the method.
Status CheckMapAndRun(const ExtractOptions& o) {
  if (o.data_type != PtexDataType::kFloat && o.data_type != PtexDataType::kHalf) {
    return Status::Error("data_type: must be float or half");
  }
  if (std::string why =
          PtexCompressionLevelProblem(PtexWriterOptions{}.compressor, o.compression_level);
      !why.empty()) {
    return Status::Error(fmt::format("compression_level = {}: {}", o.compression_level, why));
  }
  if (!(o.max_miss_fraction >= 0 && o.max_miss_fraction <= 1)) {
    return Status::Error(
        fmt::format("max_miss_fraction = {}: must be in [0, 1]", o.max_miss_fraction));
  }
  if (o.threads < 0) return Status::Error(fmt::format("threads = {}: must be >= 0", o.threads));
  if (o.vector && o.method == ExtractMethod::kRays) {
    return Status::Error(
        "method = rays: a vector map reads the sculpt through its correspondence, not rays");
  }
  return Status::Ok();
}

// UV-space maps (when uv_maps_dir is given): their size, and what they cannot be made with.
Status CheckUvMaps(const ExtractOptions& o) {
  if (o.uv_maps_dir.empty()) return Status::Ok();
  if (o.uv_resolution < 1 || o.uv_resolution > 16384) {
    return Status::Error(fmt::format("uv_resolution = {}: must be 1..16384", o.uv_resolution));
  }
  if (o.uv_padding < 0) {
    return Status::Error(fmt::format("uv_padding = {}: must be >= 0", o.uv_padding));
  }
  if (o.vector && *o.vector != VectorSpace::kObject) {
    return Status::Error(fmt::format(
        "uv_maps_dir: a {} space vector map's frame is its Ptex face's, which no UV-space "
        "reader shares: UV-space vector maps are object space only",
        VectorSpaceName(*o.vector)));
  }
  if (o.shard_count > 0) {
    return Status::Error("uv_maps_dir: UV-space maps are not made in shards (docs/FARM.md)");
  }
  return Status::Ok();
}

// A farm shard: its index, and what shards cannot be made with.
Status CheckShard(const ExtractOptions& o) {
  if (o.shard_count < 0 ||
      (o.shard_count > 0 && (o.shard_index < 1 || o.shard_index > o.shard_count))) {
    return Status::Error(fmt::format("shard {}/{}: the index must be 1..{} and the count > 0",
                                     o.shard_index, o.shard_count, o.shard_count));
  }
  if (o.shard_count > 0 && o.vector) {
    return Status::Error(
        "shard_count: vector maps are not made in shards (only scalar maps; docs/FARM.md)");
  }
  return Status::Ok();
}

// The output's name, and that the output file (and the UV maps' folder) can be written.
Status CheckOutputPlaces(const ExtractOptions& o) {
  DISPEX_RETURN_IF_ERROR(CheckMapName(o.output_path));
  const Status output = CheckOutputFile(o.output_path);
  if (!output.ok()) return output.WithPrefix("output_path");
  if (!o.uv_maps_dir.empty()) {
    const Status folder = CheckOutputFolder(o.uv_maps_dir);
    if (!folder.ok()) return folder.WithPrefix("uv_maps_dir");
  }
  return Status::Ok();
}

// The resolution rule's settings, as the spectral analysis checks them.
Status CheckResolutionRule(const ExtractOptions& o) {
  SpectralOptions spectral;
  spectral.rule = o.resolution_rule;
  spectral.tolerance = o.tolerance > 0 ? o.tolerance : 1.0;
  spectral.nonzero_threshold = o.nonzero_threshold;
  spectral.fixed_ulog2 = o.fixed_ulog2;
  spectral.fixed_vlog2 = o.fixed_vlog2;
  return ValidateSpectralOptions(spectral);
}

// Every check, in this order: the first failing one names the problem.
Status CheckOptions(const ExtractOptions& o) {
  DISPEX_RETURN_IF_ERROR(CheckFilesGiven(o));
  DISPEX_RETURN_IF_ERROR(CheckSampling(o));
  DISPEX_RETURN_IF_ERROR(CheckMapAndRun(o));
  DISPEX_RETURN_IF_ERROR(CheckUvMaps(o));
  DISPEX_RETURN_IF_ERROR(CheckShard(o));
  DISPEX_RETURN_IF_ERROR(CheckOutputPlaces(o));
  return CheckResolutionRule(o);
}

}  // namespace

Status ValidateExtractOptions(const ExtractOptions& options) {
  return CheckOptions(options).WithCode(StatusCode::kInvalidArgument);
}

StatusOr<std::uint64_t> ParseByteSize(const std::string& text) {
  double value = 0;
  char unit = 0, extra = 0;
  int n = std::sscanf(text.c_str(), "%lf%c%c", &value, &unit, &extra);
  if (n < 1 || n > 2 || !(value > 0)) {
    return Status::Error(fmt::format("'{}': expected a size such as 8G or 512M", text));
  }
  double scale = 1;
  switch (n == 2 ? unit : 'B') {
    case 'B':
    case 'b':
      break;
    case 'K':
    case 'k':
      scale = 1024.0;
      break;
    case 'M':
    case 'm':
      scale = 1024.0 * 1024;
      break;
    case 'G':
    case 'g':
      scale = 1024.0 * 1024 * 1024;
      break;
    case 'T':
    case 't':
      scale = 1024.0 * 1024 * 1024 * 1024;
      break;
    default:
      return Status::Error(fmt::format("'{}': unknown unit '{}' (K, M, G, T)", text, unit));
  }
  return static_cast<std::uint64_t>(value * scale);
}

Status ParseShard(std::string_view text, int& index, int& count) {
  const std::string s(text);
  int i = 0, n = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &i, &slash, &n, &extra) != 3 || slash != '/' || n < 1 ||
      i < 1 || i > n) {
    return Status::Error(fmt::format("'{}': expected I/N with 1 <= I <= N, e.g. 2/8", s));
  }
  index = i;
  count = n;
  return Status::Ok();
}

}  // namespace dispex
