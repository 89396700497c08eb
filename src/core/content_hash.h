// CRC-32 checksums (shape file names).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dispex/status.h"

namespace dispex {

// CRC-32 (IEEE, as zlib computes it) of the bytes, via libdeflate's accelerated routine.
std::uint32_t Crc32(std::string_view bytes);

}  // namespace dispex
