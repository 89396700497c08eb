// Decoding face data of an opened Ptex file (docs/ptex.md, "Level data and reduction order", "Face
// data blocks and tiles", "Texel order, channel split and diff encoding"): block lookup by level
// and reduction order, inflation with the exact expected size, undifferencing, channel merge,
// tiles; plus bilinear sampling (texel centres at (i + 0.5) / res, clamped at the border).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/check.h"
#include "core/hash128.h"
#include "ptex/format.h"
#include "ptex/reader_impl.h"
#include "ptex/texel_ops.h"
#include "ptex/zlib_block.h"

namespace dispex {

using namespace ptex;

const PtexFile::Impl::Block* PtexFile::Impl::FindBlock(int face, int level) const {
  const PtexFaceInfo& info = faces[std::size_t(face)];
  if (info.constant) return nullptr;
  if (level == 0) {
    const std::int32_t e = edit_block[std::size_t(face)];
    return e >= 0 ? &edit_blocks[std::size_t(e)] : &level_blocks[0][std::size_t(face)];
  }
  return &level_blocks[std::size_t(level)][std::size_t(rfaceid[std::size_t(face)])];
}

int PtexFile::Impl::NumStoredLevels(int face) const {
  const PtexFaceInfo& info = faces[std::size_t(face)];
  if (info.constant || info.has_edits) return 1;
  int n = 1;
  while (n < header.num_levels && rfaceid[std::size_t(face)] < levels[std::size_t(n)].num_entries) {
    ++n;
  }
  return n;
}

// "" when a block (or tile) of ures x vres texels with header `fdh` can hold them: a zipped
// block's compressed size bounds what it can inflate to. Checked for every block and tile
// before anything is allocated for the texels.
static std::string CheckInflatable(std::uint32_t fdh, int ures, int vres,
                                   const PtexHeaderInfo& header) {
  if (EncodingOf(fdh) == kEncConstant) return {};
  const std::uint32_t size = BlockSizeOf(fdh);
  const std::uint64_t bytes = std::uint64_t(ures) * vres * header.pixel_size();
  if (bytes <= MaxInflatedSize(size)) return {};
  return std::to_string(size) + " compressed bytes cannot hold " + std::to_string(bytes) +
         " bytes of texels";
}

// Decodes one untiled block (constant, zipped or diff-zipped) of ures x vres texels, which
// CheckInflatable accepted, into `dst` (rows `stride` bytes apart). `split` is scratch.
static std::string DecodeSimple(const std::uint8_t* block, std::uint32_t fdh, int ures, int vres,
                                const PtexHeaderInfo& header, std::uint8_t* dst, std::size_t stride,
                                std::vector<std::uint8_t>& split) {
  const int pixel = header.pixel_size();
  const std::uint32_t enc = EncodingOf(fdh), size = BlockSizeOf(fdh);
  if (enc == kEncConstant) {
    for (int v = 0; v < vres; ++v) {
      for (int u = 0; u < ures; ++u)
        std::memcpy(dst + v * stride + std::size_t(u) * pixel, block, pixel);
    }
    return {};
  }
  const std::uint64_t bytes = std::uint64_t(ures) * vres * pixel;
  split.resize(bytes);
  std::string why = Inflate({block, size}, split);
  if (!why.empty()) return why;
  if (enc == kEncDiffZipped) DecodeDifference(split.data(), bytes, header.data_type);
  MergeChannels(split.data(), ures, vres, header.num_channels, PtexDataSize(header.data_type), dst,
                stride);
  return {};
}

Status PtexFile::Impl::DecodeBlock(const Block& block, const std::string& where,
                                   std::vector<std::uint8_t>& out) const {
  const int pixel = header.pixel_size();
  const int ures = 1 << block.ulog2, vres = 1 << block.vlog2;
  const std::size_t stride = std::size_t(ures) * pixel;
  if (block.tiles < 0) {
    if (std::string why = CheckInflatable(block.fdh, ures, vres, header); !why.empty()) {
      return Status::Error(name + ": " + where + ": " + why);
    }
  } else {
    const TileTable& table = tile_tables[std::size_t(block.tiles)];
    for (std::size_t t = 0; t < table.headers.size(); ++t) {
      std::string why =
          CheckInflatable(table.headers[t], 1 << table.ulog2, 1 << table.vlog2, header);
      if (!why.empty()) {
        return Status::Error(name + ": " + where + " tile " + std::to_string(t) + ": " + why);
      }
    }
  }
  out.resize(stride * vres);
  std::vector<std::uint8_t> split;
  if (block.tiles < 0) {
    std::string why =
        DecodeSimple(data + block.offset, block.fdh, ures, vres, header, out.data(), stride, split);
    if (!why.empty()) return Status::Error(name + ": " + where + ": " + why);
    return Status::Ok();
  }
  const TileTable& table = tile_tables[std::size_t(block.tiles)];
  const int tures = 1 << table.ulog2, tvres = 1 << table.vlog2;
  const int ntilesu = ures / tures;
  for (std::size_t t = 0; t < table.headers.size(); ++t) {
    const int tu = static_cast<int>(t % std::size_t(ntilesu)),
              tv = static_cast<int>(t / std::size_t(ntilesu));
    std::uint8_t* dst =
        out.data() + std::size_t(tv) * tvres * stride + std::size_t(tu) * tures * pixel;
    std::string why = DecodeSimple(data + table.offsets[t], table.headers[t], tures, tvres, header,
                                   dst, stride, split);
    if (!why.empty()) {
      return Status::Error(name + ": " + where + " tile " + std::to_string(t) + ": " + why);
    }
  }
  return Status::Ok();
}

Status PtexFile::Impl::ReadRaw(int face, int level, std::vector<std::uint8_t>& out) const {
  if (face < 0 || face >= header.num_faces) {
    return Status::Error(name + ": face " + std::to_string(face) + " is not in 0.." +
                         std::to_string(header.num_faces - 1));
  }
  const int stored = NumStoredLevels(face);
  if (level < 0 || level >= stored) {
    return Status::Error(name + ": face " + std::to_string(face) + " has no stored level " +
                         std::to_string(level) + " (stored: 0.." + std::to_string(stored - 1) +
                         ")");
  }
  const PtexFaceInfo& info = faces[std::size_t(face)];
  const std::uint64_t texels = std::uint64_t{1} << (info.ulog2 + info.vlog2 - 2 * level);
  if (texels * std::uint64_t(header.num_channels) > options.max_values_per_read) {
    return Status::Error(name + ": " + Where(face, level) + ": " + std::to_string(texels) +
                         " texels exceed the read limit of " +
                         std::to_string(options.max_values_per_read) + " values");
  }
  const Block* block = FindBlock(face, level);
  if (block == nullptr) {  // constant face: its value over its logical resolution
    const int pixel = header.pixel_size();
    out.resize(texels * std::size_t(pixel));
    const std::uint8_t* value = const_data.data() + std::size_t(face) * pixel;
    for (std::uint64_t t = 0; t < texels; ++t) std::memcpy(out.data() + t * pixel, value, pixel);
    return Status::Ok();
  }
  return DecodeBlock(*block, Where(face, level), out);
}

// ---- Public ---------------------------------------------------------------------------------

int PtexFile::NumStoredLevels(PtexFaceId face) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  return impl_->NumStoredLevels(face.value);
}

