// PtexWriter: a streaming writer of Ptex 1.4 files (docs/ptex.md, "File layout" to "Meta data
// records", and "What the writer always writes").
//
// It follows the reference writer (wdas/ptex PtexWriter.cpp) in everything that decides the
// file's bytes: which reductions are stored (levels 1 .. min(ulog2, vlog2) - 2), their
// order (the stable "reduction order"), how they are computed, the tiling rule, the
// encodings (diff-zipped for integers), constant detection, meta data layout. It differs
// where the reference writer is wrong or wasteful: the 8-byte barrier is always written,
// averages are exact means, and every face is compressed when it is submitted (from any
// thread; the tiles of a large face in parallel with TBB), so only compressed blocks are held
// until Finish() lays them out in order. With PtexCompressor::kZlib at level 6 the file
// equals the reference writer's, plus the barrier (tests/ptex/fixture_write_test.cpp).
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <mutex>
#include <span>

#include "core/atomic_output.h"
#include "core/check.h"
#include "core/hash128.h"
#include "dispex/ptex.h"
#include "ptex/format.h"
#include "ptex/meta_data.h"
#include "ptex/texel_ops.h"
#include "ptex/zlib_block.h"

namespace dispex {

using namespace ptex;

namespace {

constexpr int kMaxChannels = 1024;
constexpr int kMaxFaces = 1 << 28;
constexpr std::size_t kMaxFaceBytes = std::size_t{1} << 29;

enum FaceState : std::uint8_t { kUnset = 0, kBusy = 1, kSet = 2 };

// A face's record as the file stores it: flags cleared (constant is the writer's to set),
// none on triangles, no edge id where there is no neighbour.
PtexFaceInfo StoredInfo(const PtexFaceInfo& given, PtexMeshType mesh_type) {
  PtexFaceInfo info = given;
  info.constant = info.neighborhood_constant = info.has_edits = false;
  if (mesh_type == PtexMeshType::kTriangle) {
    info.subface = false;  // no flags on triangles but constant (as the reference)
    info.adjfaces[3] = -1;
  }
  for (int e = 0; e < 4; ++e) {
    if (info.adjfaces[e] < 0) info.adjedges[e] = 0;
  }
  return info;
}

// Per-thread buffers reused across faces (no allocation per face once warm).
struct Scratch {
  std::vector<std::uint8_t> converted;  // the face in the file's type
  std::vector<std::uint8_t> premult;    // alpha-premultiplied copy
  std::vector<std::uint8_t> reduce_a, reduce_b;
  std::vector<std::uint8_t> split;    // channel planes of one block
  std::vector<std::uint8_t> staging;  // the face's compressed blocks, all levels
  std::vector<std::uint8_t> tile_header;
};

Scratch& ThreadScratch() {
  thread_local Scratch scratch;
  return scratch;
}

// Writes through AtomicOutput in large chunks.
class BufferedOutput {
 public:
  explicit BufferedOutput(AtomicOutput& out) : out_(out) { buffer_.reserve(kSize); }
  Status Write(const void* data, std::size_t n) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    if (buffer_.size() + n > kSize) {
      DISPEX_RETURN_IF_ERROR(Flush());
      if (n >= kSize) return out_.Write(p, n);
    }
    buffer_.insert(buffer_.end(), p, p + n);
    return Status::Ok();
  }
  Status Write(std::span<const std::uint8_t> bytes) { return Write(bytes.data(), bytes.size()); }
  Status Flush() {
    if (buffer_.empty()) return Status::Ok();
    Status s = out_.Write(buffer_.data(), buffer_.size());
    buffer_.clear();
    return s;
  }
  std::uint64_t written() const { return out_.bytes_written() + buffer_.size(); }

 private:
  static constexpr std::size_t kSize = 1 << 20;
  AtomicOutput& out_;
  std::vector<std::uint8_t> buffer_;
};

// The compressed sections of the file and their sizes, in file order (WriteFile's steps).
struct FileSections {
  std::vector<std::int32_t> order;           // the reduction order of the faces
  std::vector<std::uint32_t> level_entries;  // per level: its faces
  std::vector<std::uint8_t> face_info_zip, const_zip;
  std::vector<std::vector<std::uint8_t>> level_header_zip;  // per level
  std::vector<std::uint64_t> level_size;                    // per level: headers and blocks
  std::uint64_t level_data_total = 0;
  // Meta data: small items in one block, large ones after the barrier.
  std::vector<std::uint8_t> small_raw, small_zip, lmd_header_raw, lmd_header_zip;
  std::vector<std::vector<std::uint8_t>> lmd_values;
  std::uint64_t lmd_data_size = 0;
  std::uint64_t file_size = 0;

  std::size_t num_levels() const { return level_entries.size(); }
  // The size of the file they make up.
  std::uint64_t Total() const {
    return kHeaderSize + kExtHeaderSize + face_info_zip.size() + const_zip.size() +
           kLevelInfoSize * num_levels() + level_data_total + small_zip.size() + kBarrierSize +
           lmd_header_zip.size() + lmd_data_size;
  }
  // Whether a section the header gives a 32-bit size exceeds it.
  bool OverSectionLimit() const {
    return face_info_zip.size() > 0xffffffffull || const_zip.size() > 0xffffffffull ||
           small_raw.size() > 0xffffffffull || lmd_header_raw.size() > 0xffffffffull;
  }
};

}  // namespace

