// PNG in and out through libpng's stream API (png_set_write_fn / png_set_read_fn over memory),
// following the libpng manual (libpng-manual.txt, "IV. Writing" and "III. Reading"). libpng
// reports errors by longjmp: the functions that call setjmp below hold no object with a
// destructor, and every buffer they fill belongs to their caller.
#include <fmt/format.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "core/atomic_output.h"
#include "core/mapped_file.h"
#include "dispex/render.h"

namespace dispex {

namespace {

constexpr std::size_t kMaxReadPixels = std::size_t{1} << 28;

struct PngError {
  char message[256] = {0};
};

void OnError(png_structp png, png_const_charp message) {
  auto* error = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(error->message, sizeof error->message, "%s", message ? message : "error");
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}

void AppendBytes(png_structp png, png_bytep data, png_size_t size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}

void NoFlush(png_structp) {}

bool EncodeRows(int width, int height, png_bytep* rows, std::vector<std::uint8_t>* out,
                PngError* error) {
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
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

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

// Decodes into `image` (resized here) through `rows` (row pointers, resized here).
bool DecodeRows(ReadSource* source, Image* image, std::vector<png_bytep>* rows, PngError* error) {
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
  png_set_user_limits(png, 1u << 20, 1u << 20);
  png_read_info(png, info);
  const png_uint_32 width = png_get_image_width(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  if (std::size_t{width} * height > kMaxReadPixels) {
    png_error(png, "image is larger than 2^28 pixels");
  }
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != 3 * std::size_t{width}) {
    png_error(png, "unexpected row size after conversion to RGB");
  }
  image->width = static_cast<int>(width);
  image->height = static_cast<int>(height);
  image->rgb.resize(3 * std::size_t{width} * height);
  rows->resize(height);
  for (png_uint_32 y = 0; y < height; ++y) {
    (*rows)[y] = image->rgb.data() + 3 * std::size_t{width} * y;
  }
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

StatusOr<std::vector<std::uint8_t>> EncodePng(const Image& image) {
  if (image.width <= 0 || image.height <= 0) {
    return Status::Error(
        fmt::format("cannot encode an empty {}x{} image as PNG", image.width, image.height));
  }
  const std::size_t bytes = 3 * std::size_t(image.width) * std::size_t(image.height);
  if (bytes > 0x7fffffffu) {
    return Status::Error(
        fmt::format("image {}x{} is too large for PNG encoding", image.width, image.height));
  }
  if (image.rgb.size() != bytes) {
    return Status::Error(fmt::format("image {}x{} holds {} bytes, expected {}", image.width,
                                     image.height, image.rgb.size(), bytes));
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
  for (int y = 0; y < image.height; ++y) {
    // libpng takes non-const row pointers but only reads them when writing.
    rows[static_cast<std::size_t>(y)] =
        const_cast<png_bytep>(image.rgb.data() + 3 * std::size_t(image.width) * std::size_t(y));
  }
  std::vector<std::uint8_t> out;
  out.reserve(bytes / 4 + 1024);
  PngError error;
  if (!EncodeRows(image.width, image.height, rows.data(), &out, &error)) {
    return Status::Error(std::string("PNG encoding failed: ") + error.message);
  }
  return out;
}

Status WritePng(const std::string& path, const Image& image) {
  auto bytes = EncodePng(image);
  if (!bytes.ok()) return bytes.status().WithPrefix(path);
  return WriteFileAtomically(path, bytes->data(), bytes->size());
}

StatusOr<Image> DecodePng(const std::uint8_t* data, std::size_t size, const std::string& name) {
  if (size < 8 || png_sig_cmp(data, 0, 8) != 0) {
    return Status::Error(name + ": not a PNG file (bad signature)");
  }
  ReadSource source{data, size, 0};
  Image image;
  std::vector<png_bytep> rows;
  PngError error;
  if (!DecodeRows(&source, &image, &rows, &error)) {
    return Status::Error(name + ": cannot read PNG: " + error.message);
  }
  return image;
}

StatusOr<Image> ReadPng(const std::string& path) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  return DecodePng(reinterpret_cast<const std::uint8_t*>(file.data()), file.size(), path);
}

}  // namespace dispex
