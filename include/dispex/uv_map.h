// UV-space displacement maps on disk: one OpenEXR file per UDIM tile, DIR/<shape>.<UDIM>.exr,
// and reading them back as a renderer does.
//
// A tile is N x N texels, one channel "Y" for a scalar map (the distance along the limit
// normal) or three "R", "G", "B" for a vector map (D's components in the map's space), float32
// or half, ZIP compressed, scanline 0 at the top of the image (v = tile's 1, as OpenEXR and
// every image tool orders rows). The header holds the conventions as string attributes
// (dispex:* below; docs/UV_MAPS.md). Texel centres follow include/dispex/uv_charts.h.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dispex/status.h"

namespace dispex {

// One tile in memory: row j counts from v = 0 (the image's bottom row) up.
struct UvMapTile {
  int udim = 0;
  int resolution = 0;         // N
  int channels = 1;           // 1 or 3
  std::vector<float> values;  // N * N * channels, row-major, i fastest, channels interleaved
  // String attributes of the header (name, value), in name order when read.
  std::vector<std::pair<std::string, std::string>> attributes;
};

// DIR/<shape>.<UDIM>.exr
std::string UvMapTilePath(const std::string& dir, const std::string& shape, int udim);

// Writes `tile` to `path` atomically (complete or not at all, include/dispex/files.h), as
// float32 or, with `half`, OpenEXR half. The same tile gives the same bytes.
Status WriteUvMapTile(const std::string& path, const UvMapTile& tile, bool half);

// Writes tiles[k] to paths[k] as a set: each to a temporary file beside its path, and only once
// every one is complete are they renamed onto their paths, so an error while writing (or a
// SIGINT / SIGTERM, with the handlers of dispex/cancel.h) leaves every tile as it was. (The
// signal handlers remove at most 256 temporaries; a set of more tiles leaves the rest.)
Status WriteUvMapTiles(std::span<const std::string> paths, std::span<const UvMapTile> tiles,
                       bool half);

// Reads a tile written by WriteUvMapTile (or any square scanline OpenEXR file with a "Y"
// channel, or "R", "G" and "B"); `udim` from the file name (…​.<UDIM>.exr), 0 when it has none.
// Errors name the file and what is wrong.
StatusOr<UvMapTile> ReadUvMapTile(const std::string& path);
// The same without the texels (`values` empty): the header's size, channels and attributes.
StatusOr<UvMapTile> ReadUvMapTileHeader(const std::string& path);

// A map's tiles: `pattern` is DIR/<shape>.<UDIM>.exr with the literal "<UDIM>" (as Blender and
// Mari name tiles), or the path of one tile of the set (every DIR/<shape>.NNNN.exr beside it is
// taken). The tiles must agree on resolution and channels.
class UvMap {
 public:
  static StatusOr<UvMap> Open(const std::string& pattern);

  // Bilinear read at `uv` with texel centres at (i+0.5)/N, clamped to the tile's border texels
  // (tiles are read on their own, as UDIM readers do): `out` receives channels() floats.
  // Returns false (out zeroed) where no tile holds `uv`.
  bool Sample(double u, double v, std::span<float> out) const;

  int channels() const { return channels_; }
  int resolution() const { return resolution_; }
  const std::vector<UvMapTile>& tiles() const { return tiles_; }  // by UDIM, ascending
  const std::vector<std::string>& paths() const { return paths_; }
  // The value of a dispex:* attribute of the first tile ("" when absent).
  std::string Attribute(const std::string& name) const;

 private:
  static StatusOr<UvMap> OpenTiles(const std::string& pattern);

  std::vector<UvMapTile> tiles_;
  std::vector<std::string> paths_;
  std::vector<int> tile_index_;  // by UDIM - 1001: index into tiles_, -1 when absent
  int channels_ = 1, resolution_ = 0;
};

// What `dispex info --json` prints of a UV-space map, as JSON: kind ("scalar" or "vector"),
// resolution, channels, each tile's udim, path, value range (min, max) and count of values that
// are not finite, and the header's dispex:* attributes.
std::string UvMapSummaryJson(const UvMap& map);

// Whether `path` names an OpenEXR file (by its magic number, or by name when it does not
// exist: "<UDIM>" or ".exr").
bool IsUvMapPath(const std::string& path);

}  // namespace dispex