PtexBlockInfo PtexFile::BlockInfo(PtexFaceId face, int level) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  DISPEX_CHECK(level >= 0 && level < NumStoredLevels(face));
  const PtexFaceInfo& info = impl_->faces[std::size_t(face.value)];
  PtexBlockInfo b;
  b.ulog2 = static_cast<std::int8_t>(info.ulog2 - level);
  b.vlog2 = static_cast<std::int8_t>(info.vlog2 - level);
  b.tile_ulog2 = b.ulog2;
  b.tile_vlog2 = b.vlog2;
  const Impl::Block* block = impl_->FindBlock(face.value, level);
  if (block == nullptr) return b;
  b.encoding = static_cast<PtexBlockInfo::Encoding>(EncodingOf(block->fdh));
  b.size = BlockSizeOf(block->fdh);
  if (block->tiles >= 0) {
    const Impl::TileTable& t = impl_->tile_tables[std::size_t(block->tiles)];
    b.num_tiles = static_cast<int>(t.headers.size());
    b.tile_ulog2 = t.ulog2;
    b.tile_vlog2 = t.vlog2;
  }
  return b;
}

Status PtexFile::ReadFaceRaw(PtexFaceId face, int level, std::vector<std::uint8_t>& data) const {
  return impl_->ReadRaw(face.value, level, data);
}

