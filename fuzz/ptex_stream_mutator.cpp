// Zlib-stream mutation of Ptex files; see ptex_stream_mutator.h. The layout followed is the
// one of the Ptex 1.4 header (wdas/ptex PtexIO.h; docs/ptex.md, "Header"): a 64-byte
// header, the extended header, face info, constant data, level info, level data (each
// level: a zlib block of face data headers, then the face blocks), meta data, an 8-byte
// barrier, the large meta data header. Nothing here is trusted: a field that points outside
// the input just drops that stream from the choice.
#include "fuzz/ptex_stream_mutator.h"

#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace dispex::fuzz {
namespace {

constexpr std::uint32_t kMagic = 0x78657450;  // "Ptex"
constexpr std::size_t kHeaderSize = 64;
constexpr std::size_t kLevelInfoSize = 16;
constexpr std::size_t kBarrierSize = 8;
constexpr std::size_t kMaxInflated = std::size_t{1} << 20;

template <class T>
T Load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void Store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

enum class Kind { kFaceInfo, kConstData, kLevelHeader, kMeta, kLargeMetaHeader };

struct Stream {
  Kind kind;
  std::uint64_t offset;
  std::uint64_t zip_size;
  std::uint64_t level_info = 0;  // kLevelHeader: offset of the level's 16-byte record
};

std::vector<Stream> FindStreams(const std::uint8_t* h, std::size_t size) {
  std::vector<Stream> streams;
  if (size < kHeaderSize || Load<std::uint32_t>(h) != kMagic) return streams;
  const std::uint16_t nlevels = Load<std::uint16_t>(h + 22);
  const std::uint64_t ext_size = Load<std::uint32_t>(h + 28);
  const std::uint64_t face_info_zip = Load<std::uint32_t>(h + 32);
  const std::uint64_t const_zip = Load<std::uint32_t>(h + 36);
  const std::uint64_t level_info_size = Load<std::uint32_t>(h + 40);
  const std::uint64_t level_data_size = Load<std::uint64_t>(h + 48);
  const std::uint64_t meta_zip = Load<std::uint32_t>(h + 56);

  const std::uint64_t face_info_pos = kHeaderSize + ext_size;
  const std::uint64_t const_pos = face_info_pos + face_info_zip;
  const std::uint64_t level_info_pos = const_pos + const_zip;
  const std::uint64_t level_data_pos = level_info_pos + level_info_size;
  streams.push_back({Kind::kFaceInfo, face_info_pos, face_info_zip});
  streams.push_back({Kind::kConstData, const_pos, const_zip});
  std::uint64_t level_pos = level_data_pos;
  for (std::uint64_t l = 0; l < nlevels; ++l) {
    const std::uint64_t li = level_info_pos + l * kLevelInfoSize;
    if (li + kLevelInfoSize > size) break;
    streams.push_back({Kind::kLevelHeader, level_pos, Load<std::uint32_t>(h + li + 8), li});
    level_pos += Load<std::uint64_t>(h + li);
  }
  const std::uint64_t meta_pos = level_data_pos + level_data_size;
  streams.push_back({Kind::kMeta, meta_pos, meta_zip});
  if (ext_size >= 16 && kHeaderSize + 16 <= size) {
    const std::uint64_t lmd_zip = Load<std::uint32_t>(h + kHeaderSize + 8);
    streams.push_back({Kind::kLargeMetaHeader, meta_pos + meta_zip + kBarrierSize, lmd_zip});
  }
  // Keep the streams that lie inside the input (sums may have wrapped: compare carefully).
  std::vector<Stream> inside;
  for (const Stream& s : streams) {
    if (s.zip_size > 0 && s.offset < size && s.zip_size <= size - s.offset) inside.push_back(s);
  }
  return inside;
}

// Inflates a whole zlib stream; false if it is corrupt or inflates past kMaxInflated.
bool InflateStream(const std::uint8_t* in, std::size_t size, std::vector<std::uint8_t>& out) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return false;
  z.next_in = const_cast<Bytef*>(in);
  z.avail_in = static_cast<uInt>(size);
  out.resize(std::max<std::size_t>(256, size * 4));
  int rc = Z_OK;
  while (rc == Z_OK) {
    if (z.total_out == out.size()) {
      if (out.size() >= kMaxInflated) break;
      out.resize(std::min(kMaxInflated, out.size() * 2));
    }
    z.next_out = out.data() + z.total_out;
    z.avail_out = static_cast<uInt>(out.size() - z.total_out);
    rc = inflate(&z, Z_NO_FLUSH);
  }
  out.resize(z.total_out);
  inflateEnd(&z);
  return rc == Z_STREAM_END;
}

}  // namespace

