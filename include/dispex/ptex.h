// Ptex files (.ptx): a streaming writer, a validating reader, and the Ptex face layout of a
// Catmull-Clark base mesh.
//
// The on-disk format is the one of the reference implementation (wdas/ptex, file format
// 1.4); docs/ptex.md describes the format ("The file format") and says what this module
// supports and how it was checked. Texels are always passed as
// channel-interleaved rows, v-major: texel (u, v) of a face with resolution ures x vres
// starts at index (v * ures + u) * num_channels; texel (i, j) covers
// u in [i/ures, (i+1)/ures), v in [j/vres, (j+1)/vres).
//
// Face ids are PtexFaceId (Ptex faces: a quad base face is one, an n-gon is n sub-faces);
// the adjacency stored in a face record uses raw int32 ids because that is the file's field.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

// ---- Types shared by the writer and the reader ----------------------------------------------

enum class PtexMeshType : std::uint8_t { kTriangle = 0, kQuad = 1 };
enum class PtexDataType : std::uint8_t { kUint8 = 0, kUint16 = 1, kHalf = 2, kFloat = 3 };
// What a filter does beyond a face edge that has no neighbour (affects filtering only).
enum class PtexBorderMode : std::uint8_t { kClamp = 0, kBlack = 1, kPeriodic = 2 };
// kTangentVector: texels are tangent-space vectors that filters rotate across edges.
enum class PtexEdgeFilterMode : std::uint8_t { kNone = 0, kTangentVector = 1 };
enum class PtexMetaType : std::uint8_t {
  kString = 0,
  kInt8 = 1,
  kInt16 = 2,
  kInt32 = 3,
  kFloat = 4,
  kDouble = 5
};

// Bytes of one channel value: 1, 2, 2, 4.
int PtexDataSize(PtexDataType type);
// "uint8", "uint16", "half", "float32"; "triangle", "quad"; "clamp", "black", "periodic";
// "none", "tanvec"; "string", "int8", "int16", "int32", "float", "double".
std::string_view PtexDataTypeName(PtexDataType type);
std::string_view PtexMeshTypeName(PtexMeshType type);
std::string_view PtexBorderModeName(PtexBorderMode mode);
std::string_view PtexEdgeFilterModeName(PtexEdgeFilterMode mode);
std::string_view PtexMetaTypeName(PtexMetaType type);

// The face record of the file (20 bytes on disk), unpacked.
struct PtexFaceInfo {
  std::int8_t ulog2 = 0;  // resolution 2^ulog2 x 2^vlog2 texels
  std::int8_t vlog2 = 0;
  // Neighbour across edge e (0 = bottom v=0, 1 = right u=1, 2 = top v=1, 3 = left u=0) and
  // the index of the shared edge within that neighbour; -1 / 0 where there is none.
  std::array<std::int32_t, 4> adjfaces = {-1, -1, -1, -1};
  std::array<std::uint8_t, 4> adjedges = {0, 0, 0, 0};
  bool subface = false;                // one of the quads an n-gon was split into
  bool constant = false;               // one value (set by the writer, read from the file)
  bool neighborhood_constant = false;  // reader only: the file's filter hint (bit 2)
  bool has_edits = false;              // reader only: replaced by an edit block

  int ures() const { return 1 << ulog2; }
  int vres() const { return 1 << vlog2; }
  std::size_t num_texels() const { return std::size_t{1} << (ulog2 + vlog2); }
};

// One meta data item. `bytes` holds the value exactly as stored: little-endian numbers,
// strings with their terminating NUL.
struct PtexMetaItem {
  std::string key;
  PtexMetaType type = PtexMetaType::kString;
  std::vector<std::uint8_t> bytes;
  bool large = false;  // stored in the large meta data section (value > 1024 bytes)

  // Number of values (a string counts as one).
  std::size_t count() const;
  // The value converted to the requested type; empty (or "") when `type` differs.
  std::string AsString() const;
  std::vector<std::int8_t> AsInt8() const;
  std::vector<std::int16_t> AsInt16() const;
  std::vector<std::int32_t> AsInt32() const;
  std::vector<float> AsFloat() const;
  std::vector<double> AsDouble() const;
  // Any numeric type as doubles (empty for strings).
  std::vector<double> AsNumbers() const;
};

// ---- Writer ---------------------------------------------------------------------------------