struct PtexWriter::Impl {
  std::string path;
  PtexWriterOptions options;
  int level = 1;
  int num_faces = 0;
  int data_size = 4;
  int pixel_size = 4;
  AtomicOutput output;
  std::atomic<bool> finished{false};

  struct Face {
    PtexFaceInfo info;
    std::vector<std::uint8_t> blocks;    // level 0 block, then each stored reduction's
    std::vector<std::uint32_t> headers;  // FaceDataHeader of level 0 and each reduction
  };
  std::vector<Face> faces;
  std::unique_ptr<std::atomic<std::uint8_t>[]> state;
  std::vector<std::uint8_t> const_data;  // num_faces x pixel_size
  std::atomic<int> faces_set{0};
  std::atomic<std::size_t> compressed_bytes{0};

  std::mutex meta_mutex;
  std::vector<PtexMetaItem> meta;

  std::string FaceName(int face) const { return path + ": face " + std::to_string(face); }

  Status CheckFace(PtexFaceId face, const PtexFaceInfo& info) const;
  Status Claim(PtexFaceId face);
  void StoreFace(int face, const PtexFaceInfo& info, const std::uint8_t* data);
  std::uint32_t WriteFaceData(const std::uint8_t* data, int ulog2, int vlog2, Scratch& s) const;
  std::uint32_t WriteFaceBlock(const std::uint8_t* data, std::size_t stride, int ures, int vres,
                               std::vector<std::uint8_t>& split,
                               std::vector<std::uint8_t>& out) const;
  // `finishing`: added by Finish() itself, after which no one else may add.
  Status AddMeta(const std::string& key, PtexMetaType type, const void* data, std::size_t bytes,
                 bool finishing = false);
  Status WriteFile();
  // WriteFile's steps, in order.
  std::vector<PtexFaceInfo> CloseUnsetFaces();
  std::vector<std::uint32_t> LevelEntries(std::span<const std::int32_t> order) const;
  void CompressLevels(const std::vector<PtexFaceInfo>& infos, FileSections& sections) const;
  void CompressMetaData(FileSections& sections) const;
  std::vector<std::uint8_t> EncodeHeaders(const FileSections& sections) const;
  template <class Visit>
  Status ForEachLevelDataPiece(const FileSections& sections, Visit&& visit) const;
  Status WriteSections(const FileSections& sections);
};

// ---- Construction -------------------------------------------------------------------------

std::string PtexEncodingName(const PtexWriterOptions& options) {
  const int level = options.compression_level < 0 ? DefaultCompressionLevel(options.compressor)
                                                  : options.compression_level;
  std::string name = CompressorName(options.compressor) + " level " + std::to_string(level) + ", " +
                     std::string(PtexMeshTypeName(options.mesh_type)) + " " +
                     std::string(PtexDataTypeName(options.data_type)) + " x" +
                     std::to_string(options.num_channels);
  if (options.alpha_channel >= 0) name += ", alpha " + std::to_string(options.alpha_channel);
  if (options.write_reductions) name += ", reductions";
  if (options.tile_large_faces) name += ", tiles";
  return name;
}

PtexWriter::PtexWriter() = default;
PtexWriter::PtexWriter(PtexWriter&&) noexcept = default;
PtexWriter& PtexWriter::operator=(PtexWriter&&) noexcept = default;
PtexWriter::~PtexWriter() = default;

StatusOr<PtexWriter> PtexWriter::Create(const std::string& path, const PtexWriterOptions& options,
                                        int num_faces) {
  auto fail = [&](const std::string& what) { return Status::Error(path + ": " + what); };
  if (options.num_channels < 1 || options.num_channels > kMaxChannels) {
    return fail("channel count " + std::to_string(options.num_channels) + " is not in 1.." +
                std::to_string(kMaxChannels));
  }
  if (options.alpha_channel < -1 || options.alpha_channel >= options.num_channels) {
    return fail("alpha channel " + std::to_string(options.alpha_channel) +
                " is not -1 or a channel index below " + std::to_string(options.num_channels));
  }
  if (static_cast<int>(options.data_type) > 3 || static_cast<int>(options.mesh_type) > 1 ||
      static_cast<int>(options.u_border) > 2 || static_cast<int>(options.v_border) > 2 ||
      static_cast<int>(options.edge_filter) > 1) {
    return fail("invalid data type, mesh type, border mode or edge filter mode");
  }
  if (std::string why = CheckCompressionLevel(options.compressor, options.compression_level);
      !why.empty()) {
    return fail(why);
  }
  if (options.level_data_hash_key.size() > 254 ||
      options.level_data_hash_key.find('\0') != std::string::npos) {
    return fail("the level data hash's meta data key is not 1..254 bytes without NUL");
  }
  if (num_faces < 1 || num_faces > kMaxFaces) {
    return fail("face count " + std::to_string(num_faces) + " is not in 1.." +
                std::to_string(kMaxFaces));
  }
  DISPEX_ASSIGN_OR_RETURN(AtomicOutput output, AtomicOutput::Create(path));

  PtexWriter writer;
  writer.impl_ = std::make_unique<Impl>();
  Impl& w = *writer.impl_;
  w.path = path;
  w.options = options;
  w.level = options.compression_level < 0 ? DefaultCompressionLevel(options.compressor)
                                          : options.compression_level;
  w.num_faces = num_faces;
  w.data_size = PtexDataSize(options.data_type);
  w.pixel_size = w.data_size * options.num_channels;
  w.output = std::move(output);
  w.faces.resize(static_cast<std::size_t>(num_faces));
  w.state = std::make_unique<std::atomic<std::uint8_t>[]>(static_cast<std::size_t>(num_faces));
  for (int i = 0; i < num_faces; ++i) w.state[i].store(kUnset, std::memory_order_relaxed);
  w.const_data.assign(static_cast<std::size_t>(num_faces) * w.pixel_size, 0);
  return writer;
}

