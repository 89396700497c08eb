// Helpers for the Ptex tests: files, temporary directories, fixture texel formulas, and an
// independent walker of a Ptex file's sections that inflates with zlib (not libdeflate, which
// the reader uses), so byte-level checks do not trust the code under test.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace dispex::ptex_test {

namespace fs = std::filesystem;

inline std::string FixturePath(const std::string& name) {
  return (fs::path(DISPEX_TEST_DATA_DIR) / "ptex" / name).string();
}

// The stored `dispex info --faces` and structure dump of golden case `name` (golden_cases.h).
inline std::string GoldenDumpPath(const std::string& name) {
  return (fs::path(DISPEX_TEST_DATA_DIR) / "ptex-golden" / (name + ".txt")).string();
}

inline std::vector<std::uint8_t> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  return {s.begin(), s.end()};
}

inline void WriteBytes(const fs::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// A fresh directory per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ = fs::temp_directory_path() / ("dispex_ptex_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }
  std::size_t FileCount() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(path_), {}));
  }

 private:
  fs::path path_;
};

// T(f, u, v) = f + u/32 - v/1024 of the fixtures' README (exact in float).
inline float FixtureT(int f, int u, int v) {
  return static_cast<float>(f) + static_cast<float>(u) / 32.0f - static_cast<float>(v) / 1024.0f;
}
inline std::vector<float> FixtureFace(int f, int ures, int vres) {
  std::vector<float> t;
  for (int v = 0; v < vres; ++v) {
    for (int u = 0; u < ures; ++u) t.push_back(FixtureT(f, u, v));
  }
  return t;
}

template <class T>
T LoadLE(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// Inflates with zlib's own inflate; fails the test unless it yields exactly `expected` bytes
// and consumes the whole block.
inline std::vector<std::uint8_t> ZlibInflate(const std::uint8_t* data, std::size_t size,
                                             std::size_t expected) {
  std::vector<std::uint8_t> out(expected + 1);
  z_stream zs{};
  EXPECT_EQ(inflateInit(&zs), Z_OK);
  zs.next_in = const_cast<Bytef*>(data);
  zs.avail_in = static_cast<uInt>(size);
  zs.next_out = out.data();
  zs.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&zs, Z_FINISH);
  EXPECT_EQ(rc, Z_STREAM_END) << "zlib inflate failed";
  EXPECT_EQ(zs.total_out, expected) << "inflated size";
  EXPECT_EQ(zs.avail_in, 0u) << "bytes left after the zlib stream";
  inflateEnd(&zs);
  out.resize(zs.total_out);
  return out;
}

// Every section of a Ptex file, located by adding up the sizes as the format says, with the
// zlib blocks inflated by zlib. Face blocks are kept compressed (`blocks`) and inflated
// (`inflated`, empty for constant and tiled blocks).
struct Sections {
  std::vector<std::uint8_t> header;  // 64 + 40 bytes
  std::uint32_t nfaces = 0, nlevels = 0, nchannels = 0, datatype = 0;
  std::vector<std::uint8_t> face_info, const_data;
  struct Level {
    std::vector<std::uint8_t> info;      // 16 raw bytes
    std::vector<std::uint32_t> entries;  // face data headers
    std::vector<std::vector<std::uint8_t>> blocks, inflated;
  };
  std::vector<Level> levels;
  std::size_t level_data_end = 0;                     // where the level data section ends
  std::vector<std::uint8_t> meta;                     // inflated small block
  std::vector<std::uint8_t> barrier;                  // the 8 bytes after it (if present)
  std::vector<std::uint8_t> lmd_header;               // inflated
  std::vector<std::vector<std::uint8_t>> lmd_values;  // inflated
  std::size_t end = 0;                                // where the last section ended
};

inline int DataSizeOf(std::uint32_t datatype) {
  return datatype == 0 ? 1 : datatype == 3 ? 4 : 2;
}

