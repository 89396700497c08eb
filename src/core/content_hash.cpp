#include "core/content_hash.h"

#include <fmt/format.h>
#include <libdeflate.h>

namespace dispex {

std::uint32_t Crc32(std::string_view bytes) {
  return libdeflate_crc32(0, bytes.data(), bytes.size());
}

}  // namespace dispex
