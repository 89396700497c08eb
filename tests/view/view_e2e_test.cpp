// Review pages of real maps (`dispex view`): what a page holds for a scalar map with its sculpt,
// verify report and extraction report, a map with misses, a vector map and UV-space tiles; the
// budgets; the errors; the command line. The page in a browser: browser_test.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "../extract/e2e_support.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/ptex.h"
#include "dispex/verify.h"
#include "dispex/view.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::DataPath;
using testing::RunDispex;
using testing::Slurp;
using testing::TempDir;

const std::string kSpot = DataPath("meshes/keenan_spot/spot_control_mesh.obj");

// The JSON a page holds.
json PageData(const std::string& html) {
  const std::string open = "<script id=\"dispex-data\" type=\"application/json\">";
  const std::size_t begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const std::size_t end = html.find("</script>", begin);
  return json::parse(html.substr(begin + open.size(), end - begin - open.size()));
}

std::vector<std::uint8_t> Unbase64(const std::string& text) {
  std::vector<std::uint8_t> out;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (char c : text) {
    int v = c >= 'A' && c <= 'Z'   ? c - 'A'
            : c >= 'a' && c <= 'z' ? c - 'a' + 26
            : c >= '0' && c <= '9' ? c - '0' + 52
            : c == '+'             ? 62
            : c == '/'             ? 63
                                   : -1;
    if (v < 0) continue;
    buffer = (buffer << 6) | std::uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>(buffer >> bits));
    }
  }
  return out;
}
template <class T>
std::vector<T> ArrayOf(const json& text) {
  const auto bytes = Unbase64(text.get<std::string>());
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

void MakeSculptOrDie(const std::string& cage, const std::string& out, int levels, Pattern pattern,
                     double amplitude) {
  auto made = MakeSculpt(testing::SculptOptions(cage, out, levels, pattern, amplitude));
  ASSERT_TRUE(made.ok()) << made.status().message();
}

// A level-1 smooth sculpt of Spot and its map: dir/sculpt.obj and dir/spot.ptx.
void MakeSpotMap(const TempDir& dir) {
  MakeSculptOrDie(kSpot, dir / "sculpt.obj", 1, Pattern::kSmooth, 0.01);
  ExtractOptions extract;
  extract.base_path = kSpot;
  extract.sculpt_path = dir / "sculpt.obj";
  extract.output_path = dir / "spot.ptx";
  ASSERT_TRUE(Extract(extract).ok());
}

void WriteText(const std::string& path, const std::string& text) {
  ASSERT_TRUE(WriteFileAtomically(path, text.data(), text.size()).ok());
}

TEST(ViewPage, ScalarMapWithSculptVerifyAndExtractReport) {
  TempDir dir;
  MakeSculptOrDie(kSpot, dir / "sculpt.obj", 2, Pattern::kDetail, 0.01);
  ExtractOptions extract;
  extract.base_path = kSpot;
  extract.sculpt_path = dir / "sculpt.obj";
  extract.output_path = dir / "spot.ptx";
  auto extracted = Extract(extract);
  ASSERT_TRUE(extracted.ok()) << extracted.status().message();
  WriteText(dir / "extract.json", ExtractReportJson(*extracted));
  VerifyOptions verify;
  verify.base_path = kSpot;
  verify.sculpt_path = dir / "sculpt.obj";
  verify.map_path = dir / "spot.ptx";
  verify.truth_path = dir / "sculpt.obj.truth";
  auto verified = Verify(verify);
  ASSERT_TRUE(verified.ok()) << verified.status().message();
  ASSERT_EQ(verified->face_map_to_sculpt_max.size(), 252u);
  ASSERT_EQ(verified->face_truth_max.size(), 252u);
  double largest = 0, largest_truth = 0;
  for (double e : verified->face_map_to_sculpt_max) largest = std::max(largest, e);
  for (double e : verified->face_truth_max) largest_truth = std::max(largest_truth, e);
  EXPECT_DOUBLE_EQ(largest, verified->map_to_sculpt.max);
  EXPECT_DOUBLE_EQ(largest_truth, verified->truth.max);
  ASSERT_FALSE(verified->worst_faces.empty());
  EXPECT_DOUBLE_EQ(verified->face_map_to_sculpt_max[std::size_t(verified->worst_faces[0].face)],
                   largest);
  const std::string verify_json = VerifyReportJson(*verified);
  EXPECT_EQ(json::parse(verify_json)["per_face"]["truth_max"].size(), 252u);
  WriteText(dir / "verify.json", verify_json);

  ViewPageOptions o;
  o.base_path = kSpot;
  o.map_path = dir / "spot.ptx";
  o.sculpt_path = dir / "sculpt.obj";
  o.verify_report_path = dir / "verify.json";
  o.extract_report_path = dir / "extract.json";
  o.max_vertices = 100'000;
  o.max_sculpt_vertices = 2'000;
  ViewPageReport report;
  auto html = MakeViewPage(o, &report);
  ASSERT_TRUE(html.ok()) << html.status().message();
  EXPECT_EQ(report.page_bytes, std::int64_t(html->size()));
  EXPECT_EQ(html->rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html->find("default-src 'none'"), std::string::npos);
  EXPECT_NE(html->find("REVISION=\"111\""), std::string::npos);
  for (const char* marker : {"@DATA@", "@THREE@", "@VIEWER@", "@CSS@", "@TITLE@"}) {
    EXPECT_EQ(html->find(marker), std::string::npos) << marker;
  }
  EXPECT_NE(html->find("<title>spot.ptx - dispex view</title>"), std::string::npos);

  const json data = PageData(*html);
  EXPECT_EQ(data["map"]["kind"], "scalar");
  EXPECT_EQ(data["map"]["faces"], 252);
  EXPECT_TRUE(data["map"]["meta"].contains("dispex:options"));
  EXPECT_TRUE(data["map"]["meta"]["dispex:statistics"].is_object());
  EXPECT_FALSE(data["map"]["meta"].contains("dispex:face_keys"));
  EXPECT_DOUBLE_EQ(data["map"]["tolerance"].get<double>(), extracted->settings.tolerance);
  EXPECT_EQ(data["extract_report"]["phases_seconds"].size(),
            json::parse(ExtractReportJson(*extracted))["phases_seconds"].size());
  EXPECT_FALSE(data["verify"].contains("per_face")) << "the faces hold them";
  EXPECT_TRUE(report.verify_per_face);
  EXPECT_TRUE(report.holes_per_face);
  EXPECT_TRUE(report.atlas);
  EXPECT_EQ(data["atlas"].get<std::string>().rfind("data:image/png;base64,iVBOR", 0), 0u);

  // The grid: the finest within the budget, one step finer over it.
  const int grid = data["surface"]["grid"];
  EXPECT_EQ(grid, report.grid);
  EXPECT_EQ(grid % 2, 0);
  EXPECT_LE(report.surface_vertices, o.max_vertices);
  EXPECT_EQ(data["surface"]["vertices"], report.surface_vertices);

  // The value at face 0's centre is the map's there (within the 16 bits).
  const auto quads = ArrayOf<std::uint16_t>(data["surface"]["quads"]);
  ASSERT_EQ(quads.size(), 252u);
  const int n = quads[0];
  std::int64_t next_points = 0;  // at the next grid: about a vertex a quad
  for (std::uint16_t q : quads) {
    next_points += 1 + (q == grid ? (grid + 2) * (grid + 2) : (grid / 2 + 1) * (grid / 2 + 1));
  }
  EXPECT_GT(next_points, o.max_vertices);
  const auto values = ArrayOf<std::int16_t>(data["surface"]["value"]);
  const double scale = data["surface"]["value_scale"];
  const std::size_t centre = std::size_t(n / 2 - 1) * (n - 1) + (n / 2 - 1);
  auto map = PtexFile::Open(dir / "spot.ptx");
  ASSERT_TRUE(map.ok());
  EXPECT_NEAR(values[centre] * scale, map->Sample(PtexFaceId(0), 0.5f, 0.5f), scale + 1e-6);

  // Per face: resolutions as stored, errors as verify measured them.
  const auto ulog2 = ArrayOf<std::int8_t>(data["faces"]["ulog2"]);
  const auto truth = ArrayOf<float>(data["faces"]["error_truth"]);
  for (int f = 0; f < 252; ++f) {
    EXPECT_EQ(ulog2[std::size_t(f)], map->face_info(PtexFaceId(f)).ulog2);
    EXPECT_FLOAT_EQ(truth[std::size_t(f)], float(verified->face_truth_max[std::size_t(f)]));
  }

  // The sculpt: within its budget.
  EXPECT_EQ(report.sculpt_vertices_read, std::int64_t(extracted->inputs.sculpt_vertices));
  EXPECT_LE(report.sculpt_vertices, o.max_sculpt_vertices);
  EXPECT_GT(report.sculpt_vertices, o.max_sculpt_vertices / 4);
  EXPECT_GT(report.sculpt_cell, 0);
  EXPECT_EQ(data["sculpt"]["vertices"], report.sculpt_vertices);
  EXPECT_EQ(ArrayOf<std::uint32_t>(data["sculpt"]["index"]).size(),
            3 * std::size_t(report.sculpt_triangles));

  // The report as JSON.
  const json r = json::parse(ViewPageReportJson(report));
  EXPECT_EQ(r["bytes"]["page"], report.page_bytes);
  EXPECT_EQ(r["grid"], grid);
}

TEST(ViewPage, MissesPerFaceFromTheMapsRecords) {
  TempDir dir;
  MakeSculptOrDie(kSpot, dir / "whole.obj", 2, Pattern::kSmooth, 0.01);
  // Only the sculpt's faces on one side of x = 0.1: the faces beyond miss.
  auto sculpt = ReadMesh(dir / "whole.obj");
  ASSERT_TRUE(sculpt.ok());
  Mesh part = *sculpt;
  part.face_offsets = {0};
  part.face_indices.clear();
  for (std::size_t f = 0; f < sculpt->num_faces(); ++f) {
    const auto face = sculpt->face(f);
    if (sculpt->positions[static_cast<std::size_t>(face[0])].x > 0.1f) continue;
    part.face_indices.insert(part.face_indices.end(), face.begin(), face.end());
    part.face_offsets.push_back(static_cast<std::uint32_t>(part.face_indices.size()));
  }
  ASSERT_TRUE(WriteObj(dir / "part.obj", part).ok());
  ExtractOptions extract;
  extract.base_path = kSpot;
  extract.sculpt_path = dir / "part.obj";
  extract.output_path = dir / "part.ptx";
  extract.max_miss_fraction = 1;
  extract.check_inputs = false;
  auto extracted = Extract(extract);
  ASSERT_TRUE(extracted.ok()) << extracted.status().message();
  ASSERT_GT(extracted->sampling.misses, 0);

  ViewPageOptions o;
  o.base_path = kSpot;
  o.map_path = dir / "part.ptx";
  o.max_vertices = 20'000;
  ViewPageReport report;
  auto html = MakeViewPage(o, &report);
  ASSERT_TRUE(html.ok()) << html.status().message();
  ASSERT_TRUE(report.holes_per_face);
  const json data = PageData(*html);
  const auto misses = ArrayOf<std::int32_t>(data["faces"]["misses"]);
  const auto filled = ArrayOf<std::int32_t>(data["faces"]["filled"]);
  const auto all_missed = ArrayOf<std::uint8_t>(data["faces"]["all_missed"]);
  std::int64_t sum = 0, sum_filled = 0, whole = 0;
  for (std::size_t f = 0; f < misses.size(); ++f) {
    sum += misses[f], sum_filled += filled[f], whole += all_missed[f];
  }
  EXPECT_EQ(sum, extracted->sampling.misses);
  EXPECT_EQ(sum_filled, extracted->sampling.holes_filled);
  EXPECT_EQ(whole, extracted->sampling.faces_filled_from_neighbours +
                       extracted->sampling.faces_unreachable);
  EXPECT_LE(report.surface_vertices, 20'000);
  EXPECT_FALSE(data.contains("verify") && !data["verify"].is_null());
}

TEST(ViewPage, VectorMapDisplacesByItsVectors) {
  TempDir dir;
  MakeSculptOrDie(kSpot, dir / "sideways.obj", 2, Pattern::kSideways, 0.01);
  ExtractOptions extract;
  extract.base_path = kSpot;
  extract.sculpt_path = dir / "sideways.obj";
  extract.output_path = dir / "vector.ptx";
  extract.vector = VectorSpace::kObject;
  auto extracted = Extract(extract);
  ASSERT_TRUE(extracted.ok()) << extracted.status().message();
  ViewPageOptions o;
  o.base_path = kSpot;
  o.map_path = dir / "vector.ptx";
  o.grid = 4;
  ViewPageReport report;
  auto html = MakeViewPage(o, &report);
  ASSERT_TRUE(html.ok()) << html.status().message();
  EXPECT_EQ(report.map_kind, "vector");
  EXPECT_EQ(report.vector_space, "object");
  EXPECT_EQ(report.grid, 4);
  EXPECT_FALSE(report.holes_per_face);
  const json data = PageData(*html);
  EXPECT_EQ(data["surface"]["value_name"], "D·N");
  EXPECT_NE(data["faces"]["holes_note"].get<std::string>().find("no misses"), std::string::npos);
  // Face 0's interior point (1, 1) is at (1/4, 1/4): D is the map's channels there.
  const auto d = ArrayOf<std::int16_t>(data["surface"]["displacement"]);
  const double scale = data["surface"]["displacement_scale"];
  auto map = PtexFile::Open(dir / "vector.ptx");
  ASSERT_TRUE(map.ok());
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(d[std::size_t(c)] * scale, map->Sample(PtexFaceId(0), 0.25f, 0.25f, c),
                scale + 1e-6);
  }
}

TEST(ViewPage, UvSpaceTiles) {
  TempDir dir;
  const std::string cage = DataPath("uv_maps/udim_box.obj");
  MakeSculptOrDie(cage, dir / "box.obj", 2, Pattern::kDetail, 0.02);
  ExtractOptions extract;
  extract.base_path = cage;
  extract.sculpt_path = dir / "box.obj";
  extract.output_path = dir / "box.ptx";
  extract.uv_maps_dir = dir / "uv";
  extract.uv_resolution = 64;
  auto extracted = Extract(extract);
  ASSERT_TRUE(extracted.ok()) << extracted.status().message();
  ViewPageOptions o;
  o.base_path = cage;
  o.map_path = dir / "uv/box.<UDIM>.exr";
  o.max_vertices = 10'000;
  ViewPageReport report;
  auto html = MakeViewPage(o, &report);
  ASSERT_TRUE(html.ok()) << html.status().message();
  EXPECT_EQ(report.map_kind, "uv scalar");
  EXPECT_TRUE(report.atlas) << "the tiles, side by side";
  const json data = PageData(*html);
  EXPECT_EQ(data["map"]["tiles"].size(), 6u);
  EXPECT_EQ(data["map"]["resolution"], 64);
  EXPECT_FALSE(data["faces"].contains("ulog2"));
  EXPECT_TRUE(data["faces"]["without_tile"].empty());
  // The page of the Ptex map displaces alike, to the tiles' resolution.
  o.map_path = dir / "box.ptx";
  ViewPageReport ptex_report;
  auto ptex_html = MakeViewPage(o, &ptex_report);
  ASSERT_TRUE(ptex_html.ok());
  const json ptex_data = PageData(*ptex_html);
  const auto a = ArrayOf<std::int16_t>(data["surface"]["value"]);
  const auto b = ArrayOf<std::int16_t>(ptex_data["surface"]["value"]);
  const double sa = data["surface"]["value_scale"], sb = ptex_data["surface"]["value_scale"];
  ASSERT_EQ(a.size(), b.size());
  // The same displacement read two ways (the 64-texel tiles smooth the pattern's ridges).
  double values = 0, differences = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    values += a[i] * sa * a[i] * sa;
    differences += (a[i] * sa - b[i] * sb) * (a[i] * sa - b[i] * sb);
  }
  EXPECT_GT(values, 0);
  EXPECT_LT(std::sqrt(differences), 0.5 * std::sqrt(values));
}