int PtexWriter::faces_set() const {
  return impl_ ? impl_->faces_set.load() : 0;
}
std::size_t PtexWriter::compressed_bytes() const {
  return impl_ ? impl_->compressed_bytes.load() : 0;
}
const PtexWriterOptions& PtexWriter::options() const {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->options;
}

// ---- Faces --------------------------------------------------------------------------------

Status PtexWriter::Impl::CheckFace(PtexFaceId face, const PtexFaceInfo& info) const {
  if (finished) return Status::Error(path + ": face set after Finish()");
  if (face.value < 0 || face.value >= num_faces) {
    return Status::Error(path + ": face id " + std::to_string(face.value) + " is not in 0.." +
                         std::to_string(num_faces - 1));
  }
  const std::string name = FaceName(face.value);
  if (info.ulog2 < 0 || info.ulog2 > kMaxLog2 || info.vlog2 < 0 || info.vlog2 > kMaxLog2) {
    return Status::Error(name + ": resolution log2 (" + std::to_string(info.ulog2) + ", " +
                         std::to_string(info.vlog2) + ") is not in 0.." + std::to_string(kMaxLog2));
  }
  if (info.num_texels() * std::size_t(pixel_size) > kMaxFaceBytes) {
    return Status::Error(name + ": " + std::to_string(info.ures()) + "x" +
                         std::to_string(info.vres()) + " texels exceed " +
                         std::to_string(kMaxFaceBytes) + " bytes");
  }
  const bool triangle = options.mesh_type == PtexMeshType::kTriangle;
  if (triangle && info.ulog2 != info.vlog2) {
    return Status::Error(name + ": triangle faces must have a square resolution, got log2 (" +
                         std::to_string(info.ulog2) + ", " + std::to_string(info.vlog2) + ")");
  }
  for (int e = 0; e < (triangle ? 3 : 4); ++e) {
    if (info.adjfaces[e] < -1 || info.adjfaces[e] >= num_faces) {
      return Status::Error(name + ": neighbour across edge " + std::to_string(e) + " is face " +
                           std::to_string(info.adjfaces[e]) + ", not -1 or a face id");
    }
    if (info.adjedges[e] > (triangle ? 2 : 3)) {
      return Status::Error(name + ": neighbour edge id " + std::to_string(info.adjedges[e]) +
                           " across edge " + std::to_string(e) + " is out of range");
    }
  }
  return Status::Ok();
}

Status PtexWriter::Impl::Claim(PtexFaceId face) {
  std::uint8_t expected = kUnset;
  if (!state[face.value].compare_exchange_strong(expected, kBusy)) {
    return Status::Error(FaceName(face.value) + ": set twice");
  }
  return Status::Ok();
}

