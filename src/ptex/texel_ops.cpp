// Texel operations following the reference Ptex library's PtexUtils (reduce, reduceTri,
// multalpha, divalpha, encodeDifference, deinterleave) so stored reductions match the
// reference writer's; averages are exact means instead of float32 sums (docs/ptex.md,
// "Averages").
#include "ptex/texel_ops.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "ptex/format.h"

namespace dispex::ptex {

namespace {

// Arithmetic view of each data type: Value is what sums are done in.
struct U8 {
  using T = std::uint8_t;
  static constexpr float kOne = 255.0f;
  static float ToF(T v) { return static_cast<float>(v); }
};
struct U16 {
  using T = std::uint16_t;
  static constexpr float kOne = 65535.0f;
  static float ToF(T v) { return static_cast<float>(v); }
};
struct Half {
  using T = std::uint16_t;
  static constexpr float kOne = 1.0f;
  static float ToF(T v) { return HalfToFloat(v); }
};
struct F32 {
  using T = float;
  static constexpr float kOne = 1.0f;
  static float ToF(T v) { return v; }
};

// float -> integer as C++ truncation would, but clamped (the reference's T(x) is undefined
// out of range).
template <class I>
I TruncClamp(float x, float max) {
  if (!(x > 0.0f)) return 0;
  if (x >= max) return static_cast<I>(max);
  return static_cast<I>(x);
}

template <class Traits>
typename Traits::T FromArithmetic(float x) {
  if constexpr (std::is_same_v<Traits, U8>) return TruncClamp<std::uint8_t>(x, 255.0f);
  if constexpr (std::is_same_v<Traits, U16>) return TruncClamp<std::uint16_t>(x, 65535.0f);
  if constexpr (std::is_same_v<Traits, Half>) return FloatToHalf(x);
  if constexpr (std::is_same_v<Traits, F32>) return x;
}

template <class F>
void Dispatch(PtexDataType type, F&& f) {
  switch (type) {
    case PtexDataType::kUint8:
      f(U8{});
      break;
    case PtexDataType::kUint16:
      f(U16{});
      break;
    case PtexDataType::kHalf:
      f(Half{});
      break;
    case PtexDataType::kFloat:
      f(F32{});
      break;
  }
}

template <class T>
T LoadT(const std::uint8_t* p, std::size_t i) {
  return Load<T>(p + i * sizeof(T));
}
template <class T>
void StoreT(std::uint8_t* p, std::size_t i, T v) {
  Store<T>(p + i * sizeof(T), v);
}

template <class Traits>
typename Traits::T Reduce4(typename Traits::T a, typename Traits::T b, typename Traits::T c,
                           typename Traits::T d) {
  if constexpr (std::is_same_v<Traits, U8> || std::is_same_v<Traits, U16>) {
    return static_cast<typename Traits::T>((int(a) + int(b) + int(c) + int(d)) >> 2);
  } else {
    float sum = Traits::ToF(a) + Traits::ToF(b) + Traits::ToF(c) + Traits::ToF(d);
    return FromArithmetic<Traits>(sum * 0.25f);
  }
}

}  // namespace

void FromFloat(const float* src, std::size_t n, PtexDataType type, std::uint8_t* dst) {
  switch (type) {
    case PtexDataType::kFloat:
      std::memcpy(dst, src, n * sizeof(float));
      break;
    case PtexDataType::kHalf:
      for (std::size_t i = 0; i < n; ++i) StoreT<std::uint16_t>(dst, i, FloatToHalf(src[i]));
      break;
    case PtexDataType::kUint8:
      for (std::size_t i = 0; i < n; ++i) {
        float x = std::clamp(src[i], 0.0f, 1.0f);  // NaN stays NaN: next line maps it to 0
        dst[i] = (x == x) ? static_cast<std::uint8_t>(double(x) * 255.0 + 0.5) : 0;
      }
      break;
    case PtexDataType::kUint16:
      for (std::size_t i = 0; i < n; ++i) {
        float x = std::clamp(src[i], 0.0f, 1.0f);
        StoreT<std::uint16_t>(dst, i,
                              (x == x) ? static_cast<std::uint16_t>(double(x) * 65535.0 + 0.5) : 0);
      }
      break;
  }
}

void ToFloat(const std::uint8_t* src, std::size_t n, PtexDataType type, float* dst) {
  switch (type) {
    case PtexDataType::kFloat:
      std::memcpy(dst, src, n * sizeof(float));
      break;
    case PtexDataType::kHalf:
      for (std::size_t i = 0; i < n; ++i) dst[i] = HalfToFloat(LoadT<std::uint16_t>(src, i));
      break;
    case PtexDataType::kUint8:
      for (std::size_t i = 0; i < n; ++i) dst[i] = static_cast<float>(src[i] / 255.0);
      break;
    case PtexDataType::kUint16:
      for (std::size_t i = 0; i < n; ++i) {
        dst[i] = static_cast<float>(LoadT<std::uint16_t>(src, i) / 65535.0);
      }
      break;
  }
}

void SplitChannels(const std::uint8_t* src, std::size_t src_stride, int ures, int vres,
                   int num_channels, int data_size, std::uint8_t* dst) {
  const std::size_t row_bytes = std::size_t(ures) * data_size;
  if (num_channels == 1) {
    for (int v = 0; v < vres; ++v)
      std::memcpy(dst + v * row_bytes, src + v * src_stride, row_bytes);
    return;
  }
  const std::size_t pixel = std::size_t(num_channels) * data_size;
  for (int c = 0; c < num_channels; ++c) {
    for (int v = 0; v < vres; ++v) {
      const std::uint8_t* s = src + v * src_stride + std::size_t(c) * data_size;
      for (int u = 0; u < ures; ++u, s += pixel, dst += data_size) std::memcpy(dst, s, data_size);
    }
  }
}

void MergeChannels(const std::uint8_t* src, int ures, int vres, int num_channels, int data_size,
                   std::uint8_t* dst, std::size_t dst_stride) {
  const std::size_t row_bytes = std::size_t(ures) * data_size;
  if (num_channels == 1) {
    for (int v = 0; v < vres; ++v)
      std::memcpy(dst + v * dst_stride, src + v * row_bytes, row_bytes);
    return;
  }
  const std::size_t pixel = std::size_t(num_channels) * data_size;
  for (int c = 0; c < num_channels; ++c) {
    for (int v = 0; v < vres; ++v) {
      std::uint8_t* d = dst + v * dst_stride + std::size_t(c) * data_size;
      for (int u = 0; u < ures; ++u, d += pixel, src += data_size) std::memcpy(d, src, data_size);
    }
  }
}

void EncodeDifference(std::uint8_t* data, std::size_t bytes, PtexDataType type) {
  if (type == PtexDataType::kUint8) {
    std::uint8_t prev = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
      std::uint8_t cur = data[i];
      data[i] = static_cast<std::uint8_t>(cur - prev);
      prev = cur;
    }
  } else if (type == PtexDataType::kUint16) {
    std::uint16_t prev = 0;
    for (std::size_t i = 0; i < bytes / 2; ++i) {
      std::uint16_t cur = LoadT<std::uint16_t>(data, i);
      StoreT<std::uint16_t>(data, i, static_cast<std::uint16_t>(cur - prev));
      prev = cur;
    }
  }
}

