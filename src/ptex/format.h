// On-disk constants and little-endian helpers of the Ptex file format 1.4 (wdas/ptex
// PtexIO.h, described in docs/ptex.md, "The file format"). Everything here is internal to
// src/ptex; the public types are in include/dispex/ptex.h.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <span>
#include <vector>

#include "dispex/ptex.h"

namespace dispex::ptex {

inline constexpr std::uint32_t kMagic = 0x78657450;  // "Ptex"
inline constexpr std::uint32_t kMajorVersion = 1;
inline constexpr std::uint32_t kMinorVersion = 4;
inline constexpr std::size_t kHeaderSize = 64;
inline constexpr std::size_t kExtHeaderSize = 40;
inline constexpr std::size_t kFaceInfoSize = 20;
inline constexpr std::size_t kLevelInfoSize = 16;
inline constexpr std::size_t kBarrierSize = 8;
inline constexpr std::size_t kTilePreHeaderSize = 6;
inline constexpr std::size_t kEditFaceHeaderSize = 28;   // faceid, face info, data header
inline constexpr std::size_t kEditMetaHeaderSize = 8;    // zip size, mem size
inline constexpr std::size_t kMetaDataThreshold = 1024;  // larger values are "large" items
inline constexpr std::size_t kTileSize = 65536;          // the reference's tiling unit
inline constexpr int kMinReductionLog2 = 2;  // reductions stop when a side reaches 4 texels
inline constexpr int kMaxLog2 = 15;          // largest accepted ulog2 / vlog2
inline constexpr std::uint32_t kMaxBlockSize = (1u << 30) - 1;  // 30-bit block size field
// deflate cannot expand data by more than 1032:1; a zlib block of n bytes that claims to
// inflate to more than this is corrupt, which lets sizes be rejected before allocating.
inline constexpr std::uint64_t kMaxInflateRatio = 1040;

inline constexpr std::uint8_t kFlagConstant = 1;
inline constexpr std::uint8_t kFlagHasEdits = 2;
inline constexpr std::uint8_t kFlagNbConstant = 4;
inline constexpr std::uint8_t kFlagSubface = 8;

enum Encoding : std::uint32_t {
  kEncConstant = 0,
  kEncZipped = 1,
  kEncDiffZipped = 2,
  kEncTiled = 3
};

inline std::uint32_t PackDataHeader(std::uint32_t size, std::uint32_t encoding) {
  return (size & kMaxBlockSize) | (encoding << 30);
}
inline std::uint32_t BlockSizeOf(std::uint32_t fdh) {
  return fdh & kMaxBlockSize;
}
inline std::uint32_t EncodingOf(std::uint32_t fdh) {
  return fdh >> 30;
}

inline std::uint64_t MaxInflatedSize(std::uint64_t compressed) {
  return compressed * kMaxInflateRatio + 64;
}

// ---- Little-endian access (unaligned; the format is little-endian, so is every host the
// project builds on, which the static_assert below checks) ----

static_assert(std::endian::native == std::endian::little,
              "dispex's Ptex code assumes a little-endian host, as the format does");

template <class T>
T Load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
template <class T>
void Store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}
template <class T>
void Append(std::vector<std::uint8_t>& out, T v) {
  std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &v, sizeof(T));
}
inline void AppendBytes(std::vector<std::uint8_t>& out, const void* p, std::size_t n) {
  const auto* b = static_cast<const std::uint8_t*>(p);
  out.insert(out.end(), b, b + n);
}

// ---- Face records ----

inline std::uint8_t PackAdjEdges(const PtexFaceInfo& f) {
  return static_cast<std::uint8_t>((f.adjedges[0] & 3) | (f.adjedges[1] & 3) << 2 |
                                   (f.adjedges[2] & 3) << 4 | (f.adjedges[3] & 3) << 6);
}
inline std::uint8_t PackFlags(const PtexFaceInfo& f) {
  return static_cast<std::uint8_t>((f.constant ? kFlagConstant : 0) |
                                   (f.neighborhood_constant ? kFlagNbConstant : 0) |
                                   (f.subface ? kFlagSubface : 0));
}
// Writes the 20-byte record.
inline void EncodeFaceInfo(const PtexFaceInfo& f, std::uint8_t* p) {
  p[0] = static_cast<std::uint8_t>(f.ulog2);
  p[1] = static_cast<std::uint8_t>(f.vlog2);
  p[2] = PackAdjEdges(f);
  p[3] = PackFlags(f);
  for (int e = 0; e < 4; ++e) Store<std::int32_t>(p + 4 + 4 * e, f.adjfaces[e]);
}
// Reads a 20-byte record (no validation; the caller checks the values).
inline PtexFaceInfo DecodeFaceInfo(const std::uint8_t* p) {
  PtexFaceInfo f;
  f.ulog2 = static_cast<std::int8_t>(p[0]);
  f.vlog2 = static_cast<std::int8_t>(p[1]);
  for (int e = 0; e < 4; ++e) {
    f.adjedges[e] = static_cast<std::uint8_t>((p[2] >> (2 * e)) & 3);
    f.adjfaces[e] = Load<std::int32_t>(p + 4 + 4 * e);
  }
  f.constant = (p[3] & kFlagConstant) != 0;
  f.has_edits = false;  // runtime flag: never trusted from the file
  f.neighborhood_constant = (p[3] & kFlagNbConstant) != 0;
  f.subface = (p[3] & kFlagSubface) != 0;
  return f;
}

// The key that orders faces in reduction levels: min(ulog2, vlog2), constant faces 1.
inline int ReductionKey(const PtexFaceInfo& f) {
  return f.constant ? 1 : std::min<int>(f.ulog2, f.vlog2);
}

// Face ids sorted by decreasing ReductionKey, stable (the "reduction order": docs/ptex.md,
// "Level data and reduction order").
// Entry r of a reduction level holds face result[r].
inline std::vector<std::int32_t> ReductionOrder(std::span<const PtexFaceInfo> faces) {
  std::vector<std::int32_t> order(faces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    return ReductionKey(faces[a]) > ReductionKey(faces[b]);
  });
  return order;
}

// Number of reductions the reference writer stores for a face: levels 1 .. m-2 where
// m = min(ulog2, vlog2), none for constant faces.
inline int StoredReductions(const PtexFaceInfo& f) {
  if (f.constant) return 0;
  return std::max(0, std::min<int>(f.ulog2, f.vlog2) - kMinReductionLog2);
}

// The reference writer's tile resolution for a block of (ulog2, vlog2) texels; returns the
// face resolution itself when the block stays untiled (below 2 * kTileSize bytes).
inline void TileResolution(int ulog2, int vlog2, int pixel_size, int& tile_ulog2, int& tile_vlog2) {
  std::uint64_t face_bytes = (std::uint64_t{1} << (ulog2 + vlog2)) * std::uint64_t(pixel_size);
  std::uint64_t ratio = face_bytes / kTileSize;
  int ntiles_log2 = 0;
  while ((ratio >> (ntiles_log2 + 1)) != 0) ++ntiles_log2;
  if (ntiles_log2 == 0) {
    tile_ulog2 = ulog2;
    tile_vlog2 = vlog2;
    return;
  }
  int n = ulog2 + vlog2 - ntiles_log2;
  tile_ulog2 = std::min((n + 1) / 2, ulog2);
  tile_vlog2 = std::min(n - tile_ulog2, vlog2);
}

}  // namespace dispex::ptex