// Blocks of one face at one level: a single block, or tiles by the reference rule. Tiles
// are compressed in parallel (each into its own buffer, joined in tile order, so the bytes
// do not depend on scheduling); the work is isolated so that a thread waiting here never
// picks up another face's SetFace and reuses this thread's scratch buffers.
std::uint32_t PtexWriter::Impl::WriteFaceData(const std::uint8_t* data, int ulog2, int vlog2,
                                              Scratch& s) const {
  int tile_ulog2 = ulog2, tile_vlog2 = vlog2;
  if (options.tile_large_faces) TileResolution(ulog2, vlog2, pixel_size, tile_ulog2, tile_vlog2);
  const int ures = 1 << ulog2, vres = 1 << vlog2;
  const std::size_t stride = std::size_t(ures) * pixel_size;
  if (tile_ulog2 == ulog2 && tile_vlog2 == vlog2) {
    return WriteFaceBlock(data, stride, ures, vres, s.split, s.staging);
  }
  const int tures = 1 << tile_ulog2, tvres = 1 << tile_vlog2;
  const int ntilesu = ures / tures, ntiles = ntilesu * (vres / tvres);
  std::vector<std::vector<std::uint8_t>> tiles(static_cast<std::size_t>(ntiles));
  std::vector<std::uint32_t> headers(static_cast<std::size_t>(ntiles));
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(0, ntiles, [&](int t) {
      thread_local std::vector<std::uint8_t> split;
      const int tu = t % ntilesu, tv = t / ntilesu;
      const std::uint8_t* tile =
          data + std::size_t(tv) * tvres * stride + std::size_t(tu) * tures * pixel_size;
      std::vector<std::uint8_t>& out = tiles[std::size_t(t)];
      if (IsConstant(tile, stride, tures, tvres, pixel_size)) {
        out.assign(tile, tile + pixel_size);
        headers[std::size_t(t)] =
            PackDataHeader(static_cast<std::uint32_t>(pixel_size), kEncConstant);
      } else {
        headers[std::size_t(t)] = WriteFaceBlock(tile, stride, tures, tvres, split, out);
      }
    });
  });
  s.tile_header.clear();
  for (std::uint32_t h : headers) Append<std::uint32_t>(s.tile_header, h);
  const std::size_t start = s.staging.size();
  s.staging.push_back(static_cast<std::uint8_t>(tile_ulog2));
  s.staging.push_back(static_cast<std::uint8_t>(tile_vlog2));
  s.staging.resize(s.staging.size() + 4);
  const std::size_t header_size =
      CompressAppend(s.tile_header, options.compressor, level, s.staging);
  Store<std::uint32_t>(s.staging.data() + start + 2, static_cast<std::uint32_t>(header_size));
  for (const auto& tile : tiles) AppendBytes(s.staging, tile.data(), tile.size());
  const std::size_t total = s.staging.size() - start;
  DISPEX_CHECK_LE(total, std::size_t{kMaxBlockSize});
  return PackDataHeader(static_cast<std::uint32_t>(total), kEncTiled);
}

// One zipped (float, half) or diff-zipped (integer) block: channel split, difference, zlib.
std::uint32_t PtexWriter::Impl::WriteFaceBlock(const std::uint8_t* data, std::size_t stride,
                                               int ures, int vres, std::vector<std::uint8_t>& split,
                                               std::vector<std::uint8_t>& out) const {
  const std::size_t bytes = std::size_t(ures) * vres * pixel_size;
  split.resize(bytes);
  SplitChannels(data, stride, ures, vres, options.num_channels, data_size, split.data());
  const bool diff =
      options.data_type == PtexDataType::kUint8 || options.data_type == PtexDataType::kUint16;
  if (diff) EncodeDifference(split.data(), bytes, options.data_type);
  const std::size_t n = CompressAppend(split, options.compressor, level, out);
  DISPEX_CHECK_LE(n, std::size_t{kMaxBlockSize});
  return PackDataHeader(static_cast<std::uint32_t>(n), diff ? kEncDiffZipped : kEncZipped);
}

// Stores a checked face whose texels are in the file's type: constant, or its level-0 block,
// its reductions and its average.
void PtexWriter::Impl::StoreFace(int face_id, const PtexFaceInfo& given, const std::uint8_t* data) {
  Face& face = faces[static_cast<std::size_t>(face_id)];
  PtexFaceInfo info = StoredInfo(given, options.mesh_type);
  std::uint8_t* average = const_data.data() + std::size_t(face_id) * pixel_size;
  const int ures = info.ures(), vres = info.vres();
  const std::size_t count = info.num_texels();

  if (IsConstant(data, std::size_t(ures) * pixel_size, ures, vres, pixel_size)) {
    info.constant = true;
    std::memcpy(average, data, pixel_size);
    face.info = info;
    face.headers.assign(1, 0);
    face.blocks.clear();
    return;
  }

  Scratch& s = ThreadScratch();
  s.staging.clear();
  const int reductions = options.write_reductions ? StoredReductions(info) : 0;
  face.headers.assign(1 + std::size_t(reductions), 0);
  face.headers[0] = WriteFaceData(data, info.ulog2, info.vlog2, s);

  // Reductions and the average are computed from premultiplied texels (docs/ptex.md,
  // "Premultiplication for reductions").
  const std::uint8_t* base = data;
  if (options.alpha_channel >= 0) {
    s.premult.assign(data, data + count * pixel_size);
    MultiplyAlpha(s.premult.data(), count, options.data_type, options.num_channels,
                  options.alpha_channel);
    base = s.premult.data();
  }
  const std::uint8_t* cur = base;
  for (int level_index = 1; level_index <= reductions; ++level_index) {
    const int ul = info.ulog2 - level_index + 1, vl = info.vlog2 - level_index + 1;
    std::vector<std::uint8_t>& next = (level_index % 2) ? s.reduce_a : s.reduce_b;
    next.resize((std::size_t{1} << (ul + vl - 2)) * pixel_size);
    if (options.mesh_type == PtexMeshType::kTriangle) {
      ReduceTriangle(cur, ul, options.data_type, options.num_channels, next.data());
    } else {
      ReduceQuad(cur, ul, vl, options.data_type, options.num_channels, next.data());
    }
    face.headers[std::size_t(level_index)] = WriteFaceData(next.data(), ul - 1, vl - 1, s);
    cur = next.data();
  }
  Average(base, count, options.data_type, options.num_channels, average);
  if (options.alpha_channel >= 0) {
    DivideAlpha(average, 1, options.data_type, options.num_channels, options.alpha_channel);
  }
  face.info = info;
  face.blocks.assign(s.staging.begin(), s.staging.end());  // exact size, no slack kept
  compressed_bytes.fetch_add(face.blocks.size(), std::memory_order_relaxed);
}

