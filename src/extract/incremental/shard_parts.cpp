#include "extract/incremental/shard_parts.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/hash128.h"
#include "dispex/version.h"
#include "extract/incremental/face_records.h"

namespace dispex::extract {

namespace {

std::string Meta(const PtexFile& file, const char* key) {
  const PtexMetaItem* item = file.FindMetaData(key);
  return item ? item->AsString() : "";
}

// How part a's origin differs from part b's, in words; "" when it does not.
std::string Difference(const ShardPart& a, const ShardPart& b) {
  if (Meta(a.file, "dispex:version") != Meta(b.file, "dispex:version")) {
    return fmt::format("written by dispex {}, {} by {}", Meta(a.file, "dispex:version"), b.path,
                       Meta(b.file, "dispex:version"));
  }
  if (Meta(a.file, "dispex:base_fingerprint") != Meta(b.file, "dispex:base_fingerprint")) {
    return fmt::format("made from another base than {} (the fingerprints differ)", b.path);
  }
  if (Meta(a.file, "dispex:sculpt_fingerprint") != Meta(b.file, "dispex:sculpt_fingerprint")) {
    return fmt::format("made from another sculpt than {} (the fingerprints differ)", b.path);
  }
  if (a.info.options != b.info.options) {
    const auto x = nlohmann::json::parse(a.info.options, nullptr, false);
    const auto y = nlohmann::json::parse(b.info.options, nullptr, false);
    std::string names;
    if (x.is_object() && y.is_object()) {
      for (const auto& [key, value] : x.items()) {
        if (!y.contains(key) || y[key] != value) names += (names.empty() ? "" : ", ") + key;
      }
      for (const auto& [key, value] : y.items()) {
        if (!x.contains(key)) names += (names.empty() ? "" : ", ") + key;
      }
    }
    return fmt::format("made with other options than {} ({})", b.path,
                       names.empty() ? "options" : names);
  }
  if (a.info.count != b.info.count) {
    return fmt::format("one of {} shards, {} one of {}", a.info.count, b.path, b.info.count);
  }
  if (a.info.map_inputs_key != b.info.map_inputs_key) {
    return fmt::format("made from other inputs than {} (file names)", b.path);
  }
  return "";
}

}  // namespace

std::string ShardInfoJson(const ShardInfo& info) {
  nlohmann::json j;
  j["index"] = info.index;
  j["count"] = info.count;
  j["faces"] = {info.begin, info.end};
  j["map_inputs_key"] = info.map_inputs_key;
  j["base"] = info.base_path;
  j["sculpt"] = info.sculpt_path;
  j["options"] = info.options;
  return j.dump();
}

std::string PartInputsKey(const std::string& map_inputs_key, int index, int count) {
  Hasher h;
  h.Add(std::string_view("dispex shard part")).Add(std::string_view(map_inputs_key));
  h.Add(index).Add(count);
  return h.Digest().Hex();
}

namespace {

StatusOr<ShardPart> ReadShardPart(const std::string& path) {
  StatusOr<PtexFile> file = PtexFile::Open(path);
  if (!file.ok()) return file.status().WithPrefix(path);
  const PtexMetaItem* item = file->FindMetaData(kShardMetaKey);
  if (item == nullptr) return Status::Error(fmt::format("{}: not a part written by a shard", path));
  const std::string version = Meta(*file, "dispex:version");
  if (version != DISPEX_VERSION_STRING) {
    return Status::Error(fmt::format("{}: written by dispex {}, this is dispex {}", path, version,
                                     DISPEX_VERSION_STRING));
  }
  const auto j = nlohmann::json::parse(item->AsString(), nullptr, /*allow_exceptions=*/false);
  ShardPart part{path, std::move(*file), {}};
  ShardInfo& info = part.info;
  const bool valid = j.is_object() && j.contains("index") && j["index"].is_number_integer() &&
                     j.contains("count") && j["count"].is_number_integer() && j.contains("faces") &&
                     j["faces"].is_array() && j["faces"].size() == 2 &&
                     j["faces"][0].is_number_integer() && j["faces"][1].is_number_integer() &&
                     j.value("map_inputs_key", "") != "" && j.value("base", "") != "" &&
                     j.value("sculpt", "") != "" && j.value("options", "") != "";
  if (valid) {
    info.index = j["index"].get<int>();
    info.count = j["count"].get<int>();
    info.begin = j["faces"][0].get<std::int64_t>();
    info.end = j["faces"][1].get<std::int64_t>();
    info.map_inputs_key = j["map_inputs_key"].get<std::string>();
    info.base_path = j["base"].get<std::string>();
    info.sculpt_path = j["sculpt"].get<std::string>();
    info.options = j["options"].get<std::string>();
  }
  const auto num_faces = static_cast<std::size_t>(part.file.num_faces());
  const PtexMetaItem* keys = part.file.FindMetaData(kFaceKeysMetaKey);
  const PtexMetaItem* records = part.file.FindMetaData(kFaceRecordsMetaKey);
  if (!valid || info.count < 1 || info.index < 1 || info.index > info.count || info.begin < 0 ||
      info.begin > info.end || info.end > part.file.num_faces() || keys == nullptr ||
      records == nullptr || !DecodeFaceKeys(keys->bytes, num_faces) ||
      !DecodeFaceRecords(records->bytes, num_faces, 1)) {
    return Status::Error(fmt::format("{}: malformed shard record", path));
  }
  Status data = CheckMapFaceData(part.file);
  if (!data.ok()) return data.WithPrefix(path + ": corrupt face data");
  return part;
}

}  // namespace

StatusOr<ShardPart> OpenShardPart(const std::string& path) {
  StatusOr<ShardPart> part = ReadShardPart(path);
  if (!part.ok()) return part.status().WithCode(StatusCode::kBadInput).WithPath(path);
  return part;
}

StatusOr<std::vector<ShardPart>> CheckShardParts(std::vector<ShardPart> parts) {
  if (parts.empty()) return Status::Error(StatusCode::kMismatch, "no parts to merge");
  for (std::size_t k = 1; k < parts.size(); ++k) {
    const std::string why = Difference(parts[k], parts[0]);
    if (!why.empty()) {
      return Status::Error(StatusCode::kMismatch, fmt::format("{}: {}", parts[k].path, why));
    }
  }
  std::stable_sort(parts.begin(), parts.end(), [](const ShardPart& a, const ShardPart& b) {
    return a.info.index < b.info.index;
  });
  const int count = parts[0].info.count;
  for (std::size_t k = 1; k < parts.size(); ++k) {
    if (parts[k].info.index == parts[k - 1].info.index) {
      return Status::Error(StatusCode::kMismatch,
                           fmt::format("{} and {} are both shard {}/{}", parts[k - 1].path,
                                       parts[k].path, parts[k].info.index, count));
    }
  }
  for (int i = 1, k = 0; i <= count; ++i, ++k) {
    if (static_cast<std::size_t>(k) >= parts.size() ||
        parts[static_cast<std::size_t>(k)].info.index != i) {
      return Status::Error(StatusCode::kMismatch,
                           fmt::format("shard {}/{} is missing ({} of {} parts given)", i, count,
                                       parts.size(), count));
    }
  }
  std::int64_t next = 0;
  for (const ShardPart& part : parts) {
    if (part.info.begin != next) {
      return Status::Error(
          StatusCode::kMismatch,
          fmt::format(
              "{}: shard {}/{} holds faces {}..{} of the shard order, but the shards before it end "
              "at {}",
              part.path, part.info.index, count, part.info.begin, part.info.end - 1, next - 1));
    }
    next = part.info.end;
  }
  if (next != parts[0].file.num_faces()) {
    return Status::Error(StatusCode::kMismatch,
                         fmt::format("{}: the shards end at face {} of {} in shard order",
                                     parts.back().path, next - 1, parts[0].file.num_faces()));
  }
  return parts;
}

Status CheckPartsMatchInputs(const std::vector<ShardPart>& parts, const ExtractReport& report) {
  const ShardPart& part = parts.front();
  if (Meta(part.file, "dispex:base_fingerprint") != report.inputs.base_fingerprint) {
    return Status::Error(StatusCode::kMismatch,
                         fmt::format("{}: made from another {} than the file there now (its "
                                     "fingerprint differs); run the shards again",
                                     part.path, report.inputs.base_path));
  }
  if (Meta(part.file, "dispex:sculpt_fingerprint") != report.inputs.sculpt_fingerprint) {
    return Status::Error(StatusCode::kMismatch,
                         fmt::format("{}: made from another {} than the file there now (its "
                                     "fingerprint differs); run the shards again",
                                     part.path, report.inputs.sculpt_path));
  }
  if (part.info.map_inputs_key != report.incremental.inputs_key) {
    return Status::Error(StatusCode::kMismatch,
                         fmt::format("{}: made from other inputs than {} and {} now", part.path,
                                     report.inputs.base_path, report.inputs.sculpt_path));
  }
  if (static_cast<std::size_t>(part.file.num_faces()) != report.inputs.ptex_faces) {
    return Status::Error(
        StatusCode::kMismatch,
        fmt::format("{}: has {} faces, {} now {}", part.path, part.file.num_faces(),
                    report.inputs.base_path, report.inputs.ptex_faces));
  }
  return Status::Ok();
}

}  // namespace dispex::extract
