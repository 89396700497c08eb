// UDIM OpenEXR tiles: writing (through memory, then atomically) and reading, and a map's tile
// set read bilinearly (see dispex/uv_map.h).
#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <fmt/format.h>
#include <half.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <string_view>

#include "core/atomic_output.h"
#include "core/check.h"
#include "dispex/files.h"
#include "dispex/uv_map.h"

namespace dispex {

namespace {

// OpenEXR's output stream into memory, so that the file is written whole by
// WriteFileAtomically.
class MemoryStream : public Imf::OStream {
 public:
  MemoryStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    const auto end = position_ + static_cast<std::size_t>(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(bytes_.data() + position_, c, static_cast<std::size_t>(n));
    position_ = end;
  }
  std::uint64_t tellp() override { return position_; }
  void seekp(std::uint64_t pos) override { position_ = static_cast<std::size_t>(pos); }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  std::size_t position_ = 0;
};

const char* ChannelName(int channels, int c) {
  static const char* const kRgb[] = {"R", "G", "B"};
  return channels == 1 ? "Y" : kRgb[c];
}

// The UDIM of a name ending in ".1DDD.exr" (the extension in any letter case), else 0.
int UdimFromName(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  constexpr std::size_t kSuffix = 9;  // ".1DDD.exr"
  if (name.size() <= kSuffix) return 0;
  const std::string_view end = std::string_view(name).substr(name.size() - kSuffix);
  std::string extension(end.substr(5));
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const auto digit = [](char c) { return c >= '0' && c <= '9'; };
  if (end[0] != '.' || end[1] != '1' || !digit(end[2]) || !digit(end[3]) || !digit(end[4]) ||
      extension != ".exr") {
    return 0;
  }
  return 1000 + (end[2] - '0') * 100 + (end[3] - '0') * 10 + (end[4] - '0');
}

}  // namespace

std::string UvMapTilePath(const std::string& dir, const std::string& shape, int udim) {
  return (std::filesystem::path(dir) / fmt::format("{}.{}.exr", shape, udim)).string();
}

namespace {

// The OpenEXR file of `tile`, in memory.
StatusOr<std::string> EncodeUvMapTile(const std::string& path, const UvMapTile& tile, bool half) {
  const int n = tile.resolution, channels = tile.channels;
  const std::size_t texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  if (n < 1 || (channels != 1 && channels != 3) || tile.values.size() != texels * channels) {
    return Status::Error(
        fmt::format("{}: a tile of {} texels per side and {} channels with {} "
                    "values: not a square tile of 1 or 3 channels",
                    path, n, channels, tile.values.size()));
  }
  try {
    Imf::Header header(n, n);
    header.compression() = Imf::ZIP_COMPRESSION;
    const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
    for (int c = 0; c < channels; ++c) header.channels().insert(ChannelName(channels, c), type);
    for (const auto& [name, value] : tile.attributes) {
      header.insert(name, Imf::StringAttribute(value));
    }
    // Rows top (v = 1) first, as OpenEXR orders scanlines.
    std::vector<float> rows(tile.values.size());
    std::vector<::half> half_rows(half ? rows.size() : 0);
    const std::size_t row = static_cast<std::size_t>(n) * channels;
    for (int j = 0; j < n; ++j) {
      std::copy_n(tile.values.begin() + static_cast<std::ptrdiff_t>(j * row), row,
                  rows.begin() + static_cast<std::ptrdiff_t>((n - 1 - j) * row));
    }
    for (std::size_t i = 0; i < half_rows.size(); ++i) half_rows[i] = ::half(rows[i]);
    Imf::FrameBuffer frame;
    const std::size_t size = half ? sizeof(::half) : sizeof(float);
    char* base =
        half ? reinterpret_cast<char*>(half_rows.data()) : reinterpret_cast<char*>(rows.data());
    for (int c = 0; c < channels; ++c) {
      frame.insert(ChannelName(channels, c),
                   Imf::Slice(type, base + c * size, size * channels, size * row));
    }
    MemoryStream stream;
    {
      Imf::OutputFile file(stream, header, /*numThreads=*/0);
      file.setFrameBuffer(frame);
      file.writePixels(n);
    }
    return stream.bytes();
  } catch (const std::exception& e) {
    return Status::Error(fmt::format("{}: OpenEXR: {}", path, e.what()));
  }
}

}  // namespace

Status WriteUvMapTile(const std::string& path, const UvMapTile& tile, bool half) {
  return WriteUvMapTiles({&path, 1}, {&tile, 1}, half);
}

Status WriteUvMapTiles(std::span<const std::string> paths, std::span<const UvMapTile> tiles,
                       bool half) {
  DISPEX_CHECK_EQ(paths.size(), tiles.size());
  std::vector<AtomicOutput> outputs;
  outputs.reserve(tiles.size());
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    DISPEX_ASSIGN_OR_RETURN(const std::string bytes, EncodeUvMapTile(paths[t], tiles[t], half));
    DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(paths[t]));
    DISPEX_RETURN_IF_ERROR(out.Write(bytes.data(), bytes.size()));
    DISPEX_RETURN_IF_ERROR(out.Close());
    outputs.push_back(std::move(out));
  }
  for (AtomicOutput& out : outputs) DISPEX_RETURN_IF_ERROR(out.Commit());
  return Status::Ok();
}

