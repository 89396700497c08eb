// A growable float buffer from fftwf_malloc: FFTW plans are made for, and executed on, arrays
// with the same (SIMD) alignment, so every array the DCT touches comes from here.
#pragma once

#include <cstddef>

namespace dispex::spectral {

class AlignedFloats {
 public:
  AlignedFloats() = default;
  ~AlignedFloats();
  AlignedFloats(const AlignedFloats&) = delete;
  AlignedFloats& operator=(const AlignedFloats&) = delete;

  // Returns storage for at least `count` floats. Grows (discarding the contents) only when
  // `count` exceeds every earlier request, so steady-state use allocates nothing.
  float* Reserve(std::size_t count);
  float* data() { return data_; }
  const float* data() const { return data_; }

 private:
  float* data_ = nullptr;
  std::size_t capacity_ = 0;
};

}  // namespace dispex::spectral
