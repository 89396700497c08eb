#include "spectral/block_shape.h"

#include <fmt/format.h>

#include <bit>

#include "dispex/spectral.h"

namespace dispex::spectral {

StatusOr<BlockShape> MakeBlockShape(int nx, int ny) {
  for (int n : {nx, ny}) {
    if (n < 1 || n > kMaxSpectralSize || !std::has_single_bit(static_cast<unsigned>(n))) {
      return Status::Error(fmt::format("block size {} x {}: {} is not a power of two in 1..{}", nx,
                                       ny, n, kMaxSpectralSize));
    }
  }
  BlockShape shape;
  shape.nx = nx;
  shape.ny = ny;
  shape.lx = std::countr_zero(static_cast<unsigned>(nx));
  shape.ly = std::countr_zero(static_cast<unsigned>(ny));
  return shape;
}

StatusOr<BlockShape> MakeTexelShape(int ulog2, int vlog2) {
  for (int l : {ulog2, vlog2}) {
    if (l < 0 || l > kMaxSpectralLog2) {
      return Status::Error(fmt::format("resolution log2 {} x {}: {} is outside 0..{}", ulog2, vlog2,
                                       l, kMaxSpectralLog2));
    }
  }
  return MakeBlockShape(1 << ulog2, 1 << vlog2);
}

Status CheckSpanSize(std::size_t size, const BlockShape& shape, const char* what) {
  if (size == shape.count()) return Status::Ok();
  return Status::Error(fmt::format("{} holds {} values, a {} x {} block needs {}", what, size,
                                   shape.nx, shape.ny, shape.count()));
}

}  // namespace dispex::spectral