std::size_t MutatePtexStream(std::uint8_t* data, std::size_t size, std::size_t max_size,
                             unsigned seed) {
  const std::vector<Stream> streams = FindStreams(data, size);
  if (streams.empty()) return 0;
  std::minstd_rand rng(seed);
  const Stream s = streams[rng() % streams.size()];

  std::vector<std::uint8_t> plain;
  if (!InflateStream(data + s.offset, static_cast<std::size_t>(s.zip_size), plain)) return 0;
  const std::size_t plain_size = plain.size();
  plain.resize(plain_size + 64 + plain_size / 4);
  std::size_t mutated = LLVMFuzzerMutate(plain.data(), plain_size, plain.size());
  // Sizes of face info, constant data and level headers are implied by the face count:
  // usually keep the length, so the mutation reaches the parser instead of the size check.
  if (s.kind != Kind::kMeta && s.kind != Kind::kLargeMetaHeader && rng() % 4 != 0) {
    mutated = plain_size;
  }
  plain.resize(mutated);

  std::vector<std::uint8_t> zipped(compressBound(static_cast<uLong>(plain.size())));
  uLongf zipped_size = static_cast<uLongf>(zipped.size());
  if (compress2(zipped.data(), &zipped_size, plain.data(), static_cast<uLong>(plain.size()),
                static_cast<int>(rng() % 10)) != Z_OK) {
    return 0;
  }
  zipped.resize(zipped_size);
  const std::size_t new_size = size - static_cast<std::size_t>(s.zip_size) + zipped.size();
  if (new_size > max_size || zipped.size() > 0xffffffffu) return 0;

  // Rewrite the size fields (all of them lie before the stream), then splice.
  std::vector<std::uint8_t> file(data, data + size);
  std::uint8_t* h = file.data();
  const auto zip = static_cast<std::uint32_t>(zipped.size());
  const std::uint64_t delta = zipped.size() - s.zip_size;  // modulo 2^64
  switch (s.kind) {
    case Kind::kFaceInfo:
      Store<std::uint32_t>(h + 32, zip);
      break;
    case Kind::kConstData:
      Store<std::uint32_t>(h + 36, zip);
      break;
    case Kind::kLevelHeader:
      Store<std::uint64_t>(h + s.level_info, Load<std::uint64_t>(h + s.level_info) + delta);
      Store<std::uint32_t>(h + s.level_info + 8, zip);
      Store<std::uint64_t>(h + 48, Load<std::uint64_t>(h + 48) + delta);
      break;
    case Kind::kMeta:
      Store<std::uint32_t>(h + 56, zip);
      Store<std::uint32_t>(h + 60, static_cast<std::uint32_t>(plain.size()));
      break;
    case Kind::kLargeMetaHeader:
      Store<std::uint32_t>(h + kHeaderSize + 8, zip);
      Store<std::uint32_t>(h + kHeaderSize + 12, static_cast<std::uint32_t>(plain.size()));
      break;
  }
  // The edit data position (extended header, byte 32) is absolute: move it with the data.
  const std::uint64_t ext_size = Load<std::uint32_t>(h + 28);
  if (ext_size >= 40 && kHeaderSize + 40 <= size) {
    const std::uint64_t edit_pos = Load<std::uint64_t>(h + kHeaderSize + 32);
    if (edit_pos > s.offset) Store<std::uint64_t>(h + kHeaderSize + 32, edit_pos + delta);
  }
  const auto offset = static_cast<std::size_t>(s.offset);
  std::memcpy(data, file.data(), offset);
  std::memcpy(data + offset, zipped.data(), zipped.size());
  std::memcpy(data + offset + zipped.size(), file.data() + offset + s.zip_size,
              size - offset - static_cast<std::size_t>(s.zip_size));
  return new_size;
}

}  // namespace dispex::fuzz