TEST(ViewPage, ErrorsNameTheFile) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(MakeSpotMap(dir));
  ViewPageOptions o;
  o.base_path = DataPath("meshes/opensubdiv/catmark_cube.obj");
  o.map_path = dir / "spot.ptx";
  auto other_base = MakeViewPage(o);
  ASSERT_FALSE(other_base.ok());
  EXPECT_EQ(other_base.status().code(), StatusCode::kMismatch);
  EXPECT_EQ(other_base.status().message(), o.map_path + ": 252 faces, but " + o.base_path +
                                               " has 6 Ptex faces: not a map of this base mesh");

  o.base_path = kSpot;
  WriteText(dir / "verify.json", R"({"ptex_faces": 6, "passed": true})");
  o.verify_report_path = dir / "verify.json";
  auto other_report = MakeViewPage(o);
  ASSERT_FALSE(other_report.ok());
  EXPECT_EQ(
      other_report.status().message(),
      o.verify_report_path + ": a report of a map of 6 faces, but " + o.map_path + " has 252");
  WriteText(dir / "verify.json", "not json");
  auto not_json = MakeViewPage(o);
  ASSERT_FALSE(not_json.ok());
  EXPECT_EQ(not_json.status().code(), StatusCode::kBadInput);
  EXPECT_NE(not_json.status().message().find("not a JSON object"), std::string::npos);
  o.verify_report_path.clear();
  o.sculpt_path = dir / "missing.obj";
  auto missing = MakeViewPage(o);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message().rfind(o.sculpt_path, 0), 0u) << missing.status().message();
}