Status PtexFile::ReadFace(PtexFaceId face, int level, std::vector<float>& texels) const {
  std::vector<std::uint8_t> raw;
  DISPEX_RETURN_IF_ERROR(impl_->ReadRaw(face.value, level, raw));
  const std::size_t n = raw.size() / std::size_t(PtexDataSize(impl_->header.data_type));
  texels.resize(n);
  ToFloat(raw.data(), n, impl_->header.data_type, texels.data());
  return Status::Ok();
}

std::span<const std::uint8_t> PtexFile::ConstantValueRaw(PtexFaceId face) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  const std::size_t pixel = std::size_t(impl_->header.pixel_size());
  return {impl_->const_data.data() + std::size_t(face.value) * pixel, pixel};
}

Status PtexFile::ReadEncodedFace(PtexFaceId face, PtexEncodedFace& out) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  const PtexFaceInfo& info = impl_->faces[std::size_t(face.value)];
  if (info.has_edits) {
    return impl_->Fail("face " + std::to_string(face.value) +
                       " has edits: its stored levels are not one encoding of its texels");
  }
  out.ulog2 = info.ulog2;
  out.vlog2 = info.vlog2;
  out.constant = info.constant;
  const std::span<const std::uint8_t> average = ConstantValueRaw(face);
  out.average.assign(average.begin(), average.end());
  out.headers.clear();
  out.blocks.clear();
  if (info.constant) {
    out.headers.push_back(0);
    return Status::Ok();
  }
  for (int l = 0; l < impl_->NumStoredLevels(face.value); ++l) {
    const Impl::Block* block = impl_->FindBlock(face.value, l);
    out.headers.push_back(block->fdh);
    const std::uint8_t* begin = impl_->data + block->offset;
    out.blocks.insert(out.blocks.end(), begin, begin + BlockSizeOf(block->fdh));
  }
  return Status::Ok();
}

void PtexFile::ConstantValue(PtexFaceId face, float* out) const {
  std::span<const std::uint8_t> raw = ConstantValueRaw(face);
  ToFloat(raw.data(), std::size_t(impl_->header.num_channels), impl_->header.data_type, out);
}

std::string PtexFile::LevelDataHash() const {
  return HashBytes(std::as_bytes(std::span(impl_->data + impl_->level_data_pos,
                                           static_cast<std::size_t>(impl_->level_data_size))))
      .Hex();
}

Status PtexFile::Validate() const {
  // Faces are checked in parallel; the error reported is the one of the lowest face id, so
  // the result does not depend on scheduling.
  const int n = impl_->header.num_faces;
  std::atomic<int> first_bad{n};
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& range) {
    std::vector<std::uint8_t> raw;
    for (int f = range.begin(); f < range.end() && f < first_bad.load(); ++f) {
      if (impl_->faces[std::size_t(f)].constant) continue;
      for (int l = 0; l < impl_->NumStoredLevels(f); ++l) {
        if (!impl_->ReadRaw(f, l, raw).ok()) {
          int current = first_bad.load();
          while (f < current && !first_bad.compare_exchange_weak(current, f)) {
          }
          break;
        }
      }
    }
  });
  const int bad = first_bad.load();
  if (bad == n) return Status::Ok();
  std::vector<std::uint8_t> raw;
  for (int l = 0; l < impl_->NumStoredLevels(bad); ++l) {
    DISPEX_RETURN_IF_ERROR(impl_->ReadRaw(bad, l, raw));
  }
  DISPEX_CHECK(false);  // the face failed above and must fail again
  return Status::Ok();
}

