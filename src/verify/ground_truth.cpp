// The ground-truth file written beside a generated sculpt (format in include/dispex/verify.h).
#include <fmt/format.h>

#include <cstring>

#include "core/atomic_output.h"
#include "core/mapped_file.h"
#include "dispex/verify.h"

namespace dispex {

namespace {
constexpr char kMagic[8] = {'D', 'I', 'S', 'P', 'E', 'X', 'G', 'T'};
constexpr std::size_t kHeader = 24, kRecordV1 = 16, kRecordV2 = 20, kRecordV3 = 32;
constexpr std::size_t kRecordSize[4] = {0, kRecordV1, kRecordV2, kRecordV3};
}  // namespace

Status WriteGroundTruth(const std::string& path, const GroundTruth& truth) {
  if (!truth.local_error.empty() && truth.local_error.size() != truth.size()) {
    return Status::Error(fmt::format("{}: {} local errors for {} records", path,
                                     truth.local_error.size(), truth.size()));
  }
  if (!truth.d.empty() && truth.d.size() != 3 * truth.size()) {
    return Status::Error(fmt::format("{}: {} displacement values for {} records (3 each)", path,
                                     truth.d.size(), truth.size()));
  }
  if (!truth.d.empty() && truth.local_error.empty()) {
    return Status::Error(path + ": a truth with displacements (version 3) needs local errors");
  }
  if (truth.faces.size() != truth.size() || truth.uvs.size() != 2 * truth.size()) {
    return Status::Error(fmt::format("{}: {} faces and {} uv values for {} records", path,
                                     truth.faces.size(), truth.uvs.size(), truth.size()));
  }
  const std::uint32_t version = static_cast<std::uint32_t>(truth.version()), zero = 0;
  const bool v2 = version >= 2, v3 = version == 3;
  const std::size_t record_size = kRecordSize[version];
  std::uint64_t count = truth.size();
  DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(path));
  DISPEX_RETURN_IF_ERROR(out.Write(kMagic, 8));
  DISPEX_RETURN_IF_ERROR(out.Write(&version, 4));
  DISPEX_RETURN_IF_ERROR(out.Write(&zero, 4));
  DISPEX_RETURN_IF_ERROR(out.Write(&count, 8));
  std::vector<char> buffer;
  constexpr std::size_t kChunk = 1 << 16;
  for (std::size_t start = 0; start < count; start += kChunk) {
    std::size_t end = std::min<std::size_t>(count, start + kChunk);
    buffer.resize((end - start) * record_size);
    char* p = buffer.data();
    for (std::size_t i = start; i < end; ++i, p += record_size) {
      std::int32_t face = truth.faces[i].value;
      std::memcpy(p, &face, 4);
      std::memcpy(p + 4, &truth.uvs[2 * i], 8);
      std::memcpy(p + 12, &truth.h[i], 4);
      if (v2) std::memcpy(p + 16, &truth.local_error[i], 4);
      if (v3) std::memcpy(p + 20, &truth.d[3 * i], 12);
    }
    DISPEX_RETURN_IF_ERROR(out.Write(buffer.data(), buffer.size()));
  }
  return out.Commit();
}

StatusOr<GroundTruth> ReadGroundTruth(const std::string& path) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  if (file.size() < kHeader || std::memcmp(file.data(), kMagic, 8) != 0) {
    return Status::Error(path + ": not a dispex ground-truth file (bad magic)");
  }
  std::uint32_t version = 0;
  std::uint64_t count = 0;
  std::memcpy(&version, file.data() + 8, 4);
  std::memcpy(&count, file.data() + 16, 8);
  if (version < 1 || version > 3) {
    return Status::Error(fmt::format("{}: unsupported version {} (1..3)", path, version));
  }
  const std::size_t record_size = kRecordSize[version];
  if (count > (file.size() - kHeader) / record_size ||
      kHeader + count * record_size != file.size()) {
    return Status::Error(fmt::format("{}: {} records claimed but the file holds {} bytes", path,
                                     count, file.size()));
  }
  GroundTruth truth;
  truth.faces.resize(count);
  truth.uvs.resize(2 * count);
  truth.h.resize(count);
  if (version >= 2) truth.local_error.resize(count);
  if (version == 3) truth.d.resize(3 * count);
  const char* p = file.data() + kHeader;
  for (std::size_t i = 0; i < count; ++i, p += record_size) {
    std::int32_t face;
    std::memcpy(&face, p, 4);
    truth.faces[i] = PtexFaceId(face);
    std::memcpy(&truth.uvs[2 * i], p + 4, 8);
    std::memcpy(&truth.h[i], p + 12, 4);
    if (version >= 2) std::memcpy(&truth.local_error[i], p + 16, 4);
    if (version == 3) std::memcpy(&truth.d[3 * i], p + 20, 12);
  }
  return truth;
}

}  // namespace dispex
