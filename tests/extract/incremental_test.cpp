// Incremental extraction (docs/INCREMENTAL.md): after every edit of a sequence -- local moves
// of sculpt vertices, a locally re-meshed sculpt, a moved base vertex, a crease, an option --
// the incremental map must be byte-identical to a full extraction of the same inputs, while
// re-extracting only part of the faces for local edits. A stale face (one copied although its
// inputs changed) makes the byte comparison fail; a key that changes for every edit makes the
// "part of the faces" checks fail. Vector maps (VectorSpace variants) the same, but for the
// re-meshed sculpt, which they refuse.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <string>

#include "core/hash128.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "e2e_support.h"
#include "extract/incremental/face_records.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::Slurp;
using testing::TempDir;

// A map's face keys and first-pass records, as an incremental run reads them.
struct StoredFaces {
  std::vector<Hash128> keys;
  std::vector<extract::FaceRecord> records;
  std::vector<PtexFaceInfo> faces;  // as written
};
std::optional<StoredFaces> ReadStoredFaces(const std::string& path) {
  auto file = PtexFile::Open(path);
  if (!file.ok()) return std::nullopt;
  const auto n = static_cast<std::size_t>(file->num_faces());
  const int channels = file->header().num_channels;
  const PtexMetaItem* keys = file->FindMetaData(extract::kFaceKeysMetaKey);
  const PtexMetaItem* records = file->FindMetaData(extract::FaceRecordsMetaKey(channels));
  if (keys == nullptr || records == nullptr) return std::nullopt;
  StoredFaces out;
  out.keys = extract::DecodeFaceKeys(keys->bytes, n).value();
  out.records = extract::DecodeFaceRecords(records->bytes, n, channels).value();
  for (std::size_t f = 0; f < n; ++f) out.faces.push_back(file->face_info(PtexFaceId(int(f))));
  return out;
}

// What ExtractReport::incremental.faces_copied_redone must be, from the maps before and after the
// run alone: faces copied (same key, and stored as their first pass before) that are now stored at
// another resolution than their first pass -- raised by the edges, the only stage that changes a
// face after its first pass.
std::int64_t CopiedThenRaised(const std::optional<StoredFaces>& before, const StoredFaces& after) {
  if (!before || before->keys.size() != after.keys.size()) return 0;
  auto first_pass = [](const StoredFaces& m, std::size_t f) {
    const extract::FaceStats& s = m.records[f].stats;
    return s.all_missed || s.samples == 0 ||
           (m.faces[f].ulog2 == s.ulog2 && m.faces[f].vlog2 == s.vlog2);
  };
  std::int64_t n = 0;
  for (std::size_t f = 0; f < after.keys.size(); ++f) {
    if (after.records[f].stats.samples == 0) continue;  // a hole
    n += before->keys[f] == after.keys[f] && first_pass(*before, f) && !first_pass(after, f);
  }
  return n;
}

struct Variant {
  const char* name;
  const char* cage;  // under tests/data/meshes
  int levels;
  PtexDataType data_type;
  WatertightEdges watertight;
  // The automatic search distance depends on the whole sculpt and base (a percentile of sparse
  // distances, to 4 bits): an edit that moves it re-extracts every face. Given, local edits
  // always stay local.
  bool auto_search_distance;
  // A local edit extracts few enough faces for the re-run to trace only the sculpt within
  // their reach (a BVH of part of it): method rays.
  bool local_tracer = false;
  double edit_radius = 0.04;  // of the base's diagonal
  // A vector map (read through the correspondence: the sculpt must stay the base refined).
  std::optional<VectorSpace> vector = std::nullopt;
  // UV-space tiles too (--uv-maps): an incremental run copies the texels of the faces whose key
  // stayed from the tiles before, which must then equal a full extraction's, byte for byte.
  bool uv_maps = false;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.name;
}

