#include "extract/incremental/previous_map.h"

#include <fmt/format.h>

#include <filesystem>

#include "dispex/version.h"

namespace dispex::extract {

PreviousMap PreviousMap::Open(const std::string& path, std::size_t num_faces, bool vector) {
  PreviousMap out;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return out;
  auto ignore = [&](const std::string& why) {
    out.notice_ = fmt::format("{}: {}; not re-used, every face is extracted", path, why);
    out.files_.clear();
    return std::move(out);
  };
  StatusOr<PtexFile> file = PtexFile::Open(path);
  if (!file.ok()) return ignore("cannot be read (" + file.status().message() + ")");
  const PtexMetaItem* version = file->FindMetaData("dispex:version");
  if (version == nullptr) return ignore("not written by dispex");
  if (version->AsString() != Version()) {
    return ignore(fmt::format("written by dispex {}, not {}", version->AsString(), Version()));
  }
  const PtexMetaItem* keys = file->FindMetaData(kFaceKeysMetaKey);
  const int channels = vector ? 3 : 1;
  const PtexMetaItem* records = file->FindMetaData(FaceRecordsMetaKey(channels));
  if (keys == nullptr || records == nullptr) return ignore("has no face keys");
  if (file->header().num_channels != channels ||
      (file->header().data_type != PtexDataType::kFloat &&
       file->header().data_type != PtexDataType::kHalf)) {
    return ignore(vector ? "is not a three-channel float or half map"
                         : "is not a one-channel float or half map");
  }
  if (static_cast<std::size_t>(file->num_faces()) != num_faces) {
    return ignore(fmt::format("has {} faces, the base now {}", file->num_faces(), num_faces));
  }
  auto decoded_keys = DecodeFaceKeys(keys->bytes, num_faces);
  auto decoded_records = DecodeFaceRecords(records->bytes, num_faces, channels);
  if (!decoded_keys || !decoded_records) return ignore("has malformed face keys");
  out.keys_ = std::move(*decoded_keys);
  out.records_ = std::move(*decoded_records);
  if (const PtexMetaItem* steps = file->FindMetaData(kFirstRoundEdgeStepsMetaKey)) {
    out.first_round_edge_steps_ = steps->AsDouble();
    if (out.first_round_edge_steps_.size() != 8 * num_faces) out.first_round_edge_steps_.clear();
  }
  out.AddFile(std::move(*file));
  return out;
}

PreviousMap PreviousMap::FromParts(std::vector<ShardPart> parts,
                                   std::span<const std::int32_t> order) {
  const std::size_t num_faces = order.size();
  PreviousMap out;
  out.keys_.resize(num_faces);
  out.records_.resize(num_faces);
  out.part_of_.assign(num_faces, 0);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    ShardPart& part = parts[k];
    // OpenShardPart checked that they decode.
    const std::vector<Hash128> keys =
        *DecodeFaceKeys(part.file.FindMetaData(kFaceKeysMetaKey)->bytes, num_faces);
    const std::vector<FaceRecord> records =
        *DecodeFaceRecords(part.file.FindMetaData(kFaceRecordsMetaKey)->bytes, num_faces, 1);
    for (auto i = static_cast<std::size_t>(part.info.begin);
         i < static_cast<std::size_t>(part.info.end); ++i) {
      const auto f = static_cast<std::size_t>(order[i]);
      out.keys_[f] = keys[f];
      out.records_[f] = records[f];
      out.part_of_[f] = static_cast<std::uint32_t>(k);
    }
    out.AddFile(std::move(part.file));
  }
  return out;
}

void PreviousMap::AddFile(PtexFile file) {
  const PtexMetaItem* encoding = file.FindMetaData(kFaceEncodingMetaKey);
  encodings_.push_back(encoding != nullptr ? encoding->AsString() : "");
  files_.push_back(std::move(file));
}

void PreviousMap::CheckFaceData() {
  if (files_.size() != 1) return;  // none, or parts (OpenShardPart checks them)
  Status valid = CheckMapFaceData(files_[0]);
  if (valid.ok()) return;
  notice_ = fmt::format("{}: corrupt face data ({}); not re-used, every face is extracted",
                        files_[0].name(), valid.message());
  files_.clear();
}

std::string PreviousMap::MetaString(const std::string& key) const {
  if (files_.empty()) return "";
  const PtexMetaItem* item = files_[0].FindMetaData(key);
  return item ? item->AsString() : "";
}

bool PreviousMap::Reusable(std::size_t f, const Hash128& key) const {
  if (files_.empty() || keys_[f] != key) return false;
  const PtexFaceInfo& info = file(f).face_info(PtexFaceId(static_cast<int>(f)));
  const FaceStats& s = records_[f].stats;
  if (s.all_missed || s.samples == 0) return true;  // written from the neighbours, or a hole
  return info.ulog2 == s.ulog2 && info.vlog2 == s.vlog2;
}

void PreviousMap::KeepUnread(std::size_t f, KeptFace& out) const {
  const PtexFaceInfo& info = file(f).face_info(PtexFaceId(static_cast<int>(f)));
  out.ulog2 = info.ulog2;
  out.vlog2 = info.vlog2;
  out.kept = out.unread = true;
  out.texels.clear();
}

std::span<const double> PreviousMap::FirstRoundEdgeSteps(
    std::span<const PtexFaceInfo> faces) const {
  if (first_round_edge_steps_.empty() || files_.size() != 1) return {};
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const PtexFaceInfo& stored = files_[0].face_info(PtexFaceId(static_cast<int>(f)));
    if (stored.adjfaces != faces[f].adjfaces || stored.adjedges != faces[f].adjedges ||
        stored.subface != faces[f].subface) {
      return {};
    }
  }
  return first_round_edge_steps_;
}

Status PreviousMap::ReadTexels(std::size_t f, KeptFace& out) const {
  const PtexFaceId face(static_cast<int>(f));
  KeepUnread(f, out);
  out.unread = false;
  if (out.ulog2 == 0 && out.vlog2 == 0) {
    out.texels.resize(static_cast<std::size_t>(file(f).header().num_channels));
    file(f).ConstantValue(face, out.texels.data());
    return Status::Ok();
  }
  return file(f).ReadFace(face, 0, out.texels);
}

}  // namespace dispex::extract
