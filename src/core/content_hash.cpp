#include "core/content_hash.h"

#include <fmt/format.h>
#include <libdeflate.h>

#include "core/mapped_file.h"

namespace dispex {

std::uint32_t Crc32(std::string_view bytes) {
  return libdeflate_crc32(0, bytes.data(), bytes.size());
}

StatusOr<std::string> FileFingerprint(const std::string& path) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  return fmt::format("crc32:{:08x} size:{}", Crc32(file.view()), file.size());
}

}  // namespace dispex