Status PtexWriter::SetFace(PtexFaceId face, const PtexFaceInfo& info,
                           std::span<const float> texels) {
  DISPEX_CHECK(impl_ != nullptr);
  Impl& w = *impl_;
  DISPEX_RETURN_IF_ERROR(w.CheckFace(face, info));
  const std::size_t values = info.num_texels() * std::size_t(w.options.num_channels);
  if (texels.size() != values) {
    return Status::Error(
        w.FaceName(face.value) + ": " + std::to_string(texels.size()) + " values given, " +
        std::to_string(info.ures()) + "x" + std::to_string(info.vres()) + " texels of " +
        std::to_string(w.options.num_channels) + " channels need " + std::to_string(values));
  }
  if (std::ptrdiff_t bad = FirstNonFinite(texels.data(), texels.size()); bad >= 0) {
    return Status::Error(w.FaceName(face.value) + ": texel " +
                         std::to_string(bad / w.options.num_channels) + " channel " +
                         std::to_string(bad % w.options.num_channels) + " is not finite");
  }
  DISPEX_RETURN_IF_ERROR(w.Claim(face));
  Scratch& s = ThreadScratch();
  s.converted.resize(values * std::size_t(w.data_size));
  FromFloat(texels.data(), values, w.options.data_type, s.converted.data());
  w.StoreFace(face.value, info, s.converted.data());
  w.faces_set.fetch_add(1);
  w.state[face.value].store(kSet, std::memory_order_release);
  return Status::Ok();
}

Status PtexWriter::SetFaceRaw(PtexFaceId face, const PtexFaceInfo& info,
                              std::span<const std::uint8_t> data) {
  DISPEX_CHECK(impl_ != nullptr);
  Impl& w = *impl_;
  DISPEX_RETURN_IF_ERROR(w.CheckFace(face, info));
  const std::size_t bytes = info.num_texels() * std::size_t(w.pixel_size);
  if (data.size() != bytes) {
    return Status::Error(w.FaceName(face.value) + ": " + std::to_string(data.size()) +
                         " bytes given, " + std::to_string(info.ures()) + "x" +
                         std::to_string(info.vres()) + " texels need " + std::to_string(bytes));
  }
  DISPEX_RETURN_IF_ERROR(w.Claim(face));
  w.StoreFace(face.value, info, data.data());
  w.faces_set.fetch_add(1);
  w.state[face.value].store(kSet, std::memory_order_release);
  return Status::Ok();
}

Status PtexWriter::SetEncodedFace(PtexFaceId face, const PtexFaceInfo& info,
                                  const PtexEncodedFace& encoded) {
  DISPEX_CHECK(impl_ != nullptr);
  Impl& w = *impl_;
  DISPEX_RETURN_IF_ERROR(w.CheckFace(face, info));
  const auto fail = [&](const std::string& what) {
    return Status::Error(w.FaceName(face.value) + ": the encoded face " + what);
  };
  if (encoded.ulog2 != info.ulog2 || encoded.vlog2 != info.vlog2) {
    return fail("has resolution log2 (" + std::to_string(encoded.ulog2) + ", " +
                std::to_string(encoded.vlog2) + "), not the face's (" + std::to_string(info.ulog2) +
                ", " + std::to_string(info.vlog2) + ")");
  }
  if (encoded.average.size() != std::size_t(w.pixel_size)) {
    return fail("has texels of " + std::to_string(encoded.average.size()) +
                " bytes, the file's have " + std::to_string(w.pixel_size));
  }
  const std::size_t levels =
      encoded.constant ? 1
                       : 1 + std::size_t(w.options.write_reductions ? StoredReductions(info) : 0);
  if (encoded.headers.size() != levels) {
    return fail("stores " + std::to_string(encoded.headers.size()) + " levels, this file " +
                std::to_string(levels));
  }
  std::size_t bytes = 0;
  for (std::uint32_t h : encoded.headers) bytes += BlockSizeOf(h);
  if (bytes != encoded.blocks.size() || (encoded.constant && bytes != 0)) {
    return fail("has " + std::to_string(encoded.blocks.size()) +
                " bytes of blocks, its headers say " + std::to_string(bytes));
  }
  DISPEX_RETURN_IF_ERROR(w.Claim(face));
  Impl::Face& stored = w.faces[static_cast<std::size_t>(face.value)];
  stored.info = StoredInfo(info, w.options.mesh_type);
  stored.info.constant = encoded.constant;
  stored.headers = encoded.headers;
  stored.blocks = encoded.blocks;
  std::memcpy(w.const_data.data() + std::size_t(face.value) * w.pixel_size, encoded.average.data(),
              encoded.average.size());
  w.compressed_bytes.fetch_add(stored.blocks.size(), std::memory_order_relaxed);
  w.faces_set.fetch_add(1);
  w.state[face.value].store(kSet, std::memory_order_release);
  return Status::Ok();
}