namespace {

StatusOr<UvMapTile> ReadTileFile(const std::string& path, bool texels) {
  DISPEX_RETURN_IF_ERROR(CheckReadableFile(path));
  try {
    Imf::InputFile file(path.c_str(), /*numThreads=*/0);
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
    if (width != height || width < 1) {
      return Status::Error(
          fmt::format("{}: {} x {} texels: a UV map tile is square", path, width, height));
    }
    const Imf::ChannelList& list = header.channels();
    int channels = 0;
    if (list.findChannel("Y") != nullptr) {
      channels = 1;
    } else if (list.findChannel("R") && list.findChannel("G") && list.findChannel("B")) {
      channels = 3;
    } else {
      return Status::Error(
          fmt::format("{}: no channel Y (a scalar map) nor R, G and B (a vector map)", path));
    }
    UvMapTile tile;
    tile.udim = UdimFromName(path);
    tile.resolution = width;
    tile.channels = channels;
    for (auto it = header.begin(); it != header.end(); ++it) {
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
        tile.attributes.emplace_back(it.name(), s->value());
      }
    }
    if (!texels) return tile;
    const std::size_t n = static_cast<std::size_t>(width);
    const std::size_t row = n * static_cast<std::size_t>(channels);
    std::vector<float> rows(row * n);
    Imf::FrameBuffer frame;
    char* base = reinterpret_cast<char*>(rows.data()) -
                 (static_cast<std::ptrdiff_t>(window.min.y) * static_cast<std::ptrdiff_t>(row) +
                  window.min.x * channels) *
                     static_cast<std::ptrdiff_t>(sizeof(float));
    for (int c = 0; c < channels; ++c) {
      frame.insert(ChannelName(channels, c),
                   Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(float) * channels,
                              sizeof(float) * row));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    tile.values.resize(rows.size());
    for (std::size_t j = 0; j < n; ++j) {
      std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>(j * row), row,
                  tile.values.begin() + static_cast<std::ptrdiff_t>((n - 1 - j) * row));
    }
    return tile;
  } catch (const std::exception& e) {
    return Status::Error(fmt::format("{}: not a readable OpenEXR file: {}", path, e.what()));
  }
}

}  // namespace

StatusOr<UvMapTile> ReadUvMapTile(const std::string& path) {
  StatusOr<UvMapTile> tile = ReadTileFile(path, /*texels=*/true);
  if (!tile.ok()) return tile.status().WithCode(StatusCode::kBadInput).WithPath(path);
  return tile;
}

StatusOr<UvMapTile> ReadUvMapTileHeader(const std::string& path) {
  StatusOr<UvMapTile> tile = ReadTileFile(path, /*texels=*/false);
  if (!tile.ok()) return tile.status().WithCode(StatusCode::kBadInput).WithPath(path);
  return tile;
}

bool IsUvMapPath(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (in) {
    unsigned char magic[4] = {0, 0, 0, 0};
    in.read(reinterpret_cast<char*>(magic), 4);
    return magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
  }
  std::string lower = path;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return path.find("<UDIM>") != std::string::npos ||
         (lower.size() > 4 && lower.compare(lower.size() - 4, 4, ".exr") == 0);
}