void DecodeDifference(std::uint8_t* data, std::size_t bytes, PtexDataType type) {
  if (type == PtexDataType::kUint8) {
    std::uint8_t prev = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
      prev = static_cast<std::uint8_t>(data[i] + prev);
      data[i] = prev;
    }
  } else if (type == PtexDataType::kUint16) {
    std::uint16_t prev = 0;
    for (std::size_t i = 0; i < bytes / 2; ++i) {
      prev = static_cast<std::uint16_t>(LoadT<std::uint16_t>(data, i) + prev);
      StoreT<std::uint16_t>(data, i, prev);
    }
  }
}

void ReduceQuad(const std::uint8_t* src, int ulog2, int vlog2, PtexDataType type, int num_channels,
                std::uint8_t* dst) {
  Dispatch(type, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::T;
    const std::size_t nch = num_channels;
    const std::size_t sw = std::size_t{1} << ulog2;  // source texels per row
    const std::size_t dw = sw / 2, dh = (std::size_t{1} << vlog2) / 2;
    const std::size_t srow = sw * nch;
    for (std::size_t j = 0; j < dh; ++j) {
      const std::size_t s0 = 2 * j * srow, d0 = j * dw * nch;
      for (std::size_t i = 0; i < dw; ++i) {
        for (std::size_t c = 0; c < nch; ++c) {
          std::size_t s = s0 + 2 * i * nch + c;
          T r = Reduce4<Traits>(LoadT<T>(src, s), LoadT<T>(src, s + nch), LoadT<T>(src, s + srow),
                                LoadT<T>(src, s + srow + nch));
          StoreT<T>(dst, d0 + i * nch + c, r);
        }
      }
    }
  });
}