Status PtexWriter::SetConstantFace(PtexFaceId face, const PtexFaceInfo& info,
                                   std::span<const float> value) {
  DISPEX_CHECK(impl_ != nullptr);
  Impl& w = *impl_;
  DISPEX_RETURN_IF_ERROR(w.CheckFace(face, info));
  if (value.size() != std::size_t(w.options.num_channels)) {
    return Status::Error(w.FaceName(face.value) + ": constant value has " +
                         std::to_string(value.size()) + " channels, the file " +
                         std::to_string(w.options.num_channels));
  }
  if (FirstNonFinite(value.data(), value.size()) >= 0) {
    return Status::Error(w.FaceName(face.value) + ": constant value is not finite");
  }
  DISPEX_RETURN_IF_ERROR(w.Claim(face));
  std::vector<std::uint8_t> texel(static_cast<std::size_t>(w.pixel_size));
  FromFloat(value.data(), value.size(), w.options.data_type, texel.data());
  // A one-texel buffer is constant whatever the logical resolution: store it as 1x1 data and
  // restore the resolution.
  PtexFaceInfo one = info;
  one.ulog2 = one.vlog2 = 0;
  w.StoreFace(face.value, one, texel.data());
  w.faces[static_cast<std::size_t>(face.value)].info.ulog2 = info.ulog2;
  w.faces[static_cast<std::size_t>(face.value)].info.vlog2 = info.vlog2;
  w.faces_set.fetch_add(1);
  w.state[face.value].store(kSet, std::memory_order_release);
  return Status::Ok();
}

// ---- Meta data ----------------------------------------------------------------------------

Status PtexWriter::Impl::AddMeta(const std::string& key, PtexMetaType type, const void* data,
                                 std::size_t bytes, bool finishing) {
  if (key.empty() || key.size() > 254) {
    return Status::Error(path + ": meta data key '" + key.substr(0, 40) + "' has " +
                         std::to_string(key.size()) + " bytes, must have 1..254");
  }
  if (key.find('\0') != std::string::npos) {
    return Status::Error(path + ": meta data key contains a NUL byte");
  }
  if (bytes == 0) return Status::Error(path + ": meta data '" + key + "' has no values");
  if (bytes > 0xffffffffull) return Status::Error(path + ": meta data '" + key + "' is too large");
  PtexMetaItem item;
  item.key = key;
  item.type = type;
  const auto* p = static_cast<const std::uint8_t*>(data);
  item.bytes.assign(p, p + bytes);
  item.large = bytes > kMetaDataThreshold;
  std::lock_guard<std::mutex> lock(meta_mutex);
  if (finished && !finishing) return Status::Error(path + ": meta data added after Finish()");
  UpsertMetaItem(meta, std::move(item));
  return Status::Ok();
}

Status PtexWriter::AddMetaData(const std::string& key, std::string_view value) {
  DISPEX_CHECK(impl_ != nullptr);
  if (value.find('\0') != std::string_view::npos) {
    return Status::Error(impl_->path + ": meta data string '" + key + "' contains a NUL byte");
  }
  std::string with_nul(value);
  with_nul.push_back('\0');
  return impl_->AddMeta(key, PtexMetaType::kString, with_nul.data(), with_nul.size());
}
Status PtexWriter::AddMetaData(const std::string& key, std::span<const std::int8_t> values) {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->AddMeta(key, PtexMetaType::kInt8, values.data(), values.size_bytes());
}
Status PtexWriter::AddMetaData(const std::string& key, std::span<const std::int16_t> values) {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->AddMeta(key, PtexMetaType::kInt16, values.data(), values.size_bytes());
}
Status PtexWriter::AddMetaData(const std::string& key, std::span<const std::int32_t> values) {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->AddMeta(key, PtexMetaType::kInt32, values.data(), values.size_bytes());
}
Status PtexWriter::AddMetaData(const std::string& key, std::span<const float> values) {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->AddMeta(key, PtexMetaType::kFloat, values.data(), values.size_bytes());
}
Status PtexWriter::AddMetaData(const std::string& key, std::span<const double> values) {
  DISPEX_CHECK(impl_ != nullptr);
  return impl_->AddMeta(key, PtexMetaType::kDouble, values.data(), values.size_bytes());
}

// ---- Assembly -----------------------------------------------------------------------------

Status PtexWriter::Finish() {
  DISPEX_CHECK(impl_ != nullptr);
  Impl& w = *impl_;
  {
    std::lock_guard<std::mutex> lock(w.meta_mutex);
    if (w.finished) return Status::Error(w.path + ": Finish() called twice");
    w.finished = true;
  }
  Status s = w.WriteFile();
  if (!s.ok()) {
    w.output.Abandon();
    return s;
  }
  return w.output.Commit();
}

