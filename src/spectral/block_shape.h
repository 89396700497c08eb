// The size of an oversampled face block (or a texel grid): powers of two, 1..512 each way.
#pragma once

#include <cstddef>

#include "dispex/status.h"

namespace dispex::spectral {

struct BlockShape {
  int nx = 1;
  int ny = 1;
  int lx = 0;  // log2(nx)
  int ly = 0;  // log2(ny)
  std::size_t count() const { return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny); }
};

// The shape of an nx x ny block, or an error naming the size that is not a power of two in
// 1..kMaxSpectralSize.
StatusOr<BlockShape> MakeBlockShape(int nx, int ny);

// The shape of 2^lx x 2^ly, unchecked (lx, ly in 0..9).
inline BlockShape ShapeOfLog2(int lx, int ly) {
  BlockShape shape;
  shape.lx = lx;
  shape.ly = ly;
  shape.nx = 1 << lx;
  shape.ny = 1 << ly;
  return shape;
}

// The shape of a 2^ulog2 x 2^vlog2 texel grid, or an error naming the log2 outside 0..9.
StatusOr<BlockShape> MakeTexelShape(int ulog2, int vlog2);

// OK when `size` == shape.count(); otherwise an error "<what> holds N values, an nx x ny block
// needs M".
Status CheckSpanSize(std::size_t size, const BlockShape& shape, const char* what);

}  // namespace dispex::spectral
