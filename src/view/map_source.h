// The map a review page shows (dispex view): a Ptex map or UV-space tiles, read once, and how
// it displaces the limit surface as a renderer reads it.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/ptex_sampler.h"
#include "dispex/status.h"
#include "dispex/subdiv.h"
#include "dispex/uv_charts.h"
#include "dispex/uv_map.h"
#include "dispex/view.h"
#include "view/surface_grid.h"

namespace dispex::view {

using json = nlohmann::json;

// The map as read, and how it displaces the limit surface. `displacement` refers to the other
// members, so a MapSource stays where it was made.
struct MapSource {
  MapSource() = default;
  MapSource(const MapSource&) = delete;
  MapSource& operator=(const MapSource&) = delete;

  std::optional<PtexFile> ptex;
  std::optional<UvMap> uv;
  std::optional<PtexUvCharts> charts;
  std::optional<PtexMapSampler> sampler;
  std::vector<std::vector<float>> texels;
  std::unique_ptr<view::MapDisplacement> displacement;
  std::vector<std::atomic<std::uint8_t>> uv_missing;  // per face: points no tile holds
  json map_json;
  json statistics;  // the Ptex map's dispex:statistics
  double tolerance = 0;
};

// Reads options.map_path (tiles when IsUvMapPath, else a Ptex map of the base's faces) into
// `map`, with the face table of a Ptex map in `faces`; notes for the page in `report`.
Status ReadMap(const ViewPageOptions& options, const Mesh& base, const LimitSurface& surface,
               std::vector<PtexFaceInfo>& faces, ViewPageReport& report, MapSource& map);

}  // namespace dispex::view