inline Sections ReadSections(const std::vector<std::uint8_t>& b) {
  Sections s;
  s.header.assign(b.begin(), b.begin() + 104);
  s.datatype = LoadLE<std::uint32_t>(&b[12]);
  s.nchannels = LoadLE<std::uint16_t>(&b[20]);
  s.nlevels = LoadLE<std::uint16_t>(&b[22]);
  s.nfaces = LoadLE<std::uint32_t>(&b[24]);
  const std::uint32_t ext = LoadLE<std::uint32_t>(&b[28]);
  const std::uint32_t fis = LoadLE<std::uint32_t>(&b[32]), cds = LoadLE<std::uint32_t>(&b[36]);
  const std::uint32_t mdz = LoadLE<std::uint32_t>(&b[56]), mdm = LoadLE<std::uint32_t>(&b[60]);
  const std::uint32_t lmdz = LoadLE<std::uint32_t>(&b[64 + 8]);
  const std::uint32_t lmdm = LoadLE<std::uint32_t>(&b[64 + 12]);
  const std::size_t pixel = std::size_t(DataSizeOf(s.datatype)) * s.nchannels;
  std::size_t pos = 64 + ext;
  s.face_info = ZlibInflate(&b[pos], fis, 20 * s.nfaces);
  pos += fis;
  s.const_data = ZlibInflate(&b[pos], cds, pixel * s.nfaces);
  pos += cds;
  s.levels.resize(s.nlevels);
  for (auto& l : s.levels) {
    l.info.assign(b.begin() + static_cast<std::ptrdiff_t>(pos),
                  b.begin() + static_cast<std::ptrdiff_t>(pos + 16));
    pos += 16;
  }
  for (std::size_t li = 0; li < s.nlevels; ++li) {
    auto& l = s.levels[li];
    const std::uint32_t hs = LoadLE<std::uint32_t>(&l.info[8]);
    const std::uint32_t n = LoadLE<std::uint32_t>(&l.info[12]);
    std::vector<std::uint8_t> fdh = ZlibInflate(&b[pos], hs, 4 * n);
    pos += hs;
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t e = LoadLE<std::uint32_t>(&fdh[4 * i]);
      l.entries.push_back(e);
      const std::uint32_t size = e & 0x3fffffff;
      l.blocks.emplace_back(b.begin() + static_cast<std::ptrdiff_t>(pos),
                            b.begin() + static_cast<std::ptrdiff_t>(pos + size));
      pos += size;
    }
  }
  s.level_data_end = pos;
  if (mdz) {
    s.meta = ZlibInflate(&b[pos], mdz, mdm);
    pos += mdz;
  }
  if (pos + 8 <= b.size()) {
    s.barrier.assign(b.begin() + static_cast<std::ptrdiff_t>(pos),
                     b.begin() + static_cast<std::ptrdiff_t>(pos + 8));
    pos += 8;
  }
  if (lmdz) {
    s.lmd_header = ZlibInflate(&b[pos], lmdz, lmdm);
    pos += lmdz;
    std::size_t p = 0;
    while (p < s.lmd_header.size()) {
      const std::size_t ks = s.lmd_header[p];
      p += 1 + ks + 1;
      const std::uint32_t ds = LoadLE<std::uint32_t>(&s.lmd_header[p]);
      const std::uint32_t zs = LoadLE<std::uint32_t>(&s.lmd_header[p + 4]);
      p += 8;
      s.lmd_values.push_back(ZlibInflate(&b[pos], zs, ds));
      pos += zs;
    }
  }
  s.end = pos;
  return s;
}

// zlib-compresses (zlib's compress2, level 6).
inline std::vector<std::uint8_t> ZlibCompress(const std::vector<std::uint8_t>& data) {
  uLongf n = compressBound(static_cast<uLong>(data.size()));
  std::vector<std::uint8_t> out(n);
  EXPECT_EQ(compress2(out.data(), &n, data.data(), static_cast<uLong>(data.size()), 6), Z_OK);
  out.resize(n);
  return out;
}

template <class T>
void Put(std::vector<std::uint8_t>& out, T v) {
  const std::size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &v, sizeof(T));
}

// A second, minimal Ptex file assembler written from docs/ptex.md with zlib, for building
// files the dispex writer never makes (edit blocks, hand-made corruptions). It lays out the
// given raw sections and computes every size and offset.
struct RawPtex {
  std::uint32_t mesh_type = 1, data_type = 3, minor = 4;
  std::int32_t alpha = -1;
  std::uint16_t channels = 1;
  std::uint16_t u_border = 0, v_border = 0, edge_filter = 0;
  std::vector<std::uint8_t> face_info;   // 20-byte records
  std::vector<std::uint8_t> const_data;  // one texel per face
  struct Level {
    std::vector<std::uint32_t> headers;
    std::vector<std::vector<std::uint8_t>> blocks;
  };
  std::vector<Level> levels;
  std::vector<std::uint8_t> meta;  // small meta data records, uncompressed
  bool barrier = true;
  std::vector<std::uint8_t> edits;  // edit blocks, appended after the barrier
  bool edit_pos_zero = false;       // editdatapos = 0 (pre-1.3 files: scan to the end)