enum class PtexCompressor : std::uint8_t {
  kLibdeflate,  // default: fast; output differs from zlib's but is the same zlib format
  kZlib,        // zlib's deflate; at level 6 it reproduces the reference writer's bytes
};

// One face as a file stores it, still encoded: what PtexFile::ReadEncodedFace gives and
// PtexWriter::SetEncodedFace stores again without decoding and re-encoding its texels.
struct PtexEncodedFace {
  std::int8_t ulog2 = 0, vlog2 = 0;
  bool constant = false;
  std::vector<std::uint32_t> headers;  // FaceDataHeader of level 0, then of each stored reduction
  std::vector<std::uint8_t> blocks;    // their blocks, in that order
  std::vector<std::uint8_t> average;   // the face's constant-data texel (pixel_size() bytes)
};

struct PtexWriterOptions {
  PtexMeshType mesh_type = PtexMeshType::kQuad;
  PtexDataType data_type = PtexDataType::kFloat;
  int num_channels = 1;
  int alpha_channel = -1;  // -1: none. Reductions are stored premultiplied, as the format says
  PtexBorderMode u_border = PtexBorderMode::kClamp;
  PtexBorderMode v_border = PtexBorderMode::kClamp;
  PtexEdgeFilterMode edge_filter = PtexEdgeFilterMode::kNone;
  // Store the reduction levels the reference writer stores (each face halved until its
  // smaller side is 4 texels). false: level 0 only (readers compute reductions themselves).
  bool write_reductions = true;
  // Split face blocks of 128 KiB or more into tiles by the reference writer's rule.
  bool tile_large_faces = true;
  PtexCompressor compressor = PtexCompressor::kLibdeflate;
  // -1: the compressor's default here (libdeflate 1, zlib 6; see docs/ptex.md for why).
  // Otherwise libdeflate 0..12, zlib 0..9.
  int compression_level = -1;
  // Not empty: Finish() adds a string meta data item of this key holding the hash of the file's
  // level data (PtexFile::LevelDataHash), so that a reader can tell the face data is as written
  // without inflating it.
  std::string level_data_hash_key;
};

// Everything the options fix about how a face's texels are encoded (the compressor, its
// library version and level, the data type, channels, alpha, reductions and tiles): two
// writers with the same name encode the same texels into the same bytes.
std::string PtexEncodingName(const PtexWriterOptions& options);

// Empty when `level` (-1: the default) is a level `compressor` takes, else why not.
std::string PtexCompressionLevelProblem(PtexCompressor compressor, int level);

// Writes one Ptex file. Faces may be submitted in any order and from several threads at
// once; each submission is converted, reduced and compressed immediately, so only
// compressed blocks stay in memory. Finish() assembles the file in face-id / reduction
// order, so the bytes do not depend on submission order or thread count.
//
// Output goes to a temporary file beside `path` that Finish() renames onto it; destroying
// an unfinished writer, an error, or a signal handled by the CLI leaves no file behind.
// Faces never set become constant zero 1x1 faces without neighbours (as in the reference).
// The tiles of a large face are compressed in parallel (TBB). A default-constructed writer
// is empty: only Create gives a usable one.
class PtexWriter {
 public:
  // Fails on invalid options (channels < 1 or > 1024, alpha channel out of range, a level
  // out of the compressor's range), num_faces < 1 or > 2^28, or an unwritable path.
  static StatusOr<PtexWriter> Create(const std::string& path, const PtexWriterOptions& options,
                                     int num_faces);

  PtexWriter();
  PtexWriter(PtexWriter&&) noexcept;
  PtexWriter& operator=(PtexWriter&&) noexcept;
  ~PtexWriter();