class Incremental : public ::testing::TestWithParam<Variant> {
 protected:
  void SetUp() override {
    base_ = dir_ / "base.obj";
    sculpt_ = dir_ / "sculpt.obj";
    auto cage = ReadMesh(DataPath("meshes/") + GetParam().cage);
    ASSERT_TRUE(cage.ok()) << cage.status().message();
    cage_ = std::move(*cage);
    WriteBase();
    auto made = MakeSculpt(
        testing::SculptOptions(base_, sculpt_, GetParam().levels, Pattern::kDetail, 0.005));
    ASSERT_TRUE(made.ok()) << made.status().message();
    auto sculpt = ReadMesh(sculpt_);
    ASSERT_TRUE(sculpt.ok());
    sculpt_mesh_ = std::move(*sculpt);
  }

  ExtractOptions Options(const std::string& output) const {
    ExtractOptions o;
    o.base_path = base_;
    o.sculpt_path = sculpt_;
    o.output_path = output;
    o.data_type = GetParam().data_type;
    o.watertight = GetParam().watertight;
    o.tolerance = tolerance_;
    if (!GetParam().auto_search_distance) {
      o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
    }
    // The BVH of part of the sculpt is the ray path's (the others go through the subdivision
    // correspondence while the sculpt is the base refined).
    if (GetParam().local_tracer) o.method = ExtractMethod::kRays;
    o.vector = GetParam().vector;
    o.uv_resolution = 256;
    o.cache_dir = dir_ / "cache";
    return o;
  }

  // The base: cage_'s positions, then the cage file's other lines (its UVs, faces and tags) and
  // `tags` (WriteObj writes no UVs).
  void WriteBase(const std::string& tags = {}) {
    std::ifstream in(DataPath("meshes/") + GetParam().cage);
    std::string out, line;
    for (const Float3& p : cage_.positions) out += fmt::format("v {} {} {}\n", p.x, p.y, p.z);
    while (std::getline(in, line)) {
      if (line.rfind("v ", 0) != 0) out += line + "\n";
    }
    std::ofstream(base_) << out << tags;
  }

