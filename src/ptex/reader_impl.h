// The state of an opened Ptex file, shared by the structure parser (reader.cpp) and the face
// decoder (face_data.cpp). Everything in it has been validated by Parse().
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/mapped_file.h"
#include "dispex/ptex.h"

namespace dispex {

struct PtexFile::Impl {
  std::string name;
  PtexReadOptions options;
  std::optional<MappedFile> mapped;  // the file, or
  std::vector<std::uint8_t> owned;   // bytes given to ParsePtex
  const std::uint8_t* data = nullptr;
  std::uint64_t size = 0;

  PtexHeaderInfo header;
  std::vector<PtexFaceInfo> faces;
  std::vector<std::uint8_t> const_data;  // num_faces x pixel size
  std::vector<PtexLevelInfo> levels;
  std::uint64_t level_data_pos = 0, level_data_size = 0;  // the level data section

  // A parsed tiled block: tile resolution, where the tile blocks start, their headers.
  struct TileTable {
    std::int8_t ulog2 = 0, vlog2 = 0;
    std::uint64_t data_offset = 0;
    std::vector<std::uint32_t> headers;
    std::vector<std::uint64_t> offsets;  // file offset of each tile block
  };
  // A face block: file offset, FaceDataHeader, resolution at its level, tile table index.
  struct Block {
    std::uint64_t offset = 0;
    std::uint32_t fdh = 0;
    std::int8_t ulog2 = 0, vlog2 = 0;
    std::int32_t tiles = -1;
  };
  std::vector<std::vector<Block>> level_blocks;  // [level][entry]
  std::vector<TileTable> tile_tables;
  std::vector<std::int32_t> reduction_order;  // entry r of a reduction level -> face id
  std::vector<std::int32_t> rfaceid;          // face id -> entry
  std::vector<std::int32_t> edit_block;       // face id -> index in edit_blocks, or -1
  std::vector<Block> edit_blocks;

  std::vector<PtexMetaItem> meta;

  // Sample() cache: decoded level-0 floats per face, filled on first use.
  mutable std::unique_ptr<std::atomic<std::vector<float>*>[]> sample_cache;

  ~Impl();

  // Builds everything above from `data` / `size`; the message names the section and face.
  Status Parse();
  // The header fields and section positions the steps of Parse share.
  struct Layout {
    std::uint32_t nfaces = 0;
    std::uint64_t pixel = 0;  // bytes per texel
    std::uint64_t face_info_pos = 0, const_pos = 0, level_info_pos = 0, level_data_pos = 0,
                  meta_pos = 0;
    std::uint32_t face_info_zip = 0, const_zip = 0, meta_zip = 0, meta_mem = 0;
    std::uint64_t level_data_size = 0;
    std::uint32_t lmd_header_zip = 0, lmd_header_mem = 0;
    std::uint64_t lmd_data_size = 0, edit_size = 0, edit_pos = 0;
  };
  Status ParseHeaders(Layout& layout);
  Status ParseFaceInfo(const Layout& layout);
  void ComputeReductionOrder();
  Status ParseLevels(const Layout& layout);
  Status ParseMetaData(const Layout& layout, std::uint64_t& end);
  Status ParseEdits(const Layout& layout, std::uint64_t lmd_end);
  Status ParseFaceEdit(const std::string& where, std::uint64_t body, std::uint32_t edit_len,
                       const Layout& layout);
  Status ParseMetaEdit(const std::string& where, std::uint64_t body, std::uint32_t edit_len);
  Status Fail(const std::string& what) const;  // "name: what"
  // Inflates `zipsize` bytes at `offset` into `out`, which must come out `expected` bytes
  // long; the size is checked against the file and the block before `out` is allocated.
  Status InflateSection(const std::string& section, std::uint64_t offset, std::uint64_t zipsize,
                        std::uint64_t expected, std::vector<std::uint8_t>& out) const;
  Status ParseTiles(Block& block, const std::string& where);
  // The block of a face at a stored level (nullptr for constant faces).
  const Block* FindBlock(int face, int level) const;
  int NumStoredLevels(int face) const;
  Status DecodeBlock(const Block& block, const std::string& where,
                     std::vector<std::uint8_t>& out) const;
  Status ReadRaw(int face, int level, std::vector<std::uint8_t>& out) const;
  std::string Where(int face, int level) const;
};

}  // namespace dispex