Status PtexWriter::Impl::WriteFile() {
  const std::vector<PtexFaceInfo> infos = CloseUnsetFaces();
  FileSections sections;
  CompressLevels(infos, sections);
  if (!options.level_data_hash_key.empty()) {
    Hasher hasher;
    DISPEX_RETURN_IF_ERROR(
        ForEachLevelDataPiece(sections, [&](const std::uint8_t* data, std::size_t size) {
          hasher.Add(std::as_bytes(std::span(data, size)));
          return Status::Ok();
        }));
    const std::string hex = hasher.Digest().Hex();
    DISPEX_RETURN_IF_ERROR(AddMeta(options.level_data_hash_key, PtexMetaType::kString, hex.c_str(),
                                   hex.size() + 1, /*finishing=*/true));
  }
  CompressMetaData(sections);
  if (sections.OverSectionLimit()) {
    return Status::Error(path + ": a section exceeds the format's 4 GiB section limit");
  }
  sections.file_size = sections.Total();
  return WriteSections(sections);
}

// Faces never set become constant zero, 1x1, with no neighbours (as the reference writer).
// Returns every face's info.
std::vector<PtexFaceInfo> PtexWriter::Impl::CloseUnsetFaces() {
  const std::size_t n = faces.size();
  for (std::size_t f = 0; f < n; ++f) {
    const std::uint8_t st = state[f].load(std::memory_order_acquire);
    DISPEX_CHECK_NE(st, std::uint8_t{kBusy});  // contract: no SetFace in flight
    if (st == kUnset) {
      faces[f].info = PtexFaceInfo{};
      faces[f].info.constant = true;
      faces[f].headers.assign(1, 0);
    }
  }
  std::vector<PtexFaceInfo> infos(n);
  for (std::size_t f = 0; f < n; ++f) infos[f] = faces[f].info;
  return infos;
}

// The faces of each level: level L >= 1 holds the faces with at least L stored reductions,
// which are a prefix of the reduction order.
std::vector<std::uint32_t> PtexWriter::Impl::LevelEntries(
    std::span<const std::int32_t> order) const {
  const std::size_t n = faces.size();
  std::vector<std::uint32_t> level_entries(1, static_cast<std::uint32_t>(n));
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t reductions = faces[std::size_t(order[r])].headers.size() - 1;
    while (level_entries.size() <= reductions) level_entries.push_back(0);
    for (std::size_t l = 1; l <= reductions; ++l) {
      DISPEX_CHECK_EQ(level_entries[l], static_cast<std::uint32_t>(r));  // prefix property
      level_entries[l] = static_cast<std::uint32_t>(r + 1);
    }
  }
  return level_entries;
}

// The face info and constant data compressed, and each level's face data headers; the
// levels' sizes.
void PtexWriter::Impl::CompressLevels(const std::vector<PtexFaceInfo>& infos,
                                      FileSections& x) const {
  const std::size_t n = faces.size();
  x.order = ReductionOrder(infos);
  x.level_entries = LevelEntries(x.order);
  const std::size_t nlevels = x.num_levels();
  std::vector<std::uint8_t> face_info_raw(n * kFaceInfoSize);
  for (std::size_t f = 0; f < n; ++f) EncodeFaceInfo(infos[f], &face_info_raw[f * kFaceInfoSize]);
  CompressAppend(face_info_raw, options.compressor, level, x.face_info_zip);
  CompressAppend(const_data, options.compressor, level, x.const_zip);

  x.level_header_zip.resize(nlevels);
  x.level_size.resize(nlevels);
  for (std::size_t l = 0; l < nlevels; ++l) {
    std::vector<std::uint8_t> raw;
    raw.reserve(x.level_entries[l] * 4);
    std::uint64_t blocks = 0;
    for (std::size_t r = 0; r < x.level_entries[l]; ++r) {
      const Face& face = faces[l == 0 ? r : std::size_t(x.order[r])];
      Append<std::uint32_t>(raw, face.headers[l]);
      blocks += BlockSizeOf(face.headers[l]);
    }
    CompressAppend(raw, options.compressor, level, x.level_header_zip[l]);
    x.level_size[l] = x.level_header_zip[l].size() + blocks;
    x.level_data_total += x.level_size[l];
  }
}

// Meta data: small items in one block, large ones after the barrier.
void PtexWriter::Impl::CompressMetaData(FileSections& x) const {
  for (const PtexMetaItem& item : meta) {
    if (!item.large) AppendMetaRecord(item, -1, x.small_raw);
  }
  for (const PtexMetaItem& item : meta) {
    if (!item.large) continue;
    x.lmd_values.emplace_back();
    const std::size_t zipsize =
        CompressAppend(item.bytes, options.compressor, level, x.lmd_values.back());
    AppendMetaRecord(item, static_cast<std::int64_t>(zipsize), x.lmd_header_raw);
  }
  if (!x.small_raw.empty()) CompressAppend(x.small_raw, options.compressor, level, x.small_zip);
  if (!x.lmd_header_raw.empty()) {
    CompressAppend(x.lmd_header_raw, options.compressor, level, x.lmd_header_zip);
  }
  for (const auto& v : x.lmd_values) x.lmd_data_size += v.size();
}

