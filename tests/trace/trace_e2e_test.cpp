// The tracer through the dispex binary: a creased cage whose flat sides give noisy normals
// loses no samples, and the maps agree under every Embree ISA this CPU runs.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/ptex.h"
#include "dispex/trace.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::RunDispex;
using testing::TempDir;

// A 2 x 2 x 2 box as a column of 5 rings of 4 side quads plus 2 caps (22 quads), its vertical
// edges semi-sharp (1.0) so the sides round like a cylinder, its rims creased 2.0. The sides
// are extruded along z, so their limit normals have a z component that is rounding noise.
void WriteCreaseColumn(const std::string& path) {
  std::ofstream out(path);
  for (int k = 0; k < 6; ++k) {
    for (const auto& [x, y] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      out << fmt::format("v {} {} {}\n", x, y, -1 + 0.4 * k);
    }
  }
  for (int k = 0; k < 5; ++k) {
    for (int c = 0; c < 4; ++c) {
      const int a = 4 * k + c + 1, b = 4 * k + (c + 1) % 4 + 1;
      out << fmt::format("f {} {} {} {}\n", a, b, b + 4, a + 4);
    }
  }
  out << "f 4 3 2 1\nf 21 22 23 24\n";
  for (int k = 0; k < 5; ++k) {
    for (int c = 0; c < 4; ++c)
      out << fmt::format("t crease 2/1/0 {} {} 1.0\n", 4 * k + c, 4 * k + c + 4);
  }
  for (const int ring : {0, 5}) {
    for (int c = 0; c < 4; ++c) {
      out << fmt::format("t crease 2/1/0 {} {} 2.0\n", 4 * ring + c, 4 * ring + (c + 1) % 4);
    }
  }
}

nlohmann::json ReadJson(const std::string& path) {
  return nlohmann::json::parse(testing::Slurp(path));
}

TEST(TraceE2eTest, CreaseColumnLosesNoSamples) {
  TempDir dir;
  const std::string cage = dir / "column.obj", sculpt = dir / "sculpt.obj";
  WriteCreaseColumn(cage);
  auto made = RunDispex(fmt::format("make-sculpt {} --levels 4 -o {}", cage, sculpt), dir);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  auto r = RunDispex(fmt::format("extract {} {} -o {} --report {} -q", cage, sculpt,
                                 dir / "map.ptx", dir / "r.json"),
                     dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = ReadJson(dir / "r.json");
  EXPECT_EQ(report["statistics"]["misses"], 0);
  EXPECT_EQ(report["statistics"]["misses_recovered"], 0);
  EXPECT_GT(report["statistics"]["samples"].get<int>(), 20000);
}

// Every texel of every face at level 0, as floats.
std::vector<float> Texels(const std::string& path) {
  auto file = PtexFile::Open(path);
  EXPECT_TRUE(file.ok()) << file.status().message();
  std::vector<float> all, face;
  if (!file.ok()) return all;
  for (int f = 0; f < file->num_faces(); ++f) {
    EXPECT_TRUE(file->ReadFace(PtexFaceId(f), 0, face).ok());
    all.insert(all.end(), face.begin(), face.end());
  }
  return all;
}

TEST(TraceE2eTest, MapsAreIdenticalUnderEveryIsa) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string sculpt = dir / "sculpt.obj";
  auto made = RunDispex(fmt::format("make-sculpt {} --levels 3 --pattern detail --amplitude "
                                    "0.005 -o {}",
                                    cage, sculpt),
                        dir);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  std::vector<float> first;
  std::string first_isa;
  for (const std::string_view isa : SupportedEmbreeIsas()) {
    const std::string map = dir / fmt::format("{}.ptx", isa), json = dir / "r.json";
    // Rays: the refined sculpt would otherwise go through the subdivision correspondence.
    auto r = RunDispex(fmt::format("extract {} {} -o {} --report {} -q --method rays "
                                   "--embree-isa {}",
                                   cage, sculpt, map, json, isa),
                       dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string tracer = ReadJson(json)["tracer"];
    EXPECT_NE(tracer.find(fmt::format("({}, forced)", isa)), std::string::npos) << tracer;
    const std::vector<float> texels = Texels(map);
    ASSERT_GT(texels.size(), 10000u);
    if (first_isa.empty()) {
      first = texels;
      first_isa = isa;
      continue;
    }
    ASSERT_EQ(texels.size(), first.size()) << isa;
    std::size_t differ = 0;
    double largest = 0;
    for (std::size_t i = 0; i < texels.size(); ++i) {
      if (texels[i] == first[i]) continue;
      ++differ;
      largest = std::max(largest, std::fabs(double(texels[i]) - first[i]));
    }
    EXPECT_EQ(differ, 0u) << isa << " vs " << first_isa << ": largest difference " << largest;
  }
}

TEST(TraceE2eTest, AnIsaTheCpuLacksIsAOneLineError) {
  const auto supported = SupportedEmbreeIsas();
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  auto bad = RunDispex(
      fmt::format("extract {} {} -o {} --embree-isa avx3", cage, cage, dir / "m.ptx"), dir);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("isa 'avx3': unknown Embree ISA"), std::string::npos) << bad.err;
  for (const std::string_view isa : EmbreeIsaNames()) {
    if (std::find(supported.begin(), supported.end(), isa) != supported.end()) continue;
    auto r = RunDispex(
        fmt::format("extract {} {} -o {} --embree-isa {}", cage, cage, dir / "m.ptx", isa), dir);
    EXPECT_NE(r.exit_code, 0) << isa;
    EXPECT_NE(r.err.find("this CPU lacks"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(testing::fs::exists(dir / "m.ptx"));
  }
}

}  // namespace
}  // namespace dispex
