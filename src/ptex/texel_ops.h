// Texel buffer operations of the Ptex format: type conversion, channel split/merge,
// difference coding, 2x2 reductions (quad and triangle rules), alpha premultiplication,
// averages, constant detection. Buffers are raw bytes in the file's data type,
// little-endian, channel-interleaved and v-major unless a function says otherwise.
#pragma once

#include <cstddef>
#include <cstdint>

#include "dispex/ptex.h"

namespace dispex::ptex {

// Converts n values. FromFloat: float as is, half rounded to nearest even, integers clamped
// to [0, 1] and scaled with rounding (NaN gives 0). ToFloat: integers divided by their max.
void FromFloat(const float* src, std::size_t n, PtexDataType type, std::uint8_t* dst);
void ToFloat(const std::uint8_t* src, std::size_t n, PtexDataType type, float* dst);

// Interleaved texels of a ures x vres region whose rows start `src_stride` bytes apart ->
// channel planes (all of channel 0 v-major, then channel 1, ...), packed.
void SplitChannels(const std::uint8_t* src, std::size_t src_stride, int ures, int vres,
                   int num_channels, int data_size, std::uint8_t* dst);
// Channel planes of a ures x vres region -> interleaved rows `dst_stride` bytes apart.
void MergeChannels(const std::uint8_t* src, int ures, int vres, int num_channels, int data_size,
                   std::uint8_t* dst, std::size_t dst_stride);

// Running difference over the whole buffer (uint8 / uint16 only; other types unchanged).
void EncodeDifference(std::uint8_t* data, std::size_t bytes, PtexDataType type);
void DecodeDifference(std::uint8_t* data, std::size_t bytes, PtexDataType type);

// 2x2 box reduction of a (ulog2, vlog2) face to (ulog2-1, vlog2-1), as the reference: float
// summed left to right in float32 then times 0.25, half through float, integers floor(sum/4).
void ReduceQuad(const std::uint8_t* src, int ulog2, int vlog2, PtexDataType type, int num_channels,
                std::uint8_t* dst);
// Triangle rule (docs/ptex.md, "The triangle rule") on a square (log2, log2) face stored as
// the N x N square.
void ReduceTriangle(const std::uint8_t* src, int log2, PtexDataType type, int num_channels,
                    std::uint8_t* dst);

// Premultiplies / un-premultiplies `count` texels by their alpha, as the reference does:
// alpha channel 0 scales every other channel, otherwise only the channels before it;
// integers truncate (and clamp), texels of zero alpha are left alone by DivideAlpha.
void MultiplyAlpha(std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
                   int alpha_channel);
void DivideAlpha(std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
                 int alpha_channel);

// Mean of `count` texels per channel, summed in double, converted to the data type (float
// and half rounded to nearest, integers truncated as the reference does); one texel out.
void Average(const std::uint8_t* data, std::size_t count, PtexDataType type, int num_channels,
             std::uint8_t* out);

// True when every texel of the ures x vres region (rows `stride` bytes apart) has the same
// bytes as the first.
bool IsConstant(const std::uint8_t* data, std::size_t stride, int ures, int vres, int pixel_size);

// Index of the first value that is not finite, or -1.
std::ptrdiff_t FirstNonFinite(const float* values, std::size_t n);

}  // namespace dispex::ptex