  // The tiles of the map `shape` in `folder`, by file name less the shape.
  static std::map<std::string, std::string> Tiles(const std::string& folder,
                                                  const std::string& shape) {
    std::map<std::string, std::string> out;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(shape + ".", 0) == 0) out[name.substr(shape.size())] = Slurp(entry.path());
    }
    return out;
  }

  // The incremental run on inc.ptx, checked byte for byte against a full run.
  ExtractReport Step(const std::string& what) {
    const std::string full_name = "full_" + std::to_string(step_++);
    ExtractOptions full = Options(dir_ / (full_name + ".ptx"));
    ExtractOptions inc = Options(dir_ / "inc.ptx");
    inc.incremental = true;
    if (GetParam().uv_maps) {
      full.uv_maps_dir = dir_ / ("uv_" + full_name);
      inc.uv_maps_dir = dir_ / "uv_inc";
    }
    auto expected = Extract(full);
    EXPECT_TRUE(expected.ok()) << what << ": " << expected.status().message();
    const std::optional<StoredFaces> before = ReadStoredFaces(inc.output_path);
    auto report = Extract(inc);
    EXPECT_TRUE(report.ok()) << what << ": " << report.status().message();
    if (!report.ok() || !expected.ok()) return {};
    if (!report->incremental.unchanged) {
      const std::optional<StoredFaces> after = ReadStoredFaces(inc.output_path);
      EXPECT_TRUE(after.has_value()) << what;
      if (after) {
        EXPECT_EQ(report->incremental.faces_copied_redone, CopiedThenRaised(before, *after))
            << what;
        redone_ += report->incremental.faces_copied_redone;
      }
    }
    EXPECT_TRUE(Slurp(inc.output_path) == Slurp(full.output_path))
        << what << ": the incremental map differs from a full extraction ("
        << report->incremental.faces_copied << " faces copied, "
        << report->incremental.faces_extracted
        << " extracted): " << testing::MapDifference(inc.output_path, full.output_path);
    if (GetParam().uv_maps) {
      const auto tiles = Tiles(inc.uv_maps_dir, "inc");
      EXPECT_FALSE(tiles.empty()) << what;
      EXPECT_TRUE(tiles == Tiles(full.uv_maps_dir, full_name))
          << what << ": the incremental UV tiles differ from a full extraction's ("
          << report->uv.faces_copied << " faces' texels copied)";
    }
    return *report;
  }

  // Moves the sculpt's vertices within `radius` of a random vertex by a smooth bump.
  void EditSculptInBall(unsigned seed, double radius, double amplitude) {
    std::mt19937 rng(seed);
    const Float3 c = sculpt_mesh_.positions[rng() % sculpt_mesh_.num_vertices()];
    std::uniform_real_distribution<float> dir(-1, 1);
    const Float3 d{dir(rng), dir(rng), dir(rng)};
    for (Float3& p : sculpt_mesh_.positions) {
      const double r = std::hypot(p.x - c.x, p.y - c.y, p.z - c.z);
      if (r >= radius) continue;
      const auto w = static_cast<float>(amplitude * 0.5 * (1 + std::cos(M_PI * r / radius)));
      p = {p.x + w * d.x, p.y + w * d.y, p.z + w * d.z};
    }
    ASSERT_TRUE(WriteObj(sculpt_, sculpt_mesh_).ok());
  }

  // Splits every quad near a random vertex into two triangles: a locally re-meshed sculpt,
  // whose later faces all move to other indices.
  void RemeshSculptLocally(unsigned seed, double radius) {
    std::mt19937 rng(seed);
    const Float3 c = sculpt_mesh_.positions[rng() % sculpt_mesh_.num_vertices()];
    Mesh out = sculpt_mesh_;
    out.face_offsets = {0};
    out.face_indices.clear();
    for (std::size_t f = 0; f < sculpt_mesh_.num_faces(); ++f) {
      const auto face = sculpt_mesh_.face(f);
      const Float3& p = sculpt_mesh_.positions[static_cast<std::size_t>(face[0])];
      const bool near = std::hypot(p.x - c.x, p.y - c.y, p.z - c.z) < radius;
      if (near && face.size() == 4) {
        for (int k : {0, 1, 2, 0, 2, 3}) out.face_indices.push_back(face[k]);
        out.face_offsets.push_back(static_cast<std::uint32_t>(out.face_indices.size() - 3));
      } else {
        out.face_indices.insert(out.face_indices.end(), face.begin(), face.end());
      }
      out.face_offsets.push_back(static_cast<std::uint32_t>(out.face_indices.size()));
    }
    sculpt_mesh_ = std::move(out);
    ASSERT_TRUE(WriteObj(sculpt_, sculpt_mesh_).ok());
  }

  std::int64_t SurfaceFaces(const ExtractReport& r) const {
    return static_cast<std::int64_t>(r.inputs.ptex_faces - r.inputs.hole_faces);
  }

  TempDir dir_;
  std::string base_, sculpt_;
  Mesh cage_, sculpt_mesh_;
  double tolerance_ = 0;  // automatic
  int step_ = 0;
  std::int64_t redone_ = 0;  // faces_copied_redone over the steps
};