  // Sets face `face` from float texels (ures * vres * num_channels values, interleaved,
  // v-major), converted to the file's type: float as is; half rounded to nearest even
  // (overflow to infinity, subnormals kept); uint8/uint16 clamped to [0, 1] and scaled by
  // 255 / 65535 with rounding to nearest. `info` gives the resolution (0..15 per side,
  // square on triangle meshes, at most 2^29 bytes per face), adjacency and subface flag;
  // its constant flag is ignored. A face whose converted texels are all bit-identical is
  // stored as a constant face. Thread-safe for distinct faces. Fails (and stores nothing)
  // when the face id, resolution, adjacency or texel count is invalid, when a texel is not
  // finite, or when the face was already set.
  Status SetFace(PtexFaceId face, const PtexFaceInfo& info, std::span<const float> texels);
  // The same with texels already in the file's data type (ures * vres * pixel bytes,
  // little-endian, interleaved); no conversion and no finiteness check.
  Status SetFaceRaw(PtexFaceId face, const PtexFaceInfo& info, std::span<const std::uint8_t> data);
  // A face as another file stores it (PtexFile::ReadEncodedFace), its bytes kept as they are;
  // `info` gives the adjacency and subface flag, and its resolution must be the encoded one.
  // The file is byte-identical to one where SetFace was given the face's texels when the
  // encoding was made with this writer's PtexEncodingName. Fails (and stores nothing) when the
  // encoded face cannot be this writer's: another resolution or texel size, another number of
  // stored reductions, or blocks that are not the sizes their headers say.
  Status SetEncodedFace(PtexFaceId face, const PtexFaceInfo& info, const PtexEncodedFace& encoded);
  // A constant face: `value` has num_channels floats (converted as in SetFace). The
  // resolution in `info` stays the face's logical resolution.
  Status SetConstantFace(PtexFaceId face, const PtexFaceInfo& info, std::span<const float> value);

  // Meta data, stored in the order of first addition; adding a key again replaces its
  // value in place. Keys are 1..254 bytes without NUL; arrays must not be empty. Values
  // over 1024 bytes go to the large meta data section. Thread-safe.
  Status AddMetaData(const std::string& key, std::string_view value);
  Status AddMetaData(const std::string& key, std::span<const std::int8_t> values);
  Status AddMetaData(const std::string& key, std::span<const std::int16_t> values);
  Status AddMetaData(const std::string& key, std::span<const std::int32_t> values);
  Status AddMetaData(const std::string& key, std::span<const float> values);
  Status AddMetaData(const std::string& key, std::span<const double> values);

  // Writes the file and commits it to `path`. Call once, after every SetFace has returned.
  // On failure the target is left untouched and the temporary file removed.
  Status Finish();

  // Number of faces set so far, and bytes of compressed face data held in memory.
  int faces_set() const;
  std::size_t compressed_bytes() const;
  const PtexWriterOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---- Reader ---------------------------------------------------------------------------------

struct PtexHeaderInfo {
  PtexMeshType mesh_type = PtexMeshType::kQuad;
  PtexDataType data_type = PtexDataType::kFloat;
  int num_channels = 1;
  int alpha_channel = -1;
  int num_faces = 0;
  int num_levels = 0;  // level 0 plus stored reduction levels
  int minor_version = 0;
  PtexBorderMode u_border = PtexBorderMode::kClamp;
  PtexBorderMode v_border = PtexBorderMode::kClamp;
  PtexEdgeFilterMode edge_filter = PtexEdgeFilterMode::kNone;
  std::uint64_t file_size = 0;
  bool has_edits = false;  // the file carries edit blocks (applied by the reader)

  int pixel_size() const { return PtexDataSize(data_type) * num_channels; }
};

// One stored level of the file: `num_entries` faces, in reduction order for levels >= 1.
struct PtexLevelInfo {
  int num_entries = 0;
  std::uint64_t data_size = 0;    // compressed header + face blocks, bytes
  std::uint32_t header_size = 0;  // compressed face-data header, bytes
};

// How one face is stored at one level.
struct PtexBlockInfo {
  enum class Encoding : std::uint8_t { kConstant = 0, kZipped = 1, kDiffZipped = 2, kTiled = 3 };
  Encoding encoding = Encoding::kConstant;
  std::uint32_t size = 0;  // bytes in the file
  std::int8_t ulog2 = 0;   // resolution at this level
  std::int8_t vlog2 = 0;
  int num_tiles = 1;  // tiled: tiles of tile_ulog2 x tile_vlog2
  std::int8_t tile_ulog2 = 0;
  std::int8_t tile_vlog2 = 0;
};

struct PtexReadOptions {
  // Largest face (texels x channels) that ReadFace decodes; larger requests fail. Guards
  // against constant faces or tiles that claim huge logical resolutions.
  std::size_t max_values_per_read = std::size_t{1} << 28;
};

// A Ptex file opened for reading. Open() validates the whole structure (header, every
// section size and offset against the file size, face records, level headers, tile
// headers, meta data, edit blocks); face data is inflated when asked for, with its exact
// size checked. Every malformed input gives a Status naming the file, the section and the
// face; nothing is trusted before it is checked. Thread-safe for concurrent const calls.
// A default-constructed PtexFile is empty: only Open / ParsePtex give a usable one.
class PtexFile {
 public:
  static StatusOr<PtexFile> Open(const std::string& path, const PtexReadOptions& options = {});

