// `dispex info MAP.<UDIM>.exr` (or one tile's name): the UV-space part of the info subcommand
// (see cmd_info.cpp): the tiles, their size and channels, each tile's value range and how many
// texels are not finite, and the dispex:* conventions of the header. --json: the same as JSON.
#include <fmt/format.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "command.h"
#include "dispex/uv_map.h"
#include "info.h"

namespace dispex::cli {

int UvMapInfo(const InfoOptions& options) {
  auto map = UvMap::Open(options.path);
  if (!map.ok()) return ReportFailure(map.status());
  const std::string json = UvMapSummaryJson(*map);
  if (options.json) {
    std::puts(json.c_str());
    return 0;
  }
  const nlohmann::json j = nlohmann::json::parse(json);
  const int channels = j["channels"];
  std::string text = fmt::format("UV map      {} ({} tiles of {}x{}, {} channel{})\n", options.path,
                                 j["tiles"].size(), int(j["resolution"]), int(j["resolution"]),
                                 channels, channels == 1 ? "" : "s");
  for (const auto& tile : j["tiles"]) {
    const std::size_t not_finite = tile["not_finite"];
    text += fmt::format("  tile {}  values [{:.6g}, {:.6g}]{}  {}\n", int(tile["udim"]),
                        double(tile["min"]), double(tile["max"]),
                        not_finite ? fmt::format(", {} not finite", not_finite) : "",
                        std::string(tile["path"]));
  }
  for (const auto& [key, value] : j["attributes"].items()) {
    text += fmt::format("  {:<24} {}\n", key, std::string(value));
  }
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace dispex::cli
