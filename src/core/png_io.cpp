// PNG decoding and encoding through libpng's stream API over memory (png_set_read_fn,
// png_set_write_fn), following the libpng manual (libpng-manual.txt, "III. Reading";
// transformations in "Transformations you can do"; "IV. Writing"). libpng reports errors by
// longjmp: DecodeRows and EncodeRows, which call setjmp, hold no object with a destructor,
// and every buffer they fill belongs to their caller.
#include "core/png_io.h"

#include <fmt/format.h>
#include <png.h>

#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include "core/mapped_file.h"
#include "dispex/files.h"

namespace dispex {

namespace {

constexpr std::size_t kMaxPixels = std::size_t{1} << 28;
constexpr png_uint_32 kMaxSide = png_uint_32{1} << 20;
// Deflate encodes at most 258 bytes in 2 bits: no zlib stream inflates by more than 1032:1.
constexpr std::size_t kMaxInflateRatio = 1032;

struct PngError {
  char message[256] = {0};
};

// Keeps libpng's message on one printable line (it may quote chunk bytes from the file).
void OnError(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message ? message : "error");
  for (char& c : error->message) {
    if (c != 0 && (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f)) {
      c = '?';
    }
  }
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}

struct ReadSource {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::size_t position = 0;
};

void ReadBytes(png_structp png, png_bytep out, png_size_t size) {
  auto* source = static_cast<ReadSource*>(png_get_io_ptr(png));
  if (size > source->size - source->position) png_error(png, "file is truncated");
  std::memcpy(out, source->data + source->position, size);
  source->position += size;
}

void SetTransforms(png_structp png, png_infop info, PngConversion conversion) {
  png_set_expand(png);  // palette -> RGB, grey < 8 bits -> 8 bits, tRNS -> alpha
  png_set_interlace_handling(png);
  if (conversion == PngConversion::kRgb8) {
    png_set_strip_16(png);
    png_set_strip_alpha(png);
    png_set_gray_to_rgb(png);
    return;
  }
  if (png_get_bit_depth(png, info) == 16 && std::endian::native == std::endian::little) {
    png_set_swap(png);  // PNG stores 16-bit samples big-endian; keep host order
  }
}

// Decodes into `pixels` (data resized here) through `rows` (row pointers, resized here).
bool DecodeRows(ReadSource* source, PngConversion conversion, PngPixels* pixels,
                std::vector<png_bytep>* rows, PngError* error) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, error, OnError, OnWarning);
  if (png == nullptr) {
    std::snprintf(error->message, sizeof error->message, "cannot create a libpng reader");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(error->message, sizeof error->message, "cannot create a libpng reader");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, source, ReadBytes);
  png_set_user_limits(png, kMaxSide, kMaxSide);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  if (std::size_t{width} * height > kMaxPixels) {
    png_error(png, "image is larger than 2^28 pixels");
  }
  // The file's own scanlines (one filter byte each): more than the file could inflate to
  // means a truncated or forged header; refuse it before allocating the pixels.
  const std::size_t raw_bytes = std::size_t{height} * (png_get_rowbytes(png, info) + 1);
  if (raw_bytes / kMaxInflateRatio > source->size + 1024) {
    png_error(png, "image data cannot fit in the file (truncated, or a forged size)");
  }
  SetTransforms(png, info, conversion);
  png_read_update_info(png, info);
  const int channels = png_get_channels(png, info);
  const int depth = png_get_bit_depth(png, info);
  if (depth != 8 && depth != 16) png_error(png, "unexpected sample depth after conversion");
  if ((conversion == PngConversion::kRgb8 && (channels != 3 || depth != 8)) || channels < 1 ||
      channels > 4) {
    png_error(png, "unexpected channels after conversion");
  }
  const std::size_t row_bytes = std::size_t{width} * channels * (depth / 8);
  if (png_get_rowbytes(png, info) != row_bytes) {
    png_error(png, "unexpected row size after conversion");
  }
  pixels->width = static_cast<int>(width);
  pixels->height = static_cast<int>(height);
  pixels->channels = channels;
  pixels->bit_depth = depth;
  pixels->data.resize(row_bytes * height);
  rows->resize(height);
  for (png_uint_32 y = 0; y < height; ++y) {
    (*rows)[y] = pixels->data.data() + row_bytes * y;
  }
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

void AppendBytes(png_structp png, png_bytep data, png_size_t size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}

void NoFlush(png_structp) {}

bool EncodeRows(int width, int height, int color_type, png_bytep* rows,
                std::vector<std::uint8_t>* out, PngError* error) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, error, OnError, OnWarning);
  if (png == nullptr) {
    std::snprintf(error->message, sizeof error->message, "cannot create a libpng writer");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(error->message, sizeof error->message, "cannot create a libpng writer");
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, out, AppendBytes, NoFlush);
  // zlib level 6: on a 1042x1359 atlas 9% larger than level 9 and 12x faster
  // (docs/bench-notes/render.md).
  png_set_compression_level(png, 6);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

StatusOr<PngPixels> DecodePngPixels(const std::uint8_t* data, std::size_t size,
                                    const std::string& name, PngConversion conversion) {
  if (size < 8 || png_sig_cmp(data, 0, 8) != 0) {
    return Status::Error(name + ": not a PNG file (bad signature)");
  }
  ReadSource source{data, size, 0};
  PngPixels pixels;
  std::vector<png_bytep> rows;
  PngError error;
  if (!DecodeRows(&source, conversion, &pixels, &rows, &error)) {
    return Status::Error(name + ": cannot read PNG: " + error.message);
  }
  return pixels;
}

StatusOr<PngPixels> ReadPngPixels(const std::string& path, PngConversion conversion) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  return DecodePngPixels(reinterpret_cast<const std::uint8_t*>(file.data()), file.size(), path,
                         conversion);
}

StatusOr<std::vector<std::uint8_t>> EncodePngPixels(const std::uint8_t* data, std::size_t size,
                                                    int width, int height, int channels) {
  if (width <= 0 || height <= 0) {
    return Status::Error(fmt::format("cannot encode an empty {}x{} image as PNG", width, height));
  }
  if (channels != 1 && channels != 3) {
    return Status::Error(
        fmt::format("cannot encode {} channels as PNG (1 grey or 3 RGB)", channels));
  }
  const std::size_t row_bytes = std::size_t(channels) * std::size_t(width);
  const std::size_t bytes = row_bytes * std::size_t(height);
  if (bytes > 0x7fffffffu) {
    return Status::Error(fmt::format("image {}x{} is too large for PNG encoding", width, height));
  }
  if (size != bytes) {
    return Status::Error(
        fmt::format("image {}x{} holds {} bytes, expected {}", width, height, size, bytes));
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    // libpng takes non-const row pointers but only reads them when writing.
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(data + row_bytes * std::size_t(y));
  }
  std::vector<std::uint8_t> out;
  out.reserve(bytes / 4 + 1024);
  PngError error;
  const int color_type = channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB;
  if (!EncodeRows(width, height, color_type, rows.data(), &out, &error)) {
    return Status::Error(std::string("PNG encoding failed: ") + error.message);
  }
  return out;
}

Status WritePngPixels(const std::string& path, const std::uint8_t* data, std::size_t size,
                      int width, int height, int channels) {
  auto bytes = EncodePngPixels(data, size, width, height, channels);
  if (!bytes.ok()) return bytes.status().WithPrefix(path);
  return WriteFileAtomically(path, bytes->data(), bytes->size());
}

}  // namespace dispex
