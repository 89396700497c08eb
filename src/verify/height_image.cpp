// Height images: PNG luminance (Rec. 709 weights, ITU-R BT.709-6 item 3.2: Y = 0.2126 R +
// 0.7152 G + 0.0722 B) read with bilinear filtering and repeat wrapping, as a renderer's
// texture lookup with GL_LINEAR / GL_REPEAT does (OpenGL 4.6 core, 8.14.2).
#include "verify/height_image.h"

#include <cmath>

namespace dispex::verify {

HeightImage HeightImage::FromPixels(const PngPixels& pixels) {
  HeightImage image;
  image.width_ = pixels.width;
  image.height_ = pixels.height;
  image.luminance_.resize(std::size_t(pixels.width) * std::size_t(pixels.height));
  const double scale = pixels.bit_depth == 16 ? 1.0 / 65535.0 : 1.0 / 255.0;
  const bool colour = pixels.channels >= 3;
  for (int y = 0; y < pixels.height; ++y) {
    float* row = image.luminance_.data() + std::size_t(pixels.height - 1 - y) * pixels.width;
    for (int x = 0; x < pixels.width; ++x) {
      double l;
      if (colour) {
        l = 0.2126 * pixels.sample(x, y, 0) + 0.7152 * pixels.sample(x, y, 1) +
            0.0722 * pixels.sample(x, y, 2);
      } else {
        l = pixels.sample(x, y, 0);
      }
      row[x] = static_cast<float>(l * scale);
    }
  }
  return image;
}

StatusOr<HeightImage> HeightImage::Read(const std::string& path) {
  DISPEX_ASSIGN_OR_RETURN(PngPixels pixels, ReadPngPixels(path, PngConversion::kNative));
  return FromPixels(pixels);
}

double HeightImage::Sample(double s, double t) const {
  // Wrap to [0, 1] first (s - floor(s) may round up to 1), so the pixel indices below stay
  // within [-1, size] for any finite input.
  const double x = (s - std::floor(s)) * width_ - 0.5;
  const double y = (t - std::floor(t)) * height_ - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  auto wrap = [](int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); };
  const int x0 = wrap(static_cast<int>(fx), width_), x1 = wrap(static_cast<int>(fx) + 1, width_);
  const int y0 = wrap(static_cast<int>(fy), height_), y1 = wrap(static_cast<int>(fy) + 1, height_);
  const double bottom = (1 - ax) * at(x0, y0) + ax * at(x1, y0);
  const double top = (1 - ax) * at(x0, y1) + ax * at(x1, y1);
  return (1 - ay) * bottom + ay * top;
}

}  // namespace dispex::verify