TEST(ViewCommand, WritesThePageAndReport) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(MakeSpotMap(dir));
  const std::string args = kSpot + " " + (dir / "spot.ptx") + " --sculpt " + (dir / "sculpt.obj") +
                           " --max-vertices 5000 -o " + (dir / "pages/spot.html") + " --report " +
                           (dir / "view.json");
  auto r = RunDispex("view " + args, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("pages/spot.html ("), std::string::npos) << r.err;
  const std::string page = Slurp(dir / "pages/spot.html");
  const json report = json::parse(Slurp(dir / "view.json"));
  EXPECT_EQ(report["bytes"]["page"], page.size());
  EXPECT_LE(report["surface"]["vertices"].get<int>(), 5000);

  auto bad = RunDispex(
      "view " + kSpot + " " + (dir / "spot.ptx") + " --grid 300 -o " + (dir / "x.html"), dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.err, "dispex: --grid 300: must be 0 (automatic) or 1..256\n");
  auto odd = RunDispex(
      "view " + kSpot + " " + (dir / "spot.ptx") + " --grid 3 -o " + (dir / "x.html"), dir);
  EXPECT_EQ(odd.exit_code, 2);
  EXPECT_EQ(odd.err, "dispex: --grid 3: must be even: " + kSpot +
                         " has n-gons, whose sub-faces take half the quads a side\n");
  EXPECT_FALSE(fs::exists(dir / "x.html"));
  auto into_file = RunDispex(
      "view " + kSpot + " " + (dir / "spot.ptx") + " -o " + (dir / "view.json/x.html"), dir);
  EXPECT_EQ(into_file.exit_code, 2) << into_file.err;
  EXPECT_EQ(into_file.err.rfind("dispex: -o", 0), 0u) << into_file.err;
  auto missing =
      RunDispex("view " + kSpot + " " + (dir / "nope.ptx") + " -o " + (dir / "y.html"), dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nope.ptx"), std::string::npos) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  EXPECT_FALSE(fs::exists(dir / "y.html"));
}

