// Content hashes that identify input files in a map's meta data and reports.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dispex/status.h"

namespace dispex {

// CRC-32 (IEEE, as zlib computes it) of the bytes, via libdeflate's accelerated routine.
std::uint32_t Crc32(std::string_view bytes);

// "crc32:1a2b3c4d size:12345" for a file, read through a memory map.
StatusOr<std::string> FileFingerprint(const std::string& path);

}  // namespace dispex