void ReduceTriangle(const std::uint8_t* src, int log2, PtexDataType type, int num_channels,
                    std::uint8_t* dst) {
  Dispatch(type, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::T;
    const std::size_t nch = num_channels;
    const std::size_t n = std::size_t{1} << log2, h = n / 2;
    auto at = [&](std::size_t u, std::size_t v, std::size_t c) {
      return LoadT<T>(src, (v * n + u) * nch + c);
    };
    for (std::size_t y = 0; y < h; ++y) {
      for (std::size_t x = 0; x < h; ++x) {
        for (std::size_t c = 0; c < nch; ++c) {
          T r = Reduce4<Traits>(at(2 * x, 2 * y, c), at(2 * x + 1, 2 * y, c),
                                at(2 * x, 2 * y + 1, c), at(n - 1 - 2 * y, n - 1 - 2 * x, c));
          StoreT<T>(dst, (y * h + x) * nch + c, r);
        }
      }
    }
  });
}

void MultiplyAlpha(std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
                   int alpha_channel) {
  Dispatch(type, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::T;
    const float scale = 1.0f / Traits::kOne;
    const int first = alpha_channel == 0 ? 1 : 0;
    const int end = alpha_channel == 0 ? num_channels : alpha_channel;
    for (std::size_t t = 0; t < count; ++t) {
      const std::size_t base = t * num_channels;
      const float a = scale * Traits::ToF(LoadT<T>(data, base + alpha_channel));
      for (int c = first; c < end; ++c) {
        StoreT<T>(data, base + c,
                  FromArithmetic<Traits>(Traits::ToF(LoadT<T>(data, base + c)) * a));
      }
    }
  });
}

void DivideAlpha(std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
                 int alpha_channel) {
  Dispatch(type, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::T;
    const int first = alpha_channel == 0 ? 1 : 0;
    const int end = alpha_channel == 0 ? num_channels : alpha_channel;
    for (std::size_t t = 0; t < count; ++t) {
      const std::size_t base = t * num_channels;
      const float alpha = Traits::ToF(LoadT<T>(data, base + alpha_channel));
      if (alpha == 0.0f) continue;
      const float a = Traits::kOne / alpha;
      for (int c = first; c < end; ++c) {
        StoreT<T>(data, base + c,
                  FromArithmetic<Traits>(Traits::ToF(LoadT<T>(data, base + c)) * a));
      }
    }
  });
}

void Average(const std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
             std::uint8_t* out) {
  Dispatch(type, [&](auto traits) {
    using Traits = decltype(traits);
    using T = typename Traits::T;
    std::vector<double> sum(num_channels, 0.0);
    for (std::size_t t = 0; t < count; ++t) {
      for (int c = 0; c < num_channels; ++c) {
        sum[c] += static_cast<double>(Traits::ToF(LoadT<T>(data, t * num_channels + c)));
      }
    }
    for (int c = 0; c < num_channels; ++c) {
      const double mean = count ? sum[c] / static_cast<double>(count) : 0.0;
      T v;
      if constexpr (std::is_same_v<Traits, Half>) {
        v = DoubleToHalf(mean);
      } else if constexpr (std::is_same_v<Traits, F32>) {
        v = static_cast<float>(mean);
      } else {
        v = mean >= Traits::kOne ? static_cast<T>(Traits::kOne)
                                 : static_cast<T>(std::max(0.0, mean));
      }
      StoreT<T>(out, c, v);
    }
  });
}

bool IsConstant(const std::uint8_t* data, std::size_t stride, int ures, int vres, int pixel_size) {
  const std::size_t row = std::size_t(ures) * pixel_size;
  for (int v = 1; v < vres; ++v) {
    if (std::memcmp(data, data + v * stride, row) != 0) return false;
  }
  for (int u = 1; u < ures; ++u) {
    if (std::memcmp(data, data + std::size_t(u) * pixel_size, pixel_size) != 0) return false;
  }
  return true;
}

std::ptrdiff_t FirstNonFinite(const float* values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return static_cast<std::ptrdiff_t>(i);
  }
  return -1;
}

}  // namespace dispex::ptex