TEST(ViewCommand, BatchWritesAPagePerAssetAndAnIndex) {
  TempDir dir;
  MakeSculptOrDie(kSpot, dir / "spot_sculpt.obj", 1, Pattern::kSmooth, 0.01);
  const std::string cube = DataPath("meshes/opensubdiv/catmark_cube.obj");
  MakeSculptOrDie(cube, dir / "cube_sculpt.obj", 2, Pattern::kSmooth, 0.02);
  WriteText(dir / "batch.json", json({{"assets",
                                       {{{"name", "spot"},
                                         {"base", kSpot},
                                         {"sculpt", "spot_sculpt.obj"},
                                         {"output_dir", "maps"}},
                                        {{"name", "cube"},
                                         {"base", cube},
                                         {"sculpt", "spot_sculpt.obj"},
                                         {"output_dir", "maps"}}}}})
                                    .dump());
  // The cube's sculpt is Spot's: its extraction fails, the batch goes on and says so.
  auto r = RunDispex("batch " + (dir / "batch.json") + " --view " + (dir / "pages") + " --report " +
                         (dir / "report.json"),
                     dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(fs::exists(dir / "pages/spot.html"));
  EXPECT_FALSE(fs::exists(dir / "pages/cube.html"));
  const std::string index = Slurp(dir / "pages/index.html");
  EXPECT_NE(index.find("<a href=\"spot.html\">spot</a>"), std::string::npos) << index;
  EXPECT_NE(index.find("<tr class=\"failed\"><td>cube</td>"), std::string::npos) << index;
  const json report = json::parse(Slurp(dir / "report.json"));
  EXPECT_EQ(report["assets"][0]["view"], dir / "pages/spot.html");
  EXPECT_EQ(report["pages_failed"], 0);
  // The page holds the extraction's report (its times).
  const json data = PageData(Slurp(dir / "pages/spot.html"));
  EXPECT_EQ(data["title"], "spot");
  EXPECT_TRUE(data["extract_report"].contains("phases_seconds"));
  EXPECT_EQ(data["inputs"]["sculpt"], "spot_sculpt.obj");
}

}  // namespace
}  // namespace dispex
