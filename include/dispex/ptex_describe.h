// Text descriptions of a Ptex file, as `dispex info` prints them: a summary, one line per
// face, the texels of a face, and a structural dump of everything the file stores except
// compressed sizes (so it does not depend on the compressor; the golden tests compare it).
#pragma once

#include <cstddef>
#include <string>

#include "dispex/ptex.h"

namespace dispex {

// Whether the file at `path` starts with the Ptex magic ("Ptex"); false when it cannot be read.
bool HasPtexMagic(const std::string& path);

// The summary as JSON, pretty-printed (2 spaces, no final newline): header, face and texel
// counts, levels, border modes, meta data (arrays cut after 64 values, flagged "truncated"),
// and with `with_faces` a face_list (resolution, flags, adjacency, average).
std::string PtexSummaryJson(const PtexFile& file, bool with_faces);

// Header, levels, border modes, meta data (arrays cut after `max_values` values), texel
// counts, size on disk.
std::string FormatPtexSummary(const PtexFile& file, std::size_t max_values = 8);

// One line per face: id, resolution, flags, adjacency, min / max / average per channel.
Status FormatPtexFaces(const PtexFile& file, std::string& out);

// The level-0 texels of a face, one row (v) per line from v = 0, channels grouped in ().
Status FormatPtexTexels(const PtexFile& file, PtexFaceId face, std::string& out);

// Header fields (no sizes), face records, constant data, each level's entries in stored
// order with encodings and tiling, meta data, and every stored block's texels, all values
// exact. Golden tests compare it with checked-in dumps.
Status FormatPtexStructure(const PtexFile& file, std::string& out);

}  // namespace dispex