  static void AddFace(std::vector<std::uint8_t>& records, int ulog2, int vlog2, std::uint8_t flags,
                      std::array<std::int32_t, 4> adj = {-1, -1, -1, -1}, std::uint8_t edges = 0) {
    records.push_back(static_cast<std::uint8_t>(ulog2));
    records.push_back(static_cast<std::uint8_t>(vlog2));
    records.push_back(edges);
    records.push_back(flags);
    for (std::int32_t a : adj) Put<std::int32_t>(records, a);
  }

  std::vector<std::uint8_t> Build() const {
    const std::vector<std::uint8_t> fi = ZlibCompress(face_info);
    const std::vector<std::uint8_t> cd = ZlibCompress(const_data);
    std::vector<std::uint8_t> level_info, level_data;
    for (const Level& l : levels) {
      std::vector<std::uint8_t> raw;
      for (std::uint32_t h : l.headers) Put<std::uint32_t>(raw, h);
      const std::vector<std::uint8_t> hz = ZlibCompress(raw);
      std::uint64_t size = hz.size();
      level_data.insert(level_data.end(), hz.begin(), hz.end());
      for (const auto& b : l.blocks) {
        level_data.insert(level_data.end(), b.begin(), b.end());
        size += b.size();
      }
      Put<std::uint64_t>(level_info, size);
      Put<std::uint32_t>(level_info, static_cast<std::uint32_t>(hz.size()));
      Put<std::uint32_t>(level_info, static_cast<std::uint32_t>(l.headers.size()));
    }
    const std::vector<std::uint8_t> mz =
        meta.empty() ? std::vector<std::uint8_t>() : ZlibCompress(meta);
    std::vector<std::uint8_t> out;
    Put<std::uint32_t>(out, 0x78657450);
    Put<std::uint32_t>(out, 1);
    Put<std::uint32_t>(out, mesh_type);
    Put<std::uint32_t>(out, data_type);
    Put<std::int32_t>(out, alpha);
    Put<std::uint16_t>(out, channels);
    Put<std::uint16_t>(out, static_cast<std::uint16_t>(levels.size()));
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(face_info.size() / 20));
    Put<std::uint32_t>(out, 40);
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(fi.size()));
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(cd.size()));
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(level_info.size()));
    Put<std::uint32_t>(out, minor);
    Put<std::uint64_t>(out, level_data.size());
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(mz.size()));
    Put<std::uint32_t>(out, static_cast<std::uint32_t>(meta.size()));
    const std::uint64_t edit_pos = 64 + 40 + fi.size() + cd.size() + level_info.size() +
                                   level_data.size() + mz.size() + (barrier ? 8 : 0);
    Put<std::uint16_t>(out, u_border);
    Put<std::uint16_t>(out, 0);
    Put<std::uint16_t>(out, v_border);
    Put<std::uint16_t>(out, edge_filter);
    Put<std::uint32_t>(out, 0);
    Put<std::uint32_t>(out, 0);
    Put<std::uint64_t>(out, 0);
    Put<std::uint64_t>(out, edits.size());
    Put<std::uint64_t>(out, edit_pos_zero ? 0 : edit_pos);
    const std::vector<std::uint8_t>* parts[] = {&fi, &cd, &level_info, &level_data, &mz};
    for (const std::vector<std::uint8_t>* part : parts) {
      out.insert(out.end(), part->begin(), part->end());
    }
    if (barrier) out.resize(out.size() + 8, 0);
    out.insert(out.end(), edits.begin(), edits.end());
    return out;
  }
};

// A zipped float face block (channel split is the identity for one channel).
inline std::vector<std::uint8_t> ZippedFloats(const std::vector<float>& values) {
  std::vector<std::uint8_t> raw(values.size() * 4);
  std::memcpy(raw.data(), values.data(), raw.size());
  return ZlibCompress(raw);
}

inline std::vector<std::uint8_t> FloatBytes(const std::vector<float>& values) {
  std::vector<std::uint8_t> raw(values.size() * 4);
  std::memcpy(raw.data(), values.data(), raw.size());
  return raw;
}

}  // namespace dispex::ptex_test