TEST_P(Incremental, EveryStepEqualsAFullExtraction) {
  ExtractReport first = Step("first run, no map yet");
  EXPECT_EQ(first.incremental.faces_copied, 0);
  EXPECT_EQ(first.incremental.redo_reason, "no previous map");

  // Nothing changed: the map is not rewritten.
  const auto before = std::filesystem::last_write_time(dir_ / "inc.ptx");
  ExtractReport same = Step("unchanged inputs");
  EXPECT_TRUE(same.incremental.unchanged);
  EXPECT_EQ(std::filesystem::last_write_time(dir_ / "inc.ptx"), before);

  const double diagonal = first.inputs.base_diagonal;
  for (unsigned seed : {1u, 2u, 3u}) {
    EditSculptInBall(seed, GetParam().edit_radius * diagonal, 0.002);
    ExtractReport r = Step("sculpt edited in a ball, seed " + std::to_string(seed));
    EXPECT_FALSE(r.incremental.unchanged);
    EXPECT_GT(r.incremental.faces_copied, 0) << "a local edit re-extracted every face";
    EXPECT_GT(r.incremental.faces_extracted, 0);
    if (GetParam().local_tracer) {
      EXPECT_NE(r.tracer.find(" sculpt faces"), std::string::npos) << r.tracer;
    }
    if (GetParam().local_tracer && GetParam().auto_search_distance) {
      EXPECT_GT(r.incremental.search_rays_recast, 0);
      EXPECT_LT(r.incremental.search_rays_recast, r.incremental.search_rays / 4)
          << "the search distance's rays near a local edit are cast again, not all";
    }
    // The sculpt's faces did not change: its match, or else its adjacency, comes from the
    // cache (the ray path does not match the sculpt).
    EXPECT_EQ(r.method.adjacency_cached || r.method.labelling_cached,
              r.method.used != ExtractMethod::kRays);
    if (GetParam().uv_maps) {  // half tiles are extracted whole (uv_maps.h)
      EXPECT_EQ(r.uv.faces_copied > 0, GetParam().data_type == PtexDataType::kFloat)
          << r.uv.faces_copied << " faces' UV texels copied";
    }
    EXPECT_EQ(r.incremental.redo_reason, "sculpt");
    // Interpolated, the faces away from the edit take the sculpt keys the run before kept
    // (field_keys.h); a stale one would fail the comparison.
    if (r.method.used == ExtractMethod::kInterpolate) {
      EXPECT_GT(r.incremental.fields_kept, 0);
      EXPECT_LT(r.incremental.fields_kept, static_cast<std::int64_t>(r.inputs.ptex_faces));
      std::printf("%s: %lld of %zu faces' sculpt keys kept\n", GetParam().name,
                  static_cast<long long>(r.incremental.fields_kept), r.inputs.ptex_faces);
    }
    // The edges away from the edit keep the steps the map recorded instead of being measured
    // again (a stale one, near a face that changed, would fail the comparison).
    if (GetParam().watertight != WatertightEdges::kOff) {
      EXPECT_GT(r.incremental.edges_copied, r.edges.shared / 2);
      std::printf("%s: %lld of %lld edges copied\n", GetParam().name,
                  static_cast<long long>(r.incremental.edges_copied),
                  static_cast<long long>(r.edges.shared));
    }
  }

  // A bump beyond the search distance, within the retry's: the faces under it miss the first
  // search, so a tracer of its reach alone is widened to the retry's for them.
  if (GetParam().local_tracer && GetParam().auto_search_distance) {
    EditSculptInBall(6, 0.01 * diagonal, 3 * first.settings.search_distance);
    ExtractReport bumped = Step("a bump beyond the search distance");
    EXPECT_GT(bumped.sampling.misses_recovered, 0);
    EXPECT_NE(bumped.tracer.find("retry distance's reach"), std::string::npos) << bumped.tracer;
  }

  // Triangles: the sculpt is no longer the base subdivided, so where the oversampling rule
  // then plans other sample counts the faces are extracted again (a vector map needs the
  // sculpt to be the base refined).
  if (!GetParam().vector) {
    RemeshSculptLocally(4, 0.04 * diagonal);
    ExtractReport remeshed = Step("sculpt re-meshed locally");
    EXPECT_GT(remeshed.incremental.faces_extracted, 0);
  }

  // A base vertex moved: the faces around it change (their limit patches), not the others.
  cage_.positions[cage_.num_vertices() / 2].x += static_cast<float>(0.002 * diagonal);
  WriteBase();
  ExtractReport moved = Step("base vertex moved");
  EXPECT_GT(moved.incremental.faces_copied, SurfaceFaces(moved) / 2);
  EXPECT_LT(moved.incremental.faces_extracted, SurfaceFaces(moved) / 2);
  EXPECT_GT(moved.incremental.faces_extracted, 0);
  EXPECT_EQ(moved.incremental.redo_reason, "base");

  // A crease on one edge of the base.
  const auto face = cage_.face(0);
  WriteBase(fmt::format("t crease 2/1/0 {} {} 2.5\n", face[0], face[1]));
  ExtractReport creased = Step("crease added");
  EXPECT_GT(creased.incremental.faces_extracted, 0);
  if (!GetParam().auto_search_distance) {
    EXPECT_GT(creased.incremental.faces_copied, SurfaceFaces(creased) / 2);
  }

  // A map damaged since (a byte of its face data flipped): not re-used, with a warning.
  {
    std::fstream map(dir_ / "inc.ptx", std::ios::in | std::ios::out | std::ios::binary);
    map.seekg(0, std::ios::end);
    const std::streamoff at = map.tellg() / 3;
    map.seekg(at);
    const char byte = static_cast<char>(map.get() ^ 0x5a);
    map.seekp(at);
    map.put(byte);
  }
  // An option every face depends on: nothing can be copied.
  tolerance_ = 0.9 * first.settings.tolerance;
  ExtractReport retuned = Step("tolerance changed");
  EXPECT_EQ(retuned.incremental.faces_copied, 0);
  EXPECT_TRUE(
      std::any_of(retuned.warnings.begin(), retuned.warnings.end(),
                  [](const std::string& w) { return w.find("corrupt face data") != w.npos; }))
      << fmt::format("{}", fmt::join(retuned.warnings, "\n"));
  EXPECT_NE(retuned.incremental.redo_reason.find("corrupt face data"), std::string::npos);

  // With the new option in the map, local edits are incremental again.
  // A larger bump that moves the sculpt's outermost points (which the tracer's scale once
  // followed: docs/INCREMENTAL.md).
  EditSculptInBall(5, 0.04 * diagonal, 0.006 * diagonal);
  Step("larger sculpt edit after the option change");
  std::printf("%s: %lld copied faces extracted again for their edges over the steps\n",
              GetParam().name, static_cast<long long>(redone_));
}

