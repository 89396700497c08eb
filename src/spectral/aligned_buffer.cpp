#include "spectral/aligned_buffer.h"

#include <fftw3.h>

#include <new>

namespace dispex::spectral {

AlignedFloats::~AlignedFloats() {
  fftwf_free(data_);
}

float* AlignedFloats::Reserve(std::size_t count) {
  if (count <= capacity_) return data_;
  fftwf_free(data_);
  data_ = fftwf_alloc_real(count);
  if (data_ == nullptr) throw std::bad_alloc();
  capacity_ = count;
  return data_;
}

}  // namespace dispex::spectral
