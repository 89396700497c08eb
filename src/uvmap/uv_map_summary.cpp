#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "dispex/uv_map.h"

namespace dispex {

std::string UvMapSummaryJson(const UvMap& map) {
  nlohmann::json j;
  j["kind"] = map.channels() == 1 ? "scalar" : "vector";
  j["resolution"] = map.resolution();
  j["channels"] = map.channels();
  nlohmann::json tiles = nlohmann::json::array();
  for (std::size_t t = 0; t < map.tiles().size(); ++t) {
    const UvMapTile& tile = map.tiles()[t];
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    std::size_t not_finite = 0;
    for (float v : tile.values) {
      if (!std::isfinite(v)) {
        ++not_finite;
        continue;
      }
      lo = std::min(lo, double(v));
      hi = std::max(hi, double(v));
    }
    if (lo > hi) lo = hi = 0;
    tiles.push_back({{"udim", tile.udim},
                     {"path", map.paths()[t]},
                     {"min", lo},
                     {"max", hi},
                     {"not_finite", not_finite}});
  }
  j["tiles"] = tiles;
  nlohmann::json attributes = nlohmann::json::object();
  for (const auto& [key, value] : map.tiles().front().attributes) {
    if (key.rfind("dispex:", 0) == 0) attributes[key] = value;
  }
  j["attributes"] = attributes;
  return j.dump(2);
}

}  // namespace dispex