INSTANTIATE_TEST_SUITE_P(
    Cages, Incremental,
    ::testing::Values(Variant{"spot_float_filter_uv", "keenan_spot/spot_control_mesh.obj", 3,
                              PtexDataType::kFloat, WatertightEdges::kFilter, false, false, 0.04,
                              std::nullopt, true},
                      Variant{"spot_half_all_uv", "keenan_spot/spot_control_mesh.obj", 3,
                              PtexDataType::kHalf, WatertightEdges::kAll, false, false, 0.04,
                              std::nullopt, true},
                      Variant{"spot2928_local_tracer_uv", "keenan_spot/spot_quadrangulated.obj", 2,
                              PtexDataType::kFloat, WatertightEdges::kFilter, false, true, 0.01,
                              std::nullopt, true},
                      // Rays with the automatic search distance: each re-run updates the
                      // estimate from the rays the run before kept (ray_cache.h), with no BVH
                      // of the whole sculpt.
                      Variant{"spot2928_rays_auto_distance", "keenan_spot/spot_quadrangulated.obj",
                              2, PtexDataType::kFloat, WatertightEdges::kFilter, true, true, 0.01},
                      Variant{"car_ngons_boundary_float_off", "opensubdiv/catmark_car.obj", 3,
                              PtexDataType::kFloat, WatertightEdges::kOff, true},
                      Variant{"spot_vector_tangent", "keenan_spot/spot_control_mesh.obj", 3,
                              PtexDataType::kFloat, WatertightEdges::kFilter, true, false, 0.04,
                              VectorSpace::kTangent},
                      Variant{"car_ngons_vector_object_half_all", "opensubdiv/catmark_car.obj", 3,
                              PtexDataType::kHalf, WatertightEdges::kAll, true, false, 0.04,
                              VectorSpace::kObject}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

// A sculpt face of more than 8 corners (its corners are gathered in storage of their own, not
// the fixed array of up to 8) is keyed by all of them: moving its 11th corner re-extracts the
// faces that can reach it, and the map equals a full extraction. Keying only its first 8 corners
// copies stale faces and fails the comparison. The search distance is given, so that the edit
// cannot re-extract every face by moving the automatic one.
TEST(IncrementalMaps, ASculptFaceOfManyCornersIsKeyedByEveryCorner) {
  TempDir dir;
  const std::string base = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string refined = dir / "refined.obj", sculpt_path = dir / "sculpt.obj";
  ASSERT_TRUE(MakeSculpt(testing::SculptOptions(base, refined, 2, Pattern::kDetail, 0.005)).ok());
  auto read = ReadMesh(refined);
  ASSERT_TRUE(read.ok()) << read.status().message();
  Mesh sculpt = std::move(*read);
  // Quad (a, b, c, d) becomes the 12-gon a, 7 points on edge ab, b, c, m, d, with m the middle
  // of edge cd: the same surface, fanned from a into (a, b, c), (a, c, m), (a, m, d) and
  // triangles of no area along ab. Its neighbours keep their edges whole (T-junctions, which
  // rays do not mind), so m is its own.
  const std::size_t quad = sculpt.num_faces() / 3;
  const auto q = sculpt.face(quad);
  ASSERT_EQ(q.size(), 4u);
  auto at = [&](std::int32_t v) { return sculpt.positions[static_cast<std::size_t>(v)]; };
  auto add = [&](const Float3& p, const Float3& r, float t) {
    sculpt.positions.push_back(
        {p.x + t * (r.x - p.x), p.y + t * (r.y - p.y), p.z + t * (r.z - p.z)});
    return static_cast<std::int32_t>(sculpt.positions.size() - 1);
  };
  std::vector<std::int32_t> ring = {q[0]};
  for (int k = 1; k <= 7; ++k) ring.push_back(add(at(q[0]), at(q[1]), k / 8.0f));
  ring.push_back(q[1]);
  ring.push_back(q[2]);
  const std::int32_t m = add(at(q[2]), at(q[3]), 0.5f);
  ring.push_back(m);
  ring.push_back(q[3]);
  Mesh edited;
  edited.positions = sculpt.positions;
  edited.face_offsets = {0};
  for (std::size_t f = 0; f < sculpt.num_faces(); ++f) {
    const auto face = f == quad ? std::span<const std::int32_t>(ring) : sculpt.face(f);
    edited.face_indices.insert(edited.face_indices.end(), face.begin(), face.end());
    edited.face_offsets.push_back(static_cast<std::uint32_t>(edited.face_indices.size()));
  }
  ASSERT_TRUE(WriteObj(sculpt_path, edited).ok());

  ExtractOptions o;
  o.base_path = base;
  o.sculpt_path = sculpt_path;
  o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
  o.output_path = dir / "inc.ptx";
  o.incremental = true;
  auto first = Extract(o);
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->method.used, ExtractMethod::kRays);  // the sculpt is no longer the base refined

  // m moves half the search distance along the quad's normal.
  const Float3 a = at(q[0]), b = at(q[1]), c = at(q[2]), d = at(q[3]);
  const Float3 u{c.x - a.x, c.y - a.y, c.z - a.z}, v{d.x - b.x, d.y - b.y, d.z - b.z};
  const Float3 n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
  const double scale = 0.005 * first->inputs.base_diagonal / std::hypot(n.x, n.y, n.z);
  Float3& p = edited.positions[static_cast<std::size_t>(m)];
  p = {static_cast<float>(p.x + scale * n.x), static_cast<float>(p.y + scale * n.y),
       static_cast<float>(p.z + scale * n.z)};
  ASSERT_TRUE(WriteObj(sculpt_path, edited).ok());
  const std::string before = Slurp(o.output_path);
  auto again = Extract(o);
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_FALSE(again->incremental.unchanged);
  EXPECT_GT(again->incremental.faces_extracted, 0);
  EXPECT_GT(again->incremental.faces_copied, 0) << "moving one vertex re-extracted every face";

  ExtractOptions full = o;
  full.incremental = false;
  full.output_path = dir / "full.ptx";
  ASSERT_TRUE(Extract(full).ok());
  EXPECT_TRUE(Slurp(o.output_path) == Slurp(full.output_path))
      << "the incremental map differs from a full extraction ("
      << again->incremental.faces_extracted
      << " faces extracted): " << testing::MapDifference(o.output_path, full.output_path);
  // The edit shows in the map: a map left as it was would fail the comparison.
  const std::string old_map = dir / "before.ptx";
  { std::ofstream(old_map, std::ios::binary) << before; }
  EXPECT_NE(testing::MapDifference(old_map, full.output_path, /*faces_only=*/true), "");
}

// Options extracting a sculpt made from Spot's cage (2 levels of `pattern`, in `dir`) to `output`.
ExtractOptions SpotSculptOptions(const TempDir& dir, Pattern pattern, const std::string& output) {
  ExtractOptions o;
  o.base_path = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  o.sculpt_path = dir / "sculpt.obj";
  o.output_path = output;
  const auto made =
      MakeSculpt(testing::SculptOptions(o.base_path, o.sculpt_path, 2, pattern, 0.005));
  EXPECT_TRUE(made.ok()) << made.status().message();
  return o;
}

// Moves one sculpt vertex, so that the next run is not an unchanged one.
void MoveOneSculptVertex(const std::string& sculpt) {
  auto mesh = ReadMesh(sculpt);
  ASSERT_TRUE(mesh.ok());
  mesh->positions[mesh->num_vertices() / 3].x += 1e-4f;
  ASSERT_TRUE(WriteObj(sculpt, *mesh).ok());
}

// The map at o.output_path is byte for byte a full extraction with the same options.
void ExpectFullExtraction(const ExtractOptions& o, const TempDir& dir, const std::string& what) {
  ExtractOptions full = o;
  full.incremental = false;
  full.output_path = dir / "full.ptx";
  ASSERT_TRUE(Extract(full).ok());
  EXPECT_TRUE(Slurp(o.output_path) == Slurp(full.output_path))
      << what << ": " << testing::MapDifference(o.output_path, full.output_path);
}

// Copied faces go to the new map still encoded only when the map before encoded them the same
// way: after the compression level changed, they are encoded again at the new level (copied
// as they were, the map would differ from a full extraction), and after that, with the level
// kept, they are copied still encoded.
TEST(IncrementalMaps, CopiedFacesAreEncodedAgainWhenTheEncodingChanged) {
  TempDir dir;
  ExtractOptions o = SpotSculptOptions(dir, Pattern::kDetail, dir / "inc.ptx");
  const std::string sculpt = o.sculpt_path;
  o.search_distance = {SearchDistanceSpec::Kind::kRelative, 0.01};
  o.incremental = true;
  o.cache_dir = dir / "cache";
  for (WatertightEdges watertight : {WatertightEdges::kFilter, WatertightEdges::kOff}) {
    o.watertight = watertight;
    o.compression_level = -1;
    ASSERT_TRUE(Extract(o).ok());
    for (int level : {6, 6}) {
      o.compression_level = level;
      MoveOneSculptVertex(sculpt);
      auto r = Extract(o);
      ASSERT_TRUE(r.ok()) << r.status().message();
      EXPECT_GT(r->incremental.faces_copied, r->inputs.ptex_faces / 2);
      ExpectFullExtraction(o, dir,
                           fmt::format("{}, level {}", WatertightEdgesName(watertight), level));
    }
  }
}

// The sculpt keys an incremental run keeps in the cache folder (field_keys.h) are a file on the
// user's disk: one whose homes name a face that is not there (its content hash made to match)
// is not trusted, every face is keyed again, the map is still a full extraction's, and the
// record written then serves the next run. Without the check, the homes index past the faces.
TEST(IncrementalMaps, AFieldRecordNamingNoFaceIsNotTrusted) {
  TempDir dir;
  ExtractOptions o = SpotSculptOptions(dir, Pattern::kDetail, dir / "inc.ptx");
  const std::string sculpt = o.sculpt_path;
  o.incremental = true;
  o.cache_dir = dir / "cache";
  auto first = Extract(o);
  ASSERT_TRUE(first.ok()) << first.status().message();
  ASSERT_EQ(first->method.used, ExtractMethod::kInterpolate);
  EXPECT_EQ(first->incremental.fields_kept, -1);
  std::string record;
  for (const auto& entry : std::filesystem::directory_iterator(o.cache_dir)) {
    if (entry.path().filename().string().rfind("fields-", 0) == 0) record = entry.path();
  }
  ASSERT_FALSE(record.empty());
  // The homes are the record's last array (one int32 per sculpt vertex), before its hash.
  std::string bytes = Slurp(record);
  const std::size_t vertices = first->inputs.sculpt_vertices;
  ASSERT_GT(bytes.size(), sizeof(Hash128) + 4 * vertices);
  const std::size_t homes = bytes.size() - sizeof(Hash128) - 4 * vertices;
  const std::int32_t nowhere = 1 << 30;
  for (std::size_t v = 0; v < vertices; ++v) std::memcpy(&bytes[homes + 4 * v], &nowhere, 4);
  const Hash128 check =
      HashBytes(std::as_bytes(std::span(bytes.data(), bytes.size() - sizeof(Hash128))));
  std::memcpy(&bytes[bytes.size() - sizeof(Hash128)], &check, sizeof(Hash128));
  std::ofstream(record, std::ios::binary) << bytes;

  for (const std::int64_t expect_kept : {std::int64_t{-1}, std::int64_t{1}}) {
    MoveOneSculptVertex(sculpt);
    auto r = Extract(o);
    ASSERT_TRUE(r.ok()) << r.status().message();
    if (expect_kept < 0) {
      EXPECT_EQ(r->incremental.fields_kept, -1) << "the record was trusted";
    } else {
      EXPECT_GT(r->incremental.fields_kept, static_cast<std::int64_t>(r->inputs.ptex_faces / 2));
    }
    ExpectFullExtraction(o, dir, expect_kept < 0 ? "record not trusted" : "record written again");
  }
}

TEST(IncrementalMaps, AMapNotWrittenByDispexIsIgnoredWithANotice) {
  TempDir dir;
  ExtractOptions o = SpotSculptOptions(dir, Pattern::kSmooth, dir / "full.ptx");
  ASSERT_TRUE(Extract(o).ok());
  for (const std::string& junk :
       {std::string("not a ptex file"), Slurp(DataPath("ptex/quad_float1.ptx"))}) {
    o.output_path = dir / "inc.ptx";
    { std::ofstream(o.output_path, std::ios::binary) << junk; }
    o.incremental = true;
    auto r = Extract(o);
    ASSERT_TRUE(r.ok()) << r.status().message();
    EXPECT_EQ(r->incremental.faces_copied, 0);
    ASSERT_FALSE(r->warnings.empty());
    EXPECT_NE(r->warnings.back().find("not re-used"), std::string::npos) << r->warnings.back();
    EXPECT_EQ(Slurp(o.output_path), Slurp(dir / "full.ptx"));
  }
}

}  // namespace
}  // namespace dispex
