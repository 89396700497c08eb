// Extraction from a real scan with its cage: no truth exists, so the map is bounded by its
// two-sided distances to the scan (verify), in units of the map's tolerance, and the same
// bounds must reject every negative control.
#include <gtest/gtest.h>

#include <string>

#include "dispex/extract.h"
#include "dispex/verify.h"
#include "e2e_support.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::TempDir;
using testing::WrongMap;

// The Stanford bunny scan (69,451 triangles, five holes in its base) and the 1,032-quad cage
// QuadriFlow made from it (tests/data/README.md). The cage closes the holes, so the samples
// over them miss (1.5%) and are filled, and the displaced surface there has no scan to be
// measured against: map -> scan is bounded loosely, scan -> map (every scan vertex near the
// displaced surface) tightly. Measured (verify at 16 samples per face side, in tolerances):
// the map 0.73 / 2.8 / 5.0 / 15 for the four bounds below; the map scaled by 0.8, the closest
// wrong map, 3.1 / 10 / 6.1 / 28.
struct Bounds {
  double scan_to_map_rms, scan_to_map_p99, map_to_scan_rms, map_to_scan_p99;  // x tolerance
};
constexpr Bounds kBunny{1.0, 4.0, 8.0, 25.0};

class RealPairs : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = DataPath("meshes/stanford_bunny/bun_zipper_quadriflow_1000.obj");
    scan_ = DataPath("meshes/stanford_bunny/bun_zipper.ply");
    ExtractOptions options;
    options.base_path = base_;
    options.sculpt_path = scan_;
    options.output_path = dir_ / "bunny.ptx";
    auto report = Extract(options);
    ASSERT_TRUE(report.ok()) << report.status().message();
    tolerance_ = report->tolerance;
    misses_ = report->miss_fraction;
  }

  // Which two-sided bound `map` breaks ("" when none).
  std::string Broken(const std::string& map) {
    VerifyOptions verify;
    verify.base_path = base_;
    verify.sculpt_path = scan_;
    verify.map_path = map;
    verify.samples_per_face = 16;
    auto r = Verify(verify);
    EXPECT_TRUE(r.ok()) << r.status().message();
    if (!r.ok()) return "verify failed";
    const double t = tolerance_;
    const auto over = [&](const char* what, double value, double bound) {
      return value > bound * t ? std::string(what) + " " + std::to_string(value / t) + " tolerances"
                               : std::string();
    };
    for (const std::string& s :
         {over("scan->map RMS", r->sculpt_to_map.rms, kBunny.scan_to_map_rms),
          over("scan->map p99", r->sculpt_to_map.p99, kBunny.scan_to_map_p99),
          over("map->scan RMS", r->map_to_sculpt.rms, kBunny.map_to_scan_rms),
          over("map->scan p99", r->map_to_sculpt.p99, kBunny.map_to_scan_p99)}) {
      if (!s.empty()) return s;
    }
    return "";
  }

  TempDir dir_;
  std::string base_, scan_;
  double tolerance_ = 0, misses_ = 0;
};

TEST_F(RealPairs, BunnyScanIsWithinItsTwoSidedBoundsAndEveryWrongMapIsNot) {
  EXPECT_LT(misses_, 0.03);
  EXPECT_EQ(Broken(dir_ / "bunny.ptx"), "");
  for (WrongMap kind : testing::kWrongMaps) {
    const std::string wrong = dir_ / "wrong.ptx";
    testing::WriteWrongMap(dir_ / "bunny.ptx", wrong, kind);
    EXPECT_NE(Broken(wrong), "") << testing::WrongMapName(kind) << " passed the bounds";
  }
}

}  // namespace
}  // namespace dispex
