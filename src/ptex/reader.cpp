// PtexFile::Open / ParsePtex: reads the structure of a Ptex 1.4 file (docs/ptex.md, "File layout"
// to "Edit blocks") and validates it completely before anything is allocated from its numbers. The
// reference reader (wdas/ptex PtexReader.cpp) trusts the file; this one checks every size, offset
// and count against the file size, against what a zlib block can inflate to (at most ~1032x its
// size, so a header claiming 2^32 faces in 200 bytes fails at once), and against the format's
// limits, and inflates every stream into a buffer of exactly the expected size.
#include <algorithm>
#include <cstring>

#include "core/check.h"
#include "ptex/format.h"
#include "ptex/meta_data.h"
#include "ptex/reader_impl.h"
#include "ptex/zlib_block.h"

namespace dispex {

using namespace ptex;

namespace {

constexpr std::uint64_t kMaxFaces = 1u << 28;
constexpr std::uint64_t kMaxExtHeaderSize = 1u << 16;
constexpr int kMaxLevels = 2 * kMaxLog2 + 1;
constexpr int kMaxTilesLog2 = 20;  // the reference makes at most 2^16 (a 2^30-texel face)

std::string Num(std::uint64_t v) {
  return std::to_string(v);
}

// The fields of the 64-byte header after the magic and the version (docs/ptex.md, "Header").
struct MainHeader {
  std::uint32_t mesh_type = 0, data_type = 0;
  std::int32_t alpha = 0;
  std::uint16_t nchannels = 0, nlevels = 0;
  std::uint32_t nfaces = 0, ext_size = 0, face_info_zip = 0, const_zip = 0, level_info_size = 0,
                minor = 0;
  std::uint64_t level_data_size = 0;
  std::uint32_t meta_zip = 0, meta_mem = 0;
};

MainHeader LoadMainHeader(const std::uint8_t* h) {
  MainHeader m;
  m.mesh_type = Load<std::uint32_t>(h + 8);
  m.data_type = Load<std::uint32_t>(h + 12);
  m.alpha = Load<std::int32_t>(h + 16);
  m.nchannels = Load<std::uint16_t>(h + 20);
  m.nlevels = Load<std::uint16_t>(h + 22);
  m.nfaces = Load<std::uint32_t>(h + 24);
  m.ext_size = Load<std::uint32_t>(h + 28);
  m.face_info_zip = Load<std::uint32_t>(h + 32);
  m.const_zip = Load<std::uint32_t>(h + 36);
  m.level_info_size = Load<std::uint32_t>(h + 40);
  m.minor = Load<std::uint32_t>(h + 44);
  m.level_data_size = Load<std::uint64_t>(h + 48);
  m.meta_zip = Load<std::uint32_t>(h + 56);
  m.meta_mem = Load<std::uint32_t>(h + 60);
  return m;
}

// Why the header's fields do not describe a Ptex file dispex reads ("" when they do).
std::string MainHeaderProblem(const MainHeader& m) {
  if (m.mesh_type > 1) return "header: mesh type " + Num(m.mesh_type) + " is not 0 or 1";
  if (m.data_type > 3) return "header: data type " + Num(m.data_type) + " is not 0..3";
  if (m.nchannels == 0) return "header: 0 channels";
  if (m.alpha < -1 || m.alpha >= m.nchannels) {
    return "header: alpha channel " + std::to_string(m.alpha) + " is not -1 or below " +
           Num(m.nchannels) + " channels";
  }
  if (m.nfaces == 0) return "header: the file has no faces";
  if (m.nfaces > kMaxFaces) {
    return "header: " + Num(m.nfaces) + " faces exceed the limit of " + Num(kMaxFaces);
  }
  if (m.nlevels == 0 || m.nlevels > kMaxLevels) {
    return "header: level count " + Num(m.nlevels) + " is not in 1.." + Num(kMaxLevels);
  }
  if (m.level_info_size != kLevelInfoSize * m.nlevels) {
    return "header: level info size " + Num(m.level_info_size) + " is not 16 x " + Num(m.nlevels) +
           " levels";
  }
  if (m.ext_size > kMaxExtHeaderSize) {
    return "header: extended header size " + Num(m.ext_size) + " is not plausible";
  }
  if ((m.meta_zip == 0) != (m.meta_mem == 0)) {
    return "header: meta data sizes " + Num(m.meta_zip) + " (compressed) and " + Num(m.meta_mem) +
           " (inflated) disagree";
  }
  return "";
}

void SetHeaderInfo(const MainHeader& m, std::uint64_t file_size, PtexHeaderInfo& header) {
  header.mesh_type = static_cast<PtexMeshType>(m.mesh_type);
  header.data_type = static_cast<PtexDataType>(m.data_type);
  header.num_channels = m.nchannels;
  header.alpha_channel = m.alpha;
  header.num_faces = static_cast<int>(m.nfaces);
  header.num_levels = m.nlevels;
  header.minor_version = static_cast<int>(m.minor);
  header.file_size = file_size;
}

// The extended header's fields (docs/ptex.md, "Extended header").
struct ExtHeader {
  std::uint16_t ubord = 0, vbord = 0, edge_filter = 0;
  std::uint32_t lmd_header_zip = 0, lmd_header_mem = 0;
  std::uint64_t lmd_data_size = 0, edit_size = 0, edit_pos = 0;
};

// min(40, ext_size) bytes at `x` are read, the rest are zero.
ExtHeader LoadExtHeader(const std::uint8_t* x, std::uint32_t ext_size) {
  std::uint8_t ext[kExtHeaderSize] = {};
  std::memcpy(ext, x, std::min<std::size_t>(kExtHeaderSize, ext_size));
  ExtHeader e;
  e.ubord = Load<std::uint16_t>(ext);
  e.vbord = Load<std::uint16_t>(ext + 4);
  e.edge_filter = Load<std::uint16_t>(ext + 6);
  e.lmd_header_zip = Load<std::uint32_t>(ext + 8);
  e.lmd_header_mem = Load<std::uint32_t>(ext + 12);
  e.lmd_data_size = Load<std::uint64_t>(ext + 16);
  e.edit_size = Load<std::uint64_t>(ext + 24);
  e.edit_pos = Load<std::uint64_t>(ext + 32);
  return e;
}

std::string ExtHeaderProblem(const ExtHeader& e) {
  if (e.ubord > 2 || e.vbord > 2) {
    return "extended header: border modes (" + Num(e.ubord) + ", " + Num(e.vbord) +
           ") are not 0..2";
  }
  if (e.edge_filter > 1) {
    return "extended header: edge filter mode " + Num(e.edge_filter) + " is not 0 or 1";
  }
  if ((e.lmd_header_zip == 0) != (e.lmd_header_mem == 0)) {
    return "extended header: large meta data header sizes disagree";
  }
  return "";
}

// Where the sections start, one after the other from the end of the extended header.
struct SectionPositions {
  std::uint64_t face_info = 0, const_data = 0, level_info = 0, level_data = 0, meta = 0;
};

SectionPositions PositionsOf(const MainHeader& m) {
  SectionPositions at;
  at.face_info = kHeaderSize + m.ext_size;
  at.const_data = at.face_info + m.face_info_zip;
  at.level_info = at.const_data + m.const_zip;
  at.level_data = at.level_info + m.level_info_size;
  at.meta = at.level_data + m.level_data_size;
  return at;
}

// Whether the sections up to the level data lie within the file ("" when they do).
std::string SectionsProblem(const MainHeader& m, const SectionPositions& at, std::uint64_t size) {
  if (at.level_data > size) {
    return "face info, constant data and level info (" + Num(at.level_data - at.face_info) +
           " bytes from offset " + Num(at.face_info) + ") run past the end of the file (" +
           Num(size) + " bytes)";
  }
  if (m.level_data_size > size - at.level_data) {
    return "header: level data of " + Num(m.level_data_size) + " bytes at offset " +
           Num(at.level_data) + " runs past the end of the file (" + Num(size) + " bytes)";
  }
  return "";
}

}  // namespace

PtexFile::Impl::~Impl() {
  if (!sample_cache) return;
  for (std::size_t f = 0; f < faces.size(); ++f) delete sample_cache[f].load();
}

Status PtexFile::Impl::InflateSection(const std::string& section, std::uint64_t offset,
                                      std::uint64_t zipsize, std::uint64_t expected,
                                      std::vector<std::uint8_t>& out) const {
  const Impl& file = *this;
  if (offset > file.size || zipsize > file.size - offset) {
    return Status::Error(file.name + ": " + section + ": " + Num(zipsize) + " bytes at offset " +
                         Num(offset) + " run past the end of the file (" + Num(file.size) +
                         " bytes)");
  }
  if (expected > MaxInflatedSize(zipsize)) {
    return Status::Error(file.name + ": " + section + ": " + Num(zipsize) +
                         " compressed bytes cannot hold the " + Num(expected) +
                         " bytes it must inflate to");
  }
  out.resize(static_cast<std::size_t>(expected));
  std::string why = Inflate({file.data + offset, static_cast<std::size_t>(zipsize)}, out);
  if (!why.empty()) return Status::Error(file.name + ": " + section + ": " + why);
  return Status::Ok();
}

std::string PtexFile::Impl::Where(int face, int level) const {
  return "face " + std::to_string(face) + " level " + std::to_string(level);
}

Status PtexFile::Impl::ParseTiles(Block& block, const std::string& where) {
  const std::uint32_t block_size = BlockSizeOf(block.fdh);
  auto fail = [&](const std::string& what) {
    return Status::Error(name + ": " + where + ": tiled block: " + what);
  };
  if (block_size < kTilePreHeaderSize)
    return fail("block of " + Num(block_size) + " bytes has no tile header");
  const auto tile_ulog2 = static_cast<std::int8_t>(data[block.offset]);
  const auto tile_vlog2 = static_cast<std::int8_t>(data[block.offset + 1]);
  const std::uint32_t header_zip = Load<std::uint32_t>(data + block.offset + 2);
  if (tile_ulog2 < 0 || tile_vlog2 < 0 || tile_ulog2 > block.ulog2 || tile_vlog2 > block.vlog2) {
    return fail("tile resolution log2 (" + std::to_string(tile_ulog2) + ", " +
                std::to_string(tile_vlog2) + ") does not fit the face's (" +
                std::to_string(block.ulog2) + ", " + std::to_string(block.vlog2) + ")");
  }
  if (header_zip > block_size - kTilePreHeaderSize) {
    return fail("tile header of " + Num(header_zip) + " bytes runs past the block's " +
                Num(block_size) + " bytes");
  }
  const int ntiles_log2 = (block.ulog2 - tile_ulog2) + (block.vlog2 - tile_vlog2);
  if (ntiles_log2 > kMaxTilesLog2) {
    return fail("2^" + std::to_string(ntiles_log2) + " tiles exceed the limit of 2^" +
                std::to_string(kMaxTilesLog2));
  }
  const std::uint64_t ntiles = std::uint64_t{1} << ntiles_log2;
  TileTable table;
  table.ulog2 = tile_ulog2;
  table.vlog2 = tile_vlog2;
  if (ntiles * 4 > MaxInflatedSize(header_zip)) {
    return fail(Num(ntiles) + " tiles cannot be described by a " + Num(header_zip) +
                "-byte tile header");
  }
  std::vector<std::uint8_t> raw;
  DISPEX_RETURN_IF_ERROR(InflateSection(where + ": tile header", block.offset + kTilePreHeaderSize,
                                        header_zip, ntiles * 4, raw));
  table.data_offset = block.offset + kTilePreHeaderSize + header_zip;
  const std::uint64_t available = block_size - kTilePreHeaderSize - header_zip;
  const std::uint64_t pixel = static_cast<std::uint64_t>(header.pixel_size());
  std::uint64_t sum = 0;
  table.headers.resize(ntiles);
  table.offsets.resize(ntiles);
  for (std::uint64_t t = 0; t < ntiles; ++t) {
    const std::uint32_t fdh = Load<std::uint32_t>(raw.data() + 4 * t);
    const std::uint32_t enc = EncodingOf(fdh), bsize = BlockSizeOf(fdh);
    if (enc == kEncTiled) return fail("tile " + Num(t) + " is itself tiled");
    if (enc == kEncConstant && bsize != pixel) {
      return fail("constant tile " + Num(t) + " has " + Num(bsize) + " bytes, a texel has " +
                  Num(pixel));
    }
    if (enc != kEncConstant && bsize == 0) return fail("tile " + Num(t) + " has an empty block");
    table.headers[t] = fdh;
    table.offsets[t] = table.data_offset + sum;
    sum += bsize;
  }
  if (sum != available) {
    return fail("tile blocks total " + Num(sum) + " bytes, the block leaves " + Num(available));
  }
  block.tiles = static_cast<std::int32_t>(tile_tables.size());
  tile_tables.push_back(std::move(table));
  return Status::Ok();
}

Status PtexFile::Impl::Fail(const std::string& what) const {
  return Status::Error(name + ": " + what);
}

// The header and the extended header, and where the sections lie.
Status PtexFile::Impl::ParseHeaders(Layout& layout) {
  if (size < kHeaderSize) {
    return Fail("file of " + Num(size) + " bytes is shorter than the 64-byte Ptex header");
  }
  if (Load<std::uint32_t>(data) != kMagic) return Fail("not a Ptex file (no 'Ptex' magic)");
  const std::uint32_t version = Load<std::uint32_t>(data + 4);
  if (version != kMajorVersion) {
    return Fail("header: unsupported Ptex major version " + Num(version) + " (expected 1)");
  }
  const MainHeader m = LoadMainHeader(data);
  if (std::string why = MainHeaderProblem(m); !why.empty()) return Fail(why);
  SetHeaderInfo(m, size, header);

  if (kHeaderSize + std::uint64_t{m.ext_size} > size) {
    return Fail("extended header of " + Num(m.ext_size) + " bytes runs past the end of the file");
  }
  const ExtHeader x = LoadExtHeader(data + kHeaderSize, m.ext_size);
  if (std::string why = ExtHeaderProblem(x); !why.empty()) return Fail(why);
  header.u_border = static_cast<PtexBorderMode>(x.ubord);
  header.v_border = static_cast<PtexBorderMode>(x.vbord);
  header.edge_filter = static_cast<PtexEdgeFilterMode>(x.edge_filter);

  const SectionPositions at = PositionsOf(m);
  if (std::string why = SectionsProblem(m, at, size); !why.empty()) return Fail(why);
  layout.nfaces = m.nfaces;
  layout.pixel = static_cast<std::uint64_t>(header.pixel_size());
  layout.face_info_pos = at.face_info;
  layout.face_info_zip = m.face_info_zip;
  layout.const_pos = at.const_data;
  layout.const_zip = m.const_zip;
  layout.level_info_pos = at.level_info;
  layout.level_data_pos = at.level_data;
  layout.level_data_size = m.level_data_size;
  layout.meta_pos = at.meta;
  layout.meta_zip = m.meta_zip;
  layout.meta_mem = m.meta_mem;
  layout.lmd_header_zip = x.lmd_header_zip;
  layout.lmd_header_mem = x.lmd_header_mem;
  layout.lmd_data_size = x.lmd_data_size;
  layout.edit_size = x.edit_size;
  layout.edit_pos = x.edit_pos;
  return Status::Ok();
}

Status PtexFile::Impl::ParseFaceInfo(const Layout& layout) {
  const std::uint32_t nfaces = layout.nfaces;
  std::vector<std::uint8_t> raw;
  DISPEX_RETURN_IF_ERROR(InflateSection("face info", layout.face_info_pos, layout.face_info_zip,
                                        std::uint64_t{nfaces} * kFaceInfoSize, raw));
  faces.resize(nfaces);
  const bool triangle = header.mesh_type == PtexMeshType::kTriangle;
  for (std::uint32_t f = 0; f < nfaces; ++f) {
    PtexFaceInfo info = DecodeFaceInfo(raw.data() + std::size_t{f} * kFaceInfoSize);
    const std::string where = "face info: face " + Num(f);
    if (info.ulog2 < 0 || info.ulog2 > kMaxLog2 || info.vlog2 < 0 || info.vlog2 > kMaxLog2) {
      return Fail(where + ": resolution log2 (" + std::to_string(info.ulog2) + ", " +
                  std::to_string(info.vlog2) + ") is not in 0.." + std::to_string(kMaxLog2));
    }
    if (triangle && info.ulog2 != info.vlog2) {
      return Fail(where + ": triangle face with non-square resolution log2 (" +
                  std::to_string(info.ulog2) + ", " + std::to_string(info.vlog2) + ")");
    }
    if (triangle) {
      info.adjfaces[3] = -1;
      info.adjedges[3] = 0;
    }
    for (int e = 0; e < 4; ++e) {
      if (info.adjfaces[e] < -1 || info.adjfaces[e] >= static_cast<std::int64_t>(nfaces)) {
        return Fail(where + ": neighbour across edge " + std::to_string(e) + " is face " +
                    std::to_string(info.adjfaces[e]) + ", not -1 or one of the " + Num(nfaces) +
                    " faces");
      }
      if (triangle && info.adjfaces[e] >= 0 && info.adjedges[e] > 2) {
        return Fail(where + ": triangle neighbour edge id " + std::to_string(info.adjedges[e]));
      }
    }
    faces[f] = info;
  }
  return Status::Ok();
}

// Reduction order from the faces as stored (edits do not change it, as in the reference).
void PtexFile::Impl::ComputeReductionOrder() {
  const auto nfaces = static_cast<std::uint32_t>(faces.size());
  reduction_order = ReductionOrder(faces);
  rfaceid.assign(nfaces, 0);
  for (std::uint32_t r = 0; r < nfaces; ++r)
    rfaceid[std::size_t(reduction_order[r])] = std::int32_t(r);
}

Status PtexFile::Impl::ParseLevels(const Layout& layout) {
  const std::uint32_t nfaces = layout.nfaces;
  const std::uint16_t nlevels = static_cast<std::uint16_t>(header.num_levels);
  const std::uint64_t pixel = layout.pixel;
  const std::uint64_t level_info_pos = layout.level_info_pos;
  level_data_pos = layout.level_data_pos;
  level_data_size = layout.level_data_size;
  levels.resize(nlevels);
  level_blocks.resize(nlevels);
  std::uint64_t level_pos = level_data_pos, level_total = 0;
  for (int l = 0; l < nlevels; ++l) {
    const std::uint8_t* li = data + level_info_pos + std::uint64_t(l) * kLevelInfoSize;
    PtexLevelInfo& level = levels[std::size_t(l)];
    level.data_size = Load<std::uint64_t>(li);
    level.header_size = Load<std::uint32_t>(li + 8);
    const std::uint32_t entries = Load<std::uint32_t>(li + 12);
    const std::string where = "level " + std::to_string(l);
    if (l == 0 && entries != nfaces) {
      return Fail(where + ": " + Num(entries) + " entries, the file has " + Num(nfaces) + " faces");
    }
    if (entries > nfaces) {
      return Fail(where + ": " + Num(entries) + " entries exceed the " + Num(nfaces) + " faces");
    }
    level.num_entries = static_cast<int>(entries);
    if (level.data_size > level_data_size - level_total) {
      return Fail(where + ": " + Num(level.data_size) +
                  " bytes run past the level data size in the header (" + Num(level_data_size) +
                  ")");
    }
    if (level.header_size > level.data_size) {
      return Fail(where + ": header of " + Num(level.header_size) + " bytes exceeds the level's " +
                  Num(level.data_size) + " bytes");
    }
    std::vector<std::uint8_t> fdh_raw;
    DISPEX_RETURN_IF_ERROR(InflateSection(where + " header", level_pos, level.header_size,
                                          std::uint64_t{entries} * 4, fdh_raw));
    std::vector<Block>& blocks = level_blocks[std::size_t(l)];
    blocks.resize(entries);
    std::uint64_t offset = level_pos + level.header_size;
    const std::uint64_t end = level_pos + level.data_size;
    for (std::uint32_t r = 0; r < entries; ++r) {
      const int face = l == 0 ? static_cast<int>(r) : reduction_order[r];
      const PtexFaceInfo& info = faces[std::size_t(face)];
      Block& b = blocks[r];
      b.fdh = Load<std::uint32_t>(fdh_raw.data() + 4 * std::size_t{r});
      b.offset = offset;
      const std::uint32_t bsize = BlockSizeOf(b.fdh), enc = EncodingOf(b.fdh);
      const std::string bwhere = Where(face, l);
      if (bsize > end - offset) {
        return Fail(where + ": block of " + bwhere + " (" + Num(bsize) +
                    " bytes) runs past the end of the level");
      }
      offset += bsize;
      if (info.constant) continue;  // never read: the constant data holds the face
      if (std::min(info.ulog2, info.vlog2) < l) {
        return Fail(where + ": entry " + Num(r) + " is " + bwhere + ", too small for the level (" +
                    std::to_string(info.ures()) + "x" + std::to_string(info.vres()) + ")");
      }
      b.ulog2 = static_cast<std::int8_t>(info.ulog2 - l);
      b.vlog2 = static_cast<std::int8_t>(info.vlog2 - l);
      if (enc == kEncConstant && bsize != pixel) {
        return Fail(bwhere + ": constant block of " + Num(bsize) + " bytes, a texel has " +
                    Num(pixel));
      }
      if (enc != kEncConstant && bsize == 0) return Fail(bwhere + ": empty data block");
      if (enc == kEncTiled) DISPEX_RETURN_IF_ERROR(ParseTiles(b, bwhere));
    }
    if (offset != end) {
      return Fail(where + ": blocks total " + Num(offset - level_pos - level.header_size) +
                  " bytes, the level info says " + Num(level.data_size - level.header_size));
    }
    level_pos = end;
    level_total += level.data_size;
  }
  if (level_total != level_data_size) {
    return Fail("levels total " + Num(level_total) + " bytes, the header says " +
                Num(level_data_size));
  }
  return Status::Ok();
}

// Small meta data, the barrier, large meta data; `end` is where the large meta data ends.
Status PtexFile::Impl::ParseMetaData(const Layout& layout, std::uint64_t& end) {
  const std::uint64_t meta_pos = layout.meta_pos;
  const std::uint32_t meta_zip = layout.meta_zip, meta_mem = layout.meta_mem;
  const std::uint32_t lmd_header_zip = layout.lmd_header_zip;
  const std::uint32_t lmd_header_mem = layout.lmd_header_mem;
  const std::uint64_t lmd_data_size = layout.lmd_data_size;
  if (meta_zip != 0) {
    std::vector<std::uint8_t> block;
    DISPEX_RETURN_IF_ERROR(InflateSection("meta data", meta_pos, meta_zip, meta_mem, block));
    std::vector<ParsedMetaRecord> records;
    std::string why = ParseMetaRecords(block, false, records);
    if (!why.empty()) return Fail("meta data: " + why);
    for (ParsedMetaRecord& r : records) UpsertMetaItem(meta, std::move(r.item));
  }
  const std::uint64_t lmd_pos = meta_pos + meta_zip + kBarrierSize;
  std::uint64_t lmd_end = lmd_pos;
  if (lmd_header_zip != 0) {
    std::vector<std::uint8_t> block;
    DISPEX_RETURN_IF_ERROR(
        InflateSection("large meta data header", lmd_pos, lmd_header_zip, lmd_header_mem, block));
    std::vector<ParsedMetaRecord> records;
    std::string why = ParseMetaRecords(block, true, records);
    if (!why.empty()) return Fail("large meta data header: " + why);
    std::uint64_t value_pos = lmd_pos + lmd_header_zip;
    std::uint64_t total = 0;
    for (ParsedMetaRecord& r : records) {
      if (r.zipsize > lmd_data_size - total) {
        return Fail("large meta data " + QuotedKey(r.item.key) + ": " + Num(r.zipsize) +
                    " bytes run past the large meta data size (" + Num(lmd_data_size) + ")");
      }
      DISPEX_RETURN_IF_ERROR(InflateSection("large meta data " + QuotedKey(r.item.key), value_pos,
                                            r.zipsize, r.datasize, r.item.bytes));
      value_pos += r.zipsize;
      total += r.zipsize;
      UpsertMetaItem(meta, std::move(r.item));
    }
    if (total != lmd_data_size) {
      return Fail("large meta data: values total " + Num(total) + " bytes, the header says " +
                  Num(lmd_data_size));
    }
    lmd_end = value_pos;
  } else if (lmd_data_size != 0) {
    return Fail("extended header: large meta data of " + Num(lmd_data_size) +
                " bytes without a header");
  }
  end = lmd_end;
  return Status::Ok();
}

// Edit blocks (docs/ptex.md, "Edit blocks"): at max(editdatapos, end of large meta data);
// editdatapos 0 (files before 1.3) means "scan to the end of the file".
Status PtexFile::Impl::ParseEdits(const Layout& layout, std::uint64_t lmd_end) {
  const std::uint32_t nfaces = layout.nfaces;
  const std::uint64_t edit_pos = layout.edit_pos, edit_size = layout.edit_size;
  edit_block.assign(nfaces, -1);
  std::uint64_t edit_start = std::max(edit_pos, lmd_end), edit_end = 0;
  if (edit_pos == 0) {
    edit_end = size;
    if (edit_start > size) edit_start = size;
  } else if (edit_size != 0) {
    if (edit_start > size || edit_size > size - edit_start) {
      return Fail("edit data of " + Num(edit_size) + " bytes at offset " + Num(edit_start) +
                  " runs past the end of the file (" + Num(size) + " bytes)");
    }
    edit_end = edit_start + edit_size;
  } else {
    edit_end = edit_start;
  }
  std::uint64_t e = edit_start;
  int edit_index = 0;
  while (e < edit_end) {
    const std::string where = "edit block " + std::to_string(edit_index) + " at offset " + Num(e);
    if (edit_end - e < 5) return Fail(where + ": truncated block prefix");
    const std::uint8_t type = data[e];
    const std::uint32_t edit_len = Load<std::uint32_t>(data + e + 1);
    if (edit_len == 0) break;  // an empty block ends the edits (the barrier reads so)
    if (edit_len > edit_end - e - 5) {
      return Fail(where + ": " + Num(edit_len) + " bytes run past the edit data");
    }
    const std::uint64_t body = e + 5;
    if (type == 0) {
      DISPEX_RETURN_IF_ERROR(ParseFaceEdit(where, body, edit_len, layout));
    } else if (type == 1) {
      DISPEX_RETURN_IF_ERROR(ParseMetaEdit(where, body, edit_len));
    }  // other edit types are skipped, as the reference reader does
    e = body + edit_len;
    ++edit_index;
  }
  return Status::Ok();
}

// A face data edit: the face's info, constant value and block replace those of the levels.
Status PtexFile::Impl::ParseFaceEdit(const std::string& where, std::uint64_t body,
                                     std::uint32_t edit_len, const Layout& layout) {
  const std::uint32_t nfaces = layout.nfaces;
  const std::uint64_t pixel = layout.pixel;
  const bool triangle = header.mesh_type == PtexMeshType::kTriangle;
  if (edit_len < kEditFaceHeaderSize + pixel) {
    return Fail(where + ": face edit of " + Num(edit_len) + " bytes is too short");
  }
  const std::uint32_t face = Load<std::uint32_t>(data + body);
  if (face >= nfaces) return Fail(where + ": face id " + Num(face) + " out of range");
  PtexFaceInfo info = DecodeFaceInfo(data + body + 4);
  const std::uint32_t fdh = Load<std::uint32_t>(data + body + 24);
  const std::string fwhere = where + " (face " + Num(face) + ")";
  if (info.ulog2 < 0 || info.ulog2 > kMaxLog2 || info.vlog2 < 0 || info.vlog2 > kMaxLog2 ||
      (triangle && info.ulog2 != info.vlog2)) {
    return Fail(fwhere + ": invalid resolution log2 (" + std::to_string(info.ulog2) + ", " +
                std::to_string(info.vlog2) + ")");
  }
  if (triangle) {
    info.adjfaces[3] = -1;
    info.adjedges[3] = 0;
  }
  for (int k = 0; k < 4; ++k) {
    if (info.adjfaces[k] < -1 || info.adjfaces[k] >= static_cast<std::int64_t>(nfaces)) {
      return Fail(fwhere + ": neighbour face " + std::to_string(info.adjfaces[k]) +
                  " out of range");
    }
  }
  if (kEditFaceHeaderSize + pixel + BlockSizeOf(fdh) != edit_len) {
    return Fail(fwhere + ": block of " + Num(BlockSizeOf(fdh)) +
                " bytes does not fill the edit's " + Num(edit_len) + " bytes");
  }
  info.has_edits = true;
  std::memcpy(const_data.data() + face * pixel, data + body + kEditFaceHeaderSize, pixel);
  faces[face] = info;
  if (!info.constant) {
    Block b;
    b.offset = body + kEditFaceHeaderSize + pixel;
    b.fdh = fdh;
    b.ulog2 = info.ulog2;
    b.vlog2 = info.vlog2;
    const std::uint32_t enc = EncodingOf(fdh), bsize = BlockSizeOf(fdh);
    if (enc == kEncConstant && bsize != pixel) {
      return Fail(fwhere + ": constant block of " + Num(bsize) + " bytes");
    }
    if (enc != kEncConstant && bsize == 0) return Fail(fwhere + ": empty data block");
    if (enc == kEncTiled) DISPEX_RETURN_IF_ERROR(ParseTiles(b, fwhere));
    edit_block[face] = static_cast<std::int32_t>(edit_blocks.size());
    edit_blocks.push_back(b);
  } else {
    edit_block[face] = -1;
  }
  header.has_edits = true;
  return Status::Ok();
}

Status PtexFile::Impl::ParseMetaEdit(const std::string& where, std::uint64_t body,
                                     std::uint32_t edit_len) {
  if (edit_len < kEditMetaHeaderSize) return Fail(where + ": meta data edit too short");
  const std::uint32_t zip = Load<std::uint32_t>(data + body);
  const std::uint32_t mem = Load<std::uint32_t>(data + body + 4);
  if (std::uint64_t{zip} + kEditMetaHeaderSize != edit_len) {
    return Fail(where + ": meta data edit of " + Num(zip) + " bytes does not fill the " +
                Num(edit_len) + "-byte block");
  }
  std::vector<std::uint8_t> block;
  DISPEX_RETURN_IF_ERROR(
      InflateSection(where + ": meta data", body + kEditMetaHeaderSize, zip, mem, block));
  std::vector<ParsedMetaRecord> records;
  std::string why = ParseMetaRecords(block, false, records);
  if (!why.empty()) return Fail(where + ": meta data: " + why);
  for (ParsedMetaRecord& r : records) UpsertMetaItem(meta, std::move(r.item));
  header.has_edits = true;
  return Status::Ok();
}

Status PtexFile::Impl::Parse() {
  Layout layout;
  DISPEX_RETURN_IF_ERROR(ParseHeaders(layout));
  DISPEX_RETURN_IF_ERROR(ParseFaceInfo(layout));
  DISPEX_RETURN_IF_ERROR(InflateSection("constant data", layout.const_pos, layout.const_zip,
                                        std::uint64_t{layout.nfaces} * layout.pixel, const_data));
  ComputeReductionOrder();
  DISPEX_RETURN_IF_ERROR(ParseLevels(layout));
  std::uint64_t meta_end = 0;
  DISPEX_RETURN_IF_ERROR(ParseMetaData(layout, meta_end));
  DISPEX_RETURN_IF_ERROR(ParseEdits(layout, meta_end));
  sample_cache = std::make_unique<std::atomic<std::vector<float>*>[]>(layout.nfaces);
  for (std::uint32_t f = 0; f < layout.nfaces; ++f) sample_cache[f].store(nullptr);
  return Status::Ok();
}

// ---- Public entry points -------------------------------------------------------------------

PtexFile::PtexFile() = default;
PtexFile::PtexFile(PtexFile&&) noexcept = default;
PtexFile& PtexFile::operator=(PtexFile&&) noexcept = default;
PtexFile::~PtexFile() = default;

StatusOr<PtexFile> PtexFile::Open(const std::string& path, const PtexReadOptions& options) {
  auto bad = [&](const Status& status) {
    return status.WithCode(StatusCode::kBadInput).WithPath(path);
  };
  StatusOr<MappedFile> mapped = MappedFile::Open(path);
  if (!mapped.ok()) return bad(mapped.status());
  PtexFile file;
  file.impl_ = std::make_unique<Impl>();
  Impl& impl = *file.impl_;
  impl.name = path;
  impl.options = options;
  impl.mapped.emplace(std::move(mapped).value());
  impl.data = reinterpret_cast<const std::uint8_t*>(impl.mapped->data());
  impl.size = impl.mapped->size();
  const Status parsed = impl.Parse();
  if (!parsed.ok()) return bad(parsed);
  return file;
}

StatusOr<PtexFile> ParsePtex(std::string_view bytes, const std::string& name,
                             const PtexReadOptions& options) {
  PtexFile file;
  file.impl_ = std::make_unique<PtexFile::Impl>();
  PtexFile::Impl& impl = *file.impl_;
  impl.name = name;
  impl.options = options;
  impl.owned.assign(bytes.begin(), bytes.end());
  impl.data = impl.owned.data();
  impl.size = impl.owned.size();
  DISPEX_RETURN_IF_ERROR(impl.Parse());
  return file;
}

const std::string& PtexFile::name() const {
  return impl_->name;
}
const PtexHeaderInfo& PtexFile::header() const {
  return impl_->header;
}
int PtexFile::num_faces() const {
  return impl_ ? impl_->header.num_faces : 0;
}
const PtexFaceInfo& PtexFile::face_info(PtexFaceId face) const {
  DISPEX_CHECK(face.value >= 0 && face.value < num_faces());
  return impl_->faces[std::size_t(face.value)];
}
std::span<const PtexLevelInfo> PtexFile::levels() const {
  return impl_->levels;
}
std::span<const PtexMetaItem> PtexFile::meta_data() const {
  return impl_->meta;
}

const PtexMetaItem* PtexFile::FindMetaData(std::string_view key) const {
  for (const PtexMetaItem& item : impl_->meta) {
    if (item.key == key) return &item;
  }
  return nullptr;
}

}  // namespace dispex