StatusOr<UvMap> UvMap::Open(const std::string& pattern) {
  StatusOr<UvMap> map = OpenTiles(pattern);
  if (!map.ok()) return map.status().WithCode(StatusCode::kBadInput).WithPath(pattern);
  return map;
}

StatusOr<UvMap> UvMap::OpenTiles(const std::string& pattern) {
  std::string prefix;
  const std::size_t marker = pattern.find("<UDIM>");
  if (marker != std::string::npos) {
    if (pattern.compare(marker, std::string::npos, "<UDIM>.exr") != 0) {
      return Status::Error(pattern + ": a tile pattern ends in <UDIM>.exr");
    }
    prefix = pattern.substr(0, marker);
  } else {
    if (UdimFromName(pattern) == 0) {
      return Status::Error(pattern + ": not a UDIM tile name (<name>.<1001..1999>.exr)");
    }
    prefix = pattern.substr(0, pattern.size() - std::string("1001.exr").size());
  }
  const std::filesystem::path full(prefix);
  const std::filesystem::path dir = full.has_parent_path() ? full.parent_path() : ".";
  const std::string stem = full.filename().string();
  std::map<int, std::string> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() != stem.size() + 8 || name.compare(0, stem.size(), stem) != 0) continue;
    const int udim = UdimFromName(name);
    if (udim != 0) found[udim] = entry.path().string();
  }
  if (ec) return Status::Error(fmt::format("{}: {}", dir.string(), ec.message()));
  if (found.empty()) {
    return Status::Error(fmt::format("{}: no tile {}NNNN.exr", pattern, stem));
  }
  UvMap map;
  map.tile_index_.assign(999, -1);
  for (const auto& [udim, path] : found) {
    DISPEX_ASSIGN_OR_RETURN(UvMapTile tile, ReadUvMapTile(path));
    if (!map.tiles_.empty() &&
        (tile.resolution != map.resolution_ || tile.channels != map.channels_)) {
      return Status::Error(fmt::format(
          "{}: {} texels per side and {} channels, but {} has {} and {}", path, tile.resolution,
          tile.channels, map.paths_[0], map.resolution_, map.channels_));
    }
    map.resolution_ = tile.resolution;
    map.channels_ = tile.channels;
    map.tile_index_[static_cast<std::size_t>(udim - 1001)] = static_cast<int>(map.tiles_.size());
    map.tiles_.push_back(std::move(tile));
    map.paths_.push_back(path);
  }
  return map;
}

bool UvMap::Sample(double u, double v, std::span<float> out) const {
  std::fill(out.begin(), out.end(), 0.0f);
  const double tu = std::floor(u), tv = std::floor(v);
  if (!(tu >= 0 && tu <= 9 && tv >= 0 && tv <= 98)) return false;
  const int index = tile_index_[static_cast<std::size_t>(tu + 10 * tv)];
  if (index < 0) return false;
  const UvMapTile& tile = tiles_[static_cast<std::size_t>(index)];
  const int n = resolution_;
  const double x = (u - tu) * n - 0.5, y = (v - tv) * n - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double wx = x - fx, wy = y - fy;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  auto at = [&](int i, int j, int c) {
    i = std::clamp(i, 0, n - 1);
    j = std::clamp(j, 0, n - 1);
    return static_cast<double>(tile.values[(static_cast<std::size_t>(j) * n + i) * channels_ + c]);
  };
  for (int c = 0; c < channels_; ++c) {
    out[c] = static_cast<float>((1 - wy) * ((1 - wx) * at(x0, y0, c) + wx * at(x0 + 1, y0, c)) +
                                wy * ((1 - wx) * at(x0, y0 + 1, c) + wx * at(x0 + 1, y0 + 1, c)));
  }
  return true;
}

std::string UvMap::Attribute(const std::string& name) const {
  if (tiles_.empty()) return "";
  for (const auto& [key, value] : tiles_[0].attributes) {
    if (key == name) return value;
  }
  return "";
}

}  // namespace dispex
