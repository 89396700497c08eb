#include "extract/previous_map.h"

#include <fmt/format.h>

#include <filesystem>

#include "dispex/version.h"

namespace dispex::extract {

PreviousMap PreviousMap::Open(const std::string& path, std::size_t num_faces) {
  PreviousMap out;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return out;
  auto ignore = [&](const std::string& why) {
    out.notice_ = fmt::format("{}: {}; not re-used, every face is extracted", path, why);
    out.file_.reset();
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
  const PtexMetaItem* records = file->FindMetaData(kFaceRecordsMetaKey);
  if (keys == nullptr || records == nullptr) return ignore("has no face keys");
  if (file->header().num_channels != 1 || (file->header().data_type != PtexDataType::kFloat &&
                                           file->header().data_type != PtexDataType::kHalf)) {
    return ignore("is not a one-channel float or half map");
  }
  if (static_cast<std::size_t>(file->num_faces()) != num_faces) {
    return ignore(fmt::format("has {} faces, the base now {}", file->num_faces(), num_faces));
  }
  auto decoded_keys = DecodeFaceKeys(keys->bytes, num_faces);
  auto decoded_records = DecodeFaceRecords(records->bytes, num_faces);
  if (!decoded_keys || !decoded_records) return ignore("has malformed face keys");
  out.keys_ = std::move(*decoded_keys);
  out.records_ = std::move(*decoded_records);
  out.file_.emplace(std::move(*file));
  return out;
}

std::string StoredInputsKey(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return "";
  StatusOr<PtexFile> file = PtexFile::Open(path);
  if (!file.ok()) return "";
  const PtexMetaItem* version = file->FindMetaData("dispex:version");
  const PtexMetaItem* key = file->FindMetaData(kInputsKeyMetaKey);
  if (version == nullptr || key == nullptr || version->AsString() != Version()) {
    return "";
  }
  return key->AsString();
}

void PreviousMap::CheckFaceData() {
  if (!file_) return;
  Status valid = file_->Validate();
  if (valid.ok()) return;
  notice_ = fmt::format("{}: corrupt face data ({}); not re-used, every face is extracted",
                        file_->name(), valid.message());
  file_.reset();
}

std::string PreviousMap::MetaString(const std::string& key) const {
  if (!file_) return "";
  const PtexMetaItem* item = file_->FindMetaData(key);
  return item ? item->AsString() : "";
}

bool PreviousMap::Reusable(std::size_t f, const Hash128& key) const {
  if (!file_ || keys_[f] != key) return false;
  const FaceStats& s = records_[f].stats;
  if (s.all_missed || s.samples == 0) return true;  // written from the neighbours, or a hole
  const PtexFaceInfo& info = file_->face_info(PtexFaceId(static_cast<int>(f)));
  return info.ulog2 == s.ulog2 && info.vlog2 == s.vlog2;
}

Status PreviousMap::ReadTexels(std::size_t f, KeptFace& out) const {
  const PtexFaceId face(static_cast<int>(f));
  const PtexFaceInfo& info = file_->face_info(face);
  out.ulog2 = info.ulog2;
  out.vlog2 = info.vlog2;
  out.kept = true;
  if (info.ulog2 == 0 && info.vlog2 == 0) {
    out.texels.resize(1);
    file_->ConstantValue(face, out.texels.data());
    return Status::Ok();
  }
  return file_->ReadFace(face, 0, out.texels);
}

}  // namespace dispex::extract
