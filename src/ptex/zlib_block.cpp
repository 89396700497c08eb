#include "ptex/zlib_block.h"

#include <libdeflate.h>
#include <zlib.h>

#include <array>
#include <memory>

#include "core/check.h"

namespace dispex::ptex {

namespace {

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};
struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// One libdeflate compressor per level and thread, made on first use.
libdeflate_compressor* ThreadCompressor(int level) {
  thread_local std::array<std::unique_ptr<libdeflate_compressor, CompressorDeleter>, 13> cache;
  auto& slot = cache[static_cast<std::size_t>(level)];
  if (!slot) slot.reset(libdeflate_alloc_compressor(level));
  DISPEX_CHECK(slot != nullptr);
  return slot.get();
}

libdeflate_decompressor* ThreadDecompressor() {
  thread_local std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> d(
      libdeflate_alloc_decompressor());
  DISPEX_CHECK(d != nullptr);
  return d.get();
}

}  // namespace

std::string CompressorName(PtexCompressor compressor) {
  if (compressor == PtexCompressor::kZlib) return std::string("zlib ") + zlibVersion();
  return "libdeflate " LIBDEFLATE_VERSION_STRING;
}

int DefaultCompressionLevel(PtexCompressor compressor) {
  return compressor == PtexCompressor::kZlib ? 6 : 1;
}

std::string CheckCompressionLevel(PtexCompressor compressor, int level) {
  if (level == -1) return {};
  if (compressor == PtexCompressor::kZlib && (level < 0 || level > 9)) {
    return "zlib compression level " + std::to_string(level) + " is not in 0..9";
  }
  if (compressor == PtexCompressor::kLibdeflate && (level < 0 || level > 12)) {
    return "libdeflate compression level " + std::to_string(level) + " is not in 0..12";
  }
  return {};
}

std::size_t CompressAppend(std::span<const std::uint8_t> data, PtexCompressor compressor, int level,
                           std::vector<std::uint8_t>& out) {
  if (level < 0) level = DefaultCompressionLevel(compressor);
  const std::size_t at = out.size();
  if (compressor == PtexCompressor::kLibdeflate) {
    if (level == 1 && data.size() < kStoredBelow) level = 0;
    libdeflate_compressor* c = ThreadCompressor(level);
    const std::size_t bound = libdeflate_zlib_compress_bound(c, data.size());
    out.resize(at + bound);
    const std::size_t n =
        libdeflate_zlib_compress(c, data.data(), data.size(), out.data() + at, bound);
    DISPEX_CHECK_GT(n, std::size_t{0});  // cannot fail with a buffer of the bound's size
    out.resize(at + n);
    return n;
  }
  uLongf n = compressBound(static_cast<uLong>(data.size()));
  out.resize(at + n);
  const int rc =
      compress2(out.data() + at, &n, data.data(), static_cast<uLong>(data.size()), level);
  DISPEX_CHECK_EQ(rc, Z_OK);
  out.resize(at + n);
  return n;
}

std::string Inflate(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
  std::size_t in_used = 0, out_made = 0;
  const libdeflate_result r = libdeflate_zlib_decompress_ex(
      ThreadDecompressor(), in.data(), in.size(), out.data(), out.size(), &in_used, &out_made);
  switch (r) {
    case LIBDEFLATE_SUCCESS:
      break;
    case LIBDEFLATE_INSUFFICIENT_SPACE:
      return "zlib stream inflates to more than the expected " + std::to_string(out.size()) +
             " bytes";
    default:
      return "corrupt zlib stream";
  }
  if (out_made != out.size()) {
    return "zlib stream inflates to " + std::to_string(out_made) + " bytes, expected " +
           std::to_string(out.size());
  }
  if (in_used != in.size()) {
    return "zlib stream ends after " + std::to_string(in_used) + " of its " +
           std::to_string(in.size()) + " bytes";
  }
  return {};
}

}  // namespace dispex::ptex

namespace dispex {

std::string PtexCompressionLevelProblem(PtexCompressor compressor, int level) {
  return ptex::CheckCompressionLevel(compressor, level);
}

}  // namespace dispex
