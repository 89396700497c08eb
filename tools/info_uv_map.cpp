// `dispex info MAP.<UDIM>.exr` (or one tile's name): the UV-space part of the info subcommand
// (see cmd_info.cpp): the tiles, their size and channels, each tile's value range and how many
// texels are not finite, and the dispex:* conventions of the header. --json: the same as JSON.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "command.h"
#include "dispex/uv_map.h"
#include "info.h"

namespace dispex::cli {

int UvMapInfo(const InfoOptions& options) {
  auto map = UvMap::Open(options.path);
  if (!map.ok()) return ReportFailure(map.status());
  nlohmann::json j;
  j["kind"] = map->channels() == 1 ? "scalar" : "vector";
  j["resolution"] = map->resolution();
  j["channels"] = map->channels();
  nlohmann::json tiles = nlohmann::json::array();
  std::string text = fmt::format("UV map      {} ({} tiles of {}x{}, {} channel{})\n", options.path,
                                 map->tiles().size(), map->resolution(), map->resolution(),
                                 map->channels(), map->channels() == 1 ? "" : "s");
  for (std::size_t t = 0; t < map->tiles().size(); ++t) {
    const UvMapTile& tile = map->tiles()[t];
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
                     {"path", map->paths()[t]},
                     {"min", lo},
                     {"max", hi},
                     {"not_finite", not_finite}});
    text +=
        fmt::format("  tile {}  values [{:.6g}, {:.6g}]{}  {}\n", tile.udim, lo, hi,
                    not_finite ? fmt::format(", {} not finite", not_finite) : "", map->paths()[t]);
  }
  j["tiles"] = tiles;
  nlohmann::json attributes = nlohmann::json::object();
  for (const auto& [key, value] : map->tiles().front().attributes) {
    if (key.rfind("dispex:", 0) != 0) continue;
    attributes[key] = value;
    text += fmt::format("  {:<24} {}\n", key, value);
  }
  j["attributes"] = attributes;
  if (options.json) {
    std::puts(j.dump(2).c_str());
  } else {
    std::fputs(text.c_str(), stdout);
  }
  return 0;
}

}  // namespace dispex::cli
