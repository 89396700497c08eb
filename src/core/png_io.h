// PNG images (libpng), read and written, for every module that takes or makes one: reading
// for dispex::render's ReadPng (8-bit RGB pictures) and dispex::verify's height images (grey
// or colour, 8 or 16 bits), writing of 8-bit RGB or grey pixels for render's EncodePng and
// WritePng. libpng is linked PRIVATE to dispex_core; no libpng type appears here.
//
// Hostile files give a Status, never a crash or an unbounded allocation: libpng's errors are
// caught (setjmp), widths and heights above 2^20 and images above 2^28 pixels are refused, and
// so is an image whose raw scanlines could not fit in the file even at deflate's largest
// compression ratio (1032:1), before any pixel memory is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "dispex/status.h"

namespace dispex {

enum class PngConversion : std::uint8_t {
  // 8-bit RGB: palettes and grey expanded, 16-bit samples cut to their high byte (libpng's
  // png_set_strip_16), alpha and tRNS dropped.
  kRgb8,
  // The file's own channels and depth: grey (1), grey + alpha (2), RGB (3) or RGBA (4);
  // palettes expanded to RGB (RGBA with a tRNS chunk), grey with a tRNS chunk to grey + alpha,
  // grey of 1, 2 or 4 bits scaled to 8 bits (a 1-bit 1 becomes 255); 8 or 16 bits per sample.
  kNative,
};

struct PngPixels {
  int width = 0, height = 0;
  int channels = 0;   // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
  int bit_depth = 0;  // 8 or 16
  // Rows from the top of the image, samples interleaved; 16-bit samples in host byte order.
  std::vector<std::uint8_t> data;

  std::size_t samples_per_row() const { return std::size_t(width) * std::size_t(channels); }
  // Sample `c` of pixel (x, y), y counted from the top row; 0..255 or 0..65535.
  std::uint32_t sample(int x, int y, int c) const {
    const std::size_t i = std::size_t(y) * samples_per_row() + std::size_t(x) * channels + c;
    if (bit_depth == 8) return data[i];
    std::uint16_t s;
    std::memcpy(&s, data.data() + 2 * i, 2);
    return s;
  }
};

// Decodes a whole PNG file held in memory. `name` starts every error message:
// "<name>: not a PNG file (bad signature)", "<name>: cannot read PNG: <libpng's reason>".
StatusOr<PngPixels> DecodePngPixels(const std::uint8_t* data, std::size_t size,
                                    const std::string& name, PngConversion conversion);

// The same for a file (memory-mapped); errors name `path`.
StatusOr<PngPixels> ReadPngPixels(const std::string& path, PngConversion conversion);

// Encodes width x height 8-bit pixels of `channels` samples (1 grey, 3 RGB), rows from the
// top, samples interleaved, `size` bytes at `data`, as a PNG in memory (zlib level 6, no
// interlacing, default filters). Fails for an empty image, other channel counts, more than
// 2^31 - 1 bytes of pixels, or a `size` other than width * height * channels.
StatusOr<std::vector<std::uint8_t>> EncodePngPixels(const std::uint8_t* data, std::size_t size,
                                                    int width, int height, int channels);

// Encodes as EncodePngPixels does and writes the PNG to `path` atomically (AtomicOutput: the
// file appears whole or not at all). Encoding errors are prefixed with `path`.
Status WritePngPixels(const std::string& path, const std::uint8_t* data, std::size_t size,
                      int width, int height, int channels);

}  // namespace dispex
