// Image to and from PNG through dispex::core's PNG module (core/png_io.h): images are written
// as 8-bit RGB and read converted to 8-bit RGB.
#include "core/png_io.h"

#include <utility>
#include <vector>

#include "dispex/render.h"

namespace dispex {

StatusOr<std::vector<std::uint8_t>> EncodePng(const Image& image) {
  return EncodePngPixels(image.rgb.data(), image.rgb.size(), image.width, image.height, 3);
}

Status WritePng(const std::string& path, const Image& image) {
  return WritePngPixels(path, image.rgb.data(), image.rgb.size(), image.width, image.height, 3);
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