float PtexFile::Sample(PtexFaceId face, float u, float v, int channel) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  const PtexHeaderInfo& header = impl_->header;
  DISPEX_CHECK(channel >= 0 && channel < header.num_channels);
  const PtexFaceInfo& info = impl_->faces[std::size_t(face.value)];
  const int nch = header.num_channels;
  if (info.constant) {
    const int size = PtexDataSize(header.data_type);
    float value = 0;
    ToFloat(ConstantValueRaw(face).data() + std::size_t(channel) * size, 1, header.data_type,
            &value);
    return value;
  }
  std::atomic<std::vector<float>*>& slot = impl_->sample_cache[std::size_t(face.value)];
  std::vector<float>* texels = slot.load(std::memory_order_acquire);
  if (texels == nullptr) {
    // A face that cannot be decoded is cached as an empty vector, so that a caller sampling it
    // many times does not decode it again each time.
    auto decoded = std::make_unique<std::vector<float>>();
    if (!ReadFace(face, 0, *decoded).ok()) decoded->clear();
    std::vector<float>* expected = nullptr;
    if (slot.compare_exchange_strong(expected, decoded.get(), std::memory_order_acq_rel)) {
      texels = decoded.release();
    } else {
      texels = expected;  // another thread decoded it first
    }
  }
  const std::vector<float>& t = *texels;
  if (t.empty()) return std::numeric_limits<float>::quiet_NaN();
  const int ures = info.ures(), vres = info.vres();
  u = std::clamp(std::isnan(u) ? 0.0f : u, 0.0f, 1.0f);
  v = std::clamp(std::isnan(v) ? 0.0f : v, 0.0f, 1.0f);

  if (header.mesh_type == PtexMeshType::kTriangle) {
    // The triangular texel containing (u, v) (docs/ptex.md, "The triangle rule"); points past
    // u + v = 1 are pulled back onto the hypotenuse.
    const int n = ures;
    if (u + v > 1.0f) {
      const float s = u + v;
      u /= s;
      v /= s;
    }
    const float x = u * static_cast<float>(n), y = v * static_cast<float>(n);
    const int i = std::min(static_cast<int>(x), n - 1), j = std::min(static_cast<int>(y), n - 1);
    const bool inverted =
        (i + j <= n - 2) && (x - static_cast<float>(i)) + (y - static_cast<float>(j)) > 1.0f;
    int su = i, sv = j;
    if (inverted) {
      su = n - 1 - j;
      sv = n - 1 - i;
    } else if (i + j > n - 1) {  // rounding put the point just outside: nearest upright texel
      su = i;
      sv = n - 1 - i;
    }
    return t[(std::size_t(sv) * n + su) * nch + channel];
  }

  const float x =
      std::clamp(u * static_cast<float>(ures) - 0.5f, 0.0f, static_cast<float>(ures - 1));
  const float y =
      std::clamp(v * static_cast<float>(vres) - 0.5f, 0.0f, static_cast<float>(vres - 1));
  const int i0 = static_cast<int>(x), j0 = static_cast<int>(y);
  const int i1 = std::min(i0 + 1, ures - 1), j1 = std::min(j0 + 1, vres - 1);
  const float fx = x - static_cast<float>(i0), fy = y - static_cast<float>(j0);
  auto at = [&](int i, int j) { return t[(std::size_t(j) * ures + i) * nch + channel]; };
  const float bottom = at(i0, j0) + (at(i1, j0) - at(i0, j0)) * fx;
  const float top = at(i0, j1) + (at(i1, j1) - at(i0, j1)) * fx;
  return bottom + (top - bottom) * fy;
}

void PtexFile::ReleaseSampleCache() const {
  for (int f = 0; f < num_faces(); ++f)
    delete impl_->sample_cache[std::size_t(f)].exchange(nullptr);
}

}  // namespace dispex
