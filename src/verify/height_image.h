// The height image of the image pattern (Pattern::kImage in dispex/verify.h): a PNG's
// luminance per pixel, sampled bilinearly with wrapping at texture coordinates.
#pragma once

#include <string>
#include <vector>

#include "core/png_io.h"
#include "dispex/status.h"

namespace dispex::verify {

class HeightImage {
 public:
  // Reads the PNG at `path` (errors name it, see core/png_io.h) and converts it.
  static StatusOr<HeightImage> Read(const std::string& path);
  // Luminance of decoded pixels (PngConversion::kNative): grey / max, or Rec. 709 weights
  // 0.2126 R + 0.7152 G + 0.0722 B on the stored values / max (max 255 or 65535); alpha is
  // ignored. No gamma decoding: the stored value is the height.
  static HeightImage FromPixels(const PngPixels& pixels);

  int width() const { return width_; }
  int height() const { return height_; }
  // L of pixel (i, j), j counted from the BOTTOM row (j = 0 is the image's last row).
  float at(int i, int j) const { return luminance_[std::size_t(j) * std::size_t(width_) + i]; }

  // L at texture coordinates (s, t), t = 0 at the bottom: bilinear between the four nearest
  // pixel centres (pixel (i, j) centred at ((i + 0.5) / width, (j + 0.5) / height)), repeating
  // outside [0, 1). s and t must be finite. No allocation; safe from any number of threads.
  double Sample(double s, double t) const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> luminance_;  // rows from the bottom, i fastest
};

}  // namespace dispex::verify
