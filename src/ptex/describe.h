// The value formatting behind dispex/ptex_describe.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dispex/ptex.h"
#include "dispex/ptex_describe.h"

namespace dispex::ptex {

// The value of a meta data item: a quoted string or numbers (exact), "... (N values)" when
// cut after `max_values`.
std::string FormatMetaValue(const PtexMetaItem& item, std::size_t max_values);

// One value of the file's data type at `p`, exact: integers as integers, half and float as
// the shortest decimal that reads back to the same value.
std::string FormatRawValue(const std::uint8_t* p, PtexDataType type);

}  // namespace dispex::ptex
