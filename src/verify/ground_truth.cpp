// The ground-truth file written beside a generated sculpt (format in include/dispex/verify.h).
#include <fmt/format.h>

#include <cstring>

#include "core/atomic_output.h"
#include "core/mapped_file.h"
#include "dispex/verify.h"

namespace dispex {

namespace {
constexpr char kMagic[8] = {'D', 'I', 'S', 'P', 'E', 'X', 'G', 'T'};
constexpr std::size_t kHeader = 24, kRecord = 16;
}  // namespace

Status WriteGroundTruth(const std::string& path, const GroundTruth& truth) {
  DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(path));
  std::uint32_t version = 1, zero = 0;
  std::uint64_t count = truth.size();
  DISPEX_RETURN_IF_ERROR(out.Write(kMagic, 8));
  DISPEX_RETURN_IF_ERROR(out.Write(&version, 4));
  DISPEX_RETURN_IF_ERROR(out.Write(&zero, 4));
  DISPEX_RETURN_IF_ERROR(out.Write(&count, 8));
  std::vector<char> buffer;
  constexpr std::size_t kChunk = 1 << 16;
  for (std::size_t start = 0; start < count; start += kChunk) {
    std::size_t end = std::min<std::size_t>(count, start + kChunk);
    buffer.resize((end - start) * kRecord);
    char* p = buffer.data();
    for (std::size_t i = start; i < end; ++i, p += kRecord) {
      std::int32_t face = truth.faces[i].value;
      std::memcpy(p, &face, 4);
      std::memcpy(p + 4, &truth.uvs[2 * i], 8);
      std::memcpy(p + 12, &truth.h[i], 4);
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
  if (version != 1) return Status::Error(fmt::format("{}: unsupported version {}", path, version));
  if (count > (file.size() - kHeader) / kRecord || kHeader + count * kRecord != file.size()) {
    return Status::Error(fmt::format("{}: {} records claimed but the file holds {} bytes", path,
                                     count, file.size()));
  }
  GroundTruth truth;
  truth.faces.resize(count);
  truth.uvs.resize(2 * count);
  truth.h.resize(count);
  const char* p = file.data() + kHeader;
  for (std::size_t i = 0; i < count; ++i, p += kRecord) {
    std::int32_t face;
    std::memcpy(&face, p, 4);
    truth.faces[i] = PtexFaceId(face);
    std::memcpy(&truth.uvs[2 * i], p + 4, 8);
    std::memcpy(&truth.h[i], p + 12, 4);
  }
  return truth;
}

}  // namespace dispex