// The header and the extended header.
std::vector<std::uint8_t> PtexWriter::Impl::EncodeHeaders(const FileSections& x) const {
  std::vector<std::uint8_t> header(kHeaderSize + kExtHeaderSize, 0);
  std::uint8_t* h = header.data();
  Store<std::uint32_t>(h + 0, kMagic);
  Store<std::uint32_t>(h + 4, kMajorVersion);
  Store<std::uint32_t>(h + 8, static_cast<std::uint32_t>(options.mesh_type));
  Store<std::uint32_t>(h + 12, static_cast<std::uint32_t>(options.data_type));
  Store<std::int32_t>(h + 16, options.alpha_channel);
  Store<std::uint16_t>(h + 20, static_cast<std::uint16_t>(options.num_channels));
  Store<std::uint16_t>(h + 22, static_cast<std::uint16_t>(x.num_levels()));
  Store<std::uint32_t>(h + 24, static_cast<std::uint32_t>(faces.size()));
  Store<std::uint32_t>(h + 28, static_cast<std::uint32_t>(kExtHeaderSize));
  Store<std::uint32_t>(h + 32, static_cast<std::uint32_t>(x.face_info_zip.size()));
  Store<std::uint32_t>(h + 36, static_cast<std::uint32_t>(x.const_zip.size()));
  Store<std::uint32_t>(h + 40, static_cast<std::uint32_t>(kLevelInfoSize * x.num_levels()));
  Store<std::uint32_t>(h + 44, kMinorVersion);
  Store<std::uint64_t>(h + 48, x.level_data_total);
  Store<std::uint32_t>(h + 56, static_cast<std::uint32_t>(x.small_zip.size()));
  Store<std::uint32_t>(h + 60, static_cast<std::uint32_t>(x.small_raw.size()));
  std::uint8_t* e = h + kHeaderSize;
  Store<std::uint16_t>(e + 0, static_cast<std::uint16_t>(options.u_border));
  Store<std::uint16_t>(e + 4, static_cast<std::uint16_t>(options.v_border));
  Store<std::uint16_t>(e + 6, static_cast<std::uint16_t>(options.edge_filter));
  Store<std::uint32_t>(e + 8, static_cast<std::uint32_t>(x.lmd_header_zip.size()));
  Store<std::uint32_t>(e + 12, static_cast<std::uint32_t>(x.lmd_header_raw.size()));
  Store<std::uint64_t>(e + 16, x.lmd_data_size);
  Store<std::uint64_t>(e + 24, 0);            // editdatasize
  Store<std::uint64_t>(e + 32, x.file_size);  // editdatapos: where edits would be appended
  return header;
}

// The level data section's bytes in file order, piece by piece: each level's compressed
// headers, then its faces' blocks. Stops at the first error `visit` returns.
template <class Visit>
Status PtexWriter::Impl::ForEachLevelDataPiece(const FileSections& x, Visit&& visit) const {
  // Offsets of each stored level inside a face's block buffer.
  auto block_offset = [&](const Face& face, std::size_t level_index) {
    std::size_t off = 0;
    for (std::size_t l = 0; l < level_index; ++l) off += BlockSizeOf(face.headers[l]);
    return off;
  };
  for (std::size_t l = 0; l < x.num_levels(); ++l) {
    DISPEX_RETURN_IF_ERROR(visit(x.level_header_zip[l].data(), x.level_header_zip[l].size()));
    for (std::size_t r = 0; r < x.level_entries[l]; ++r) {
      const Face& face = faces[l == 0 ? r : std::size_t(x.order[r])];
      const std::uint32_t size = BlockSizeOf(face.headers[l]);
      if (size == 0) continue;
      DISPEX_RETURN_IF_ERROR(visit(face.blocks.data() + block_offset(face, l), size));
    }
  }
  return Status::Ok();
}

// The file, section by section, in order; it must come out file_size bytes long.
Status PtexWriter::Impl::WriteSections(const FileSections& x) {
  const std::size_t nlevels = x.num_levels();
  BufferedOutput out(output);
  DISPEX_RETURN_IF_ERROR(out.Write(EncodeHeaders(x)));
  DISPEX_RETURN_IF_ERROR(out.Write(x.face_info_zip));
  DISPEX_RETURN_IF_ERROR(out.Write(x.const_zip));
  for (std::size_t l = 0; l < nlevels; ++l) {
    std::uint8_t info[kLevelInfoSize];
    Store<std::uint64_t>(info, x.level_size[l]);
    Store<std::uint32_t>(info + 8, static_cast<std::uint32_t>(x.level_header_zip[l].size()));
    Store<std::uint32_t>(info + 12, x.level_entries[l]);
    DISPEX_RETURN_IF_ERROR(out.Write(info, sizeof(info)));
  }
  DISPEX_RETURN_IF_ERROR(ForEachLevelDataPiece(
      x, [&](const std::uint8_t* data, std::size_t size) { return out.Write(data, size); }));
  DISPEX_RETURN_IF_ERROR(out.Write(x.small_zip));
  const std::uint8_t barrier[kBarrierSize] = {};
  DISPEX_RETURN_IF_ERROR(out.Write(barrier, sizeof(barrier)));
  DISPEX_RETURN_IF_ERROR(out.Write(x.lmd_header_zip));
  for (const auto& v : x.lmd_values) DISPEX_RETURN_IF_ERROR(out.Write(v));
  DISPEX_RETURN_IF_ERROR(out.Flush());
  DISPEX_CHECK_EQ(out.written(), x.file_size);
  return Status::Ok();
}

}  // namespace dispex
