// Text descriptions of a Ptex file, shared by `dispex info` and the golden tests: a
// summary, one line per face, the texels of a face, and a structural dump of everything the
// file stores except compressed sizes (so it does not depend on the compressor).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "dispex/ptex.h"

namespace dispex::ptex {

// Header, levels, border modes, meta data (arrays cut after `max_values` values), texel
// counts, size on disk.
std::string FormatPtexSummary(const PtexFile& file, std::size_t max_values = 8);

// The value of a meta data item: a quoted string or numbers (exact), "... (N values)" when
// cut after `max_values`.
std::string FormatMetaValue(const PtexMetaItem& item, std::size_t max_values);

// One line per face: id, resolution, flags, adjacency, min / max / average per channel.
Status FormatPtexFaces(const PtexFile& file, std::string& out);

// The level-0 texels of a face, one row (v) per line from v = 0, channels grouped in ().
Status FormatPtexTexels(const PtexFile& file, PtexFaceId face, std::string& out);

// Header fields (no sizes), face records, constant data, each level's entries in stored
// order with encodings and tiling, meta data, and every stored block's texels, all values
// exact. Golden tests compare it with checked-in dumps.
Status FormatPtexStructure(const PtexFile& file, std::string& out);

// One value of the file's data type at `p`, exact: integers as integers, half and float as
// the shortest decimal that reads back to the same value.
std::string FormatRawValue(const std::uint8_t* p, PtexDataType type);

}  // namespace dispex::ptex
