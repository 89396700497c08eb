// The zlib streams of a Ptex file (RFC 1950; every block its own stream, docs/ptex.md,
// "zlib blocks"):
// compression with libdeflate or zlib, and inflation with libdeflate into a buffer of the
// exact expected size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dispex/ptex.h"

namespace dispex::ptex {

// The compressor and its library's version ("libdeflate 1.14", "zlib 1.2.13"): other versions
// may deflate the same data into other bytes.
std::string CompressorName(PtexCompressor compressor);
// The level used for `level` = -1.
int DefaultCompressionLevel(PtexCompressor compressor);
// Empty when `level` is valid for the compressor, else the reason.
std::string CheckCompressionLevel(PtexCompressor compressor, int level);

// At libdeflate's fastest level (1, the default), data this short is stored (level 0): each call
// at level 1 first clears the compressor's hash tables, about 5 us (libdeflate 1.14), which is
// more than what deflating a few hundred bytes of float texels saves (docs/bench-notes/extract.md,
// "Compression"). The small reductions of every face are such blocks.
inline constexpr std::size_t kStoredBelow = 512;

// Appends one complete zlib stream holding `data` to `out`; returns its size in bytes.
// Deterministic: the same input, compressor and level give the same bytes. Uses a
// per-thread compressor, so it is safe to call from several threads.
std::size_t CompressAppend(std::span<const std::uint8_t> data, PtexCompressor compressor, int level,
                           std::vector<std::uint8_t>& out);

// Inflates the zlib stream `in` into exactly `out.size()` bytes. Returns an empty string on
// success, else what is wrong: a corrupt stream, or one that inflates to a different size,
// or bytes left after the stream's end.
std::string Inflate(std::span<const std::uint8_t> in, std::span<std::uint8_t> out);

}  // namespace dispex::ptex