  PtexFile();
  PtexFile(PtexFile&&) noexcept;
  PtexFile& operator=(PtexFile&&) noexcept;
  ~PtexFile();

  const std::string& name() const;
  const PtexHeaderInfo& header() const;
  int num_faces() const;
  // Precondition: 0 <= face < num_faces().
  const PtexFaceInfo& face_info(PtexFaceId face) const;
  std::span<const PtexLevelInfo> levels() const;

  // All meta data items: small ones, then large ones, then items added by edit blocks.
  std::span<const PtexMetaItem> meta_data() const;
  // The item with this key, or nullptr.
  const PtexMetaItem* FindMetaData(std::string_view key) const;

  // Stored levels of a face: 1 (level 0 only) plus its stored reductions. Level L of a
  // face has resolution (ulog2 - L, vlog2 - L).
  int NumStoredLevels(PtexFaceId face) const;
  // How the face is stored at `level` (< NumStoredLevels); constant faces report kConstant.
  PtexBlockInfo BlockInfo(PtexFaceId face, int level) const;

  // Texels of `face` at `level` (0 or a stored reduction) as interleaved floats: float and
  // half as is, uint8 / uint16 divided by 255 / 65535. Constant faces give their value
  // repeated over their resolution. Fails, naming the face, level and tile, on corrupt data.
  Status ReadFace(PtexFaceId face, int level, std::vector<float>& texels) const;
  // The same in the file's data type (pixel_size() bytes per texel, little-endian).
  Status ReadFaceRaw(PtexFaceId face, int level, std::vector<std::uint8_t>& data) const;
  // The constant-data value of the face (its value, or its average) as floats
  // (num_channels values written to `out`).
  void ConstantValue(PtexFaceId face, float* out) const;
  std::span<const std::uint8_t> ConstantValueRaw(PtexFaceId face) const;
  // The face's stored bytes as they are (nothing inflated). Fails, naming the face, for a face
  // an edit block changed: its stored levels are no longer one encoding of its texels.
  Status ReadEncodedFace(PtexFaceId face, PtexEncodedFace& out) const;

  // Bilinear sample of level 0 at (u, v) in [0, 1]^2: texel centres at ((i + 0.5) / ures,
  // (j + 0.5) / vres), clamped at the face border (no blending across edges), as a renderer
  // reads a face at its own resolution. Triangle faces return the triangular texel that
  // contains (u, v). Decoded faces are cached (thread-safe); NaN if the face's data is
  // corrupt (ReadFace says why). Precondition: valid face and channel.
  float Sample(PtexFaceId face, float u, float v, int channel = 0) const;
  // Frees the faces cached by Sample(). Not to be called while Sample() runs.
  void ReleaseSampleCache() const;

  // The hash (32 hex digits, XXH3-128) of the level data section's bytes: every face's blocks
  // at every level, and the levels' headers.
  std::string LevelDataHash() const;
  // Inflates and checks every block of every level (Open checks only the structure), faces
  // in parallel (TBB); the error returned is the one of the lowest failing face id.
  Status Validate() const;

 private:
  friend StatusOr<PtexFile> ParsePtex(std::string_view bytes, const std::string& name,
                                      const PtexReadOptions& options);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Parses a Ptex file held in memory (copied); `name` is used in messages. For tests and
// fuzzing: the same checks as PtexFile::Open.
StatusOr<PtexFile> ParsePtex(std::string_view bytes, const std::string& name,
                             const PtexReadOptions& options = {});

// ---- Half floats ----------------------------------------------------------------------------

// IEEE-754 binary16 conversions as the reference Ptex library makes them: round to nearest
// with ties away from zero (normal and subnormal halves), -0 and +0 both to +0, overflow to
// +-infinity, NaN stays NaN (quiet, sign and top payload bits kept); a double is rounded to
// float first. Reading is exact.
std::uint16_t FloatToHalf(float value);
std::uint16_t DoubleToHalf(double value);
float HalfToFloat(std::uint16_t bits);

// ---- The base mesh --------------------------------------------------------------------------

// Adds the standard mesh meta data (PtexFaceVertCounts, PtexFaceVertIndices as int32 and
// PtexVertPositions as float xyz) describing the base mesh, so viewers can show the map
// without it.
Status AddMeshMetaData(PtexWriter& writer, const Mesh& mesh);

}  // namespace dispex
