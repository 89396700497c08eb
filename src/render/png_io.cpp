// PNG out through libpng's stream API (png_set_write_fn over memory), following the libpng
// manual (libpng-manual.txt, "IV. Writing"); PNG in through dispex::core's reader
// (core/png_read.h), converted to 8-bit RGB. libpng reports errors by longjmp: the function
// that calls setjmp below holds no object with a destructor, and every buffer it fills
// belongs to its caller.
#include <fmt/format.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

#include "core/atomic_output.h"
#include "core/png_read.h"
#include "dispex/render.h"

namespace dispex {

namespace {

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
  DISPEX_ASSIGN_OR_RETURN(PngPixels pixels,
                          DecodePngPixels(data, size, name, PngConversion::kRgb8));
  Image image;
  image.width = pixels.width;
  image.height = pixels.height;
  image.rgb = std::move(pixels.data);
  return image;
}

StatusOr<Image> ReadPng(const std::string& path) {
  DISPEX_ASSIGN_OR_RETURN(PngPixels pixels, ReadPngPixels(path, PngConversion::kRgb8));
  Image image;
  image.width = pixels.width;
  image.height = pixels.height;
  image.rgb = std::move(pixels.data);
  return image;
}

}  // namespace dispex
