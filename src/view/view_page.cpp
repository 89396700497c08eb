// MakeViewPage: reads the base, the map and what else the page shows, and puts them with the
// embedded page and three.js into one HTML file.
#include <fmt/format.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "core/system.h"
#include "dispex/extract.h"
#include "dispex/files.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/ptex_sampler.h"
#include "dispex/render.h"
#include "dispex/subdiv.h"
#include "dispex/uv_charts.h"
#include "dispex/uv_map.h"
#include "dispex/vector_space.h"
#include "dispex/version.h"
#include "dispex/view.h"
#include "view/decimate.h"
#include "view/embedded_assets.h"
#include "view/map_source.h"
#include "view/page_data.h"
#include "view/surface_grid.h"

namespace dispex {

namespace {

using nlohmann::json;
using view::Base64Of;
using view::MapSource;
using view::ReadMap;

std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

StatusOr<json> ReadJsonFile(const std::string& path, const char* what) {
  DISPEX_RETURN_IF_ERROR(CheckReadableFile(path));
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  json j = json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return Status::Error(StatusCode::kBadInput,
                         fmt::format("{}: not a JSON object (expected {})", path, what))
        .WithPath(path);
  }
  return j;
}

// Per-face misses from the map's first-pass records (dispex:face_records_v1, the records
// `extract --incremental` re-uses): each record begins with the face's samples (int64),
// misses, misses recovered by the longer search, misses filled within the face (int32 each),
// two hit counts (int32) and whether every ray missed (a byte), little-endian. Read only when
// they add up to the map's statistics (samples, misses, holes filled over the faces with a
// surface), so that a map whose records mean something else is not misread.
struct FaceHoles {
  std::vector<std::int32_t> samples, misses, filled;
  std::vector<std::uint8_t> all_missed;
};
std::optional<FaceHoles> ReadFaceHoles(const PtexFile& map, const LimitSurface& surface,
                                       const json& statistics, std::string& note) {
  const PtexMetaItem* item = map.FindMetaData("dispex:face_records_v1");
  if (item == nullptr) {
    note = map.FindMetaData("dispex:vector_face_records_v1") != nullptr
               ? "a vector map reads the sculpt through the correspondence: no rays, no misses"
               : "the map records no per-face misses (dispex:face_records_v1)";
    return std::nullopt;
  }
  const std::size_t faces = static_cast<std::size_t>(map.num_faces());
  const std::vector<std::uint8_t>& bytes = item->bytes;
  if (faces == 0 || bytes.size() % faces != 0 || bytes.size() / faces < 29) {
    note = "the map's per-face records have an unknown layout";
    return std::nullopt;
  }
  const std::size_t size = bytes.size() / faces;
  FaceHoles holes;
  holes.samples.resize(faces), holes.misses.resize(faces), holes.filled.resize(faces);
  holes.all_missed.resize(faces);
  std::int64_t samples = 0, misses = 0, filled = 0;
  for (std::size_t f = 0; f < faces; ++f) {
    const std::uint8_t* r = bytes.data() + f * size;
    std::int64_t s = 0;
    std::int32_t m = 0, fill = 0;
    std::memcpy(&s, r, 8);
    std::memcpy(&m, r + 8, 4);
    std::memcpy(&fill, r + 16, 4);
    holes.samples[f] = static_cast<std::int32_t>(std::clamp<std::int64_t>(s, 0, INT32_MAX));
    holes.misses[f] = m;
    holes.filled[f] = fill;
    holes.all_missed[f] = r[28] != 0;
    if (surface.is_hole(PtexFaceId(static_cast<std::int32_t>(f)))) continue;
    samples += s, misses += m, filled += fill;
  }
  if (!statistics.is_object() || statistics.value("samples", std::int64_t{-1}) != samples ||
      statistics.value("misses", std::int64_t{-1}) != misses ||
      statistics.value("holes_filled", std::int64_t{-1}) != filled) {
    note = "the map's per-face records do not add up to its statistics: not shown";
    return std::nullopt;
  }
  return holes;
}

// Per-face errors from a verify report: every face's (per_face, dispex 0.1 and later), else the
// ten worst faces it lists.
struct FaceErrors {
  std::vector<float> map_to_sculpt, truth;  // object units; NaN where unknown
  std::string note;
};
FaceErrors ReadFaceErrors(const json& report, std::size_t faces) {
  FaceErrors errors;
  auto array = [&](const json& values, std::vector<float>& out) {
    if (!values.is_array() || values.size() != faces) return false;
    out.resize(faces);
    for (std::size_t f = 0; f < faces; ++f) {
      out[f] = values[f].is_number() ? values[f].get<float>() : std::nanf("");
    }
    return true;
  };
  if (report.contains("per_face") && report["per_face"].is_object()) {
    const json& per_face = report["per_face"];
    if (per_face.contains("map_to_sculpt_max"))
      array(per_face["map_to_sculpt_max"], errors.map_to_sculpt);
    if (per_face.contains("truth_max")) array(per_face["truth_max"], errors.truth);
  }
  if (errors.map_to_sculpt.empty() && errors.truth.empty()) {
    if (report.contains("worst_faces") && report["worst_faces"].is_array() &&
        !report["worst_faces"].empty()) {
      errors.map_to_sculpt.assign(faces, std::nanf(""));
      for (const json& w : report["worst_faces"]) {
        const int f = w.value("face", -1);
        if (f >= 0 && std::size_t(f) < faces)
          errors.map_to_sculpt[std::size_t(f)] = w.value("max", 0.0f);
      }
      errors.note =
          "the verify report lists the 10 worst faces only (map to sculpt, largest distance): "
          "the others are grey; a report of dispex verify 0.1 or later has every face";
    } else {
      errors.note =
          "the verify report has no per-face errors (give verify a sculpt or a truth file)";
    }
  }
  return errors;
}

// ---- The atlas ------------------------------------------------------------------------------

StatusOr<Image> UvTilesImage(const UvMap& map) {
  const int side = std::min(256, map.resolution());
  const int gap = 4;
  const auto tiles = static_cast<int>(map.tiles().size());
  double m = 0;
  for (const UvMapTile& tile : map.tiles()) {
    for (float v : tile.values) {
      if (std::isfinite(v)) m = std::max(m, std::fabs(double(v)));
    }
  }
  Image image(tiles * side + (tiles + 1) * gap, side + 2 * gap, {255, 255, 255});
  for (int t = 0; t < tiles; ++t) {
    const UvMapTile& tile = map.tiles()[static_cast<std::size_t>(t)];
    const int n = tile.resolution, channels = tile.channels;
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const int i = std::min(n - 1, x * n / side);
        const int j = std::min(n - 1, (side - 1 - y) * n / side);  // row 0 is v = 0
        const float* v = &tile.values[(std::size_t(j) * n + i) * std::size_t(channels)];
        image.set(gap + t * (side + gap) + x, gap + y,
                  channels == 3 ? AtlasVectorColour(-m, m, v)
                                : AtlasColour(AtlasMode::kSigned, -m, m, v[0]));
      }
    }
  }
  return image;
}

// ---- The page -------------------------------------------------------------------------------

std::string ReplaceOnce(std::string text, std::string_view marker, std::string_view by) {
  const std::size_t at = text.find(marker);
  if (at == std::string::npos) return text;
  return text.replace(at, marker.size(), by);
}

// ---- MakeViewPage's steps -------------------------------------------------------------------

// The page's header: its format, generator, title and the inputs' file names.
json PageHeader(const ViewPageOptions& options) {
  json page;
  page["format"] = 1;
  page["generator"] = fmt::format("dispex {}", Version());
  page["title"] = options.title.empty() ? FileName(options.map_path) : options.title;
  auto name_or_null = [](const std::string& path) {
    return path.empty() ? json() : json(FileName(path));
  };
  page["inputs"] = {{"base", FileName(options.base_path)},
                    {"map", FileName(options.map_path)},
                    {"sculpt", name_or_null(options.sculpt_path)},
                    {"verify", name_or_null(options.verify_report_path)},
                    {"extract_report", name_or_null(options.extract_report_path)}};
  return page;
}

// The reports (verify, extract), read first: a file that is not there stops the run before
// the heavy work; so does a sculpt that cannot be read.
struct Reports {
  std::optional<json> verify, extract;
};
StatusOr<Reports> ReadReports(const ViewPageOptions& options) {
  Reports reports;
  if (!options.verify_report_path.empty()) {
    DISPEX_ASSIGN_OR_RETURN(reports.verify, ReadJsonFile(options.verify_report_path,
                                                         "the report of dispex verify --report"));
  }
  if (!options.extract_report_path.empty()) {
    DISPEX_ASSIGN_OR_RETURN(reports.extract, ReadJsonFile(options.extract_report_path,
                                                          "the report of dispex extract --report"));
  } else if (!options.extract_report_json.empty()) {
    reports.extract = json::parse(options.extract_report_json, nullptr, false);
    if (reports.extract->is_discarded() || !reports.extract->is_object()) {
      return Status::Error(StatusCode::kInvalidArgument, "extract_report_json: not a JSON object");
    }
  }
  if (!options.sculpt_path.empty()) DISPEX_RETURN_IF_ERROR(CheckReadableFile(options.sculpt_path));
  return reports;
}

// The grid's step: an n-gon's sub-faces take half the quads a side of a quad face, so a base
// with n-gons takes even grids only.
int GridStep(const LimitSurface& surface) {
  bool has_ngons = false;
  for (int f = 0; f < surface.num_ptex_faces() && !has_ngons; ++f) {
    has_ngons = surface.num_ptex_faces(surface.base_face(PtexFaceId(f))) != 1;
  }
  return has_ngons ? 2 : 1;
}

// The grid to begin with: the one given, else the finest within the budget.
StatusOr<int> ChooseGrid(const ViewPageOptions& options, const LimitSurface& surface, int step) {
  int grid = options.grid;
  if (grid % step != 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("grid = {}: must be even: {} has n-gons, whose sub-faces "
                                     "take half the quads a side",
                                     grid, options.base_path));
  }
  // The mesh's vertices at a grid: a closed quad mesh of Q quads has about Q of them (the
  // faces' points less those they share).
  auto estimate = [&](int g) {
    std::int64_t points = 0;
    for (std::uint16_t n : view::FaceQuads(surface, g)) {
      if (n > 0) points += std::int64_t(n) * n + 1;
    }
    return points;
  };
  if (grid == 0) {
    grid = step;
    for (int g = 2 * step; g <= options.max_grid; g += step) {
      if (estimate(g) > options.max_vertices) break;
      grid = g;
    }
  }
  return grid;
}

// The displaced surface's mesh at the grid chosen; `report.grid` takes the grid it was built at.
StatusOr<view::SurfaceGrid> BuildSurfaceMesh(const ViewPageOptions& options,
                                             const LimitSurface& surface,
                                             std::span<const PtexFaceInfo> faces,
                                             const view::MapDisplacement& displacement,
                                             ViewPageReport& report) {
  const int step = GridStep(surface);
  DISPEX_ASSIGN_OR_RETURN(int grid, ChooseGrid(options, surface, step));
  view::SurfaceGrid mesh;
  for (;;) {
    DISPEX_ASSIGN_OR_RETURN(
        mesh, view::BuildSurfaceGrid(surface, faces, grid, displacement, options.map_path));
    // An open mesh shares fewer points: one step coarser while over the budget.
    if (options.grid != 0 || std::int64_t(mesh.limit.size()) <= options.max_vertices ||
        grid - step < step) {
      break;
    }
    grid -= step;
  }
  if (std::int64_t(mesh.limit.size()) > options.max_vertices) {
    report.notes.push_back(fmt::format(
        "surface: {} vertices at grid {}, over max_vertices = {}{}", mesh.limit.size(), grid,
        options.max_vertices,
        options.grid != 0 ? " (the grid was given)" : ": the coarsest grid has that many"));
  }
  report.grid = grid;
  return mesh;
}

// The surface on the page: packed positions, quantized displacements and values.
json SurfaceJson(const view::SurfaceGrid& mesh, int grid, const std::string& map_kind) {
  double box[6];
  const auto packed = view::PackPoints(mesh.limit, box);
  std::vector<float> flat(3 * mesh.displacement.size());
  for (std::size_t v = 0; v < mesh.displacement.size(); ++v) {
    flat[3 * v] = mesh.displacement[v].x;
    flat[3 * v + 1] = mesh.displacement[v].y;
    flat[3 * v + 2] = mesh.displacement[v].z;
  }
  double d_scale = 0, v_scale = 0;
  const auto d = view::QuantizeValues(flat, d_scale);
  const auto values = view::QuantizeValues(mesh.value, v_scale);
  return {{"grid", grid},
          {"vertices", mesh.limit.size()},
          {"triangles", mesh.triangles},
          {"shared_points", mesh.shared_points},
          {"quads", Base64Of(mesh.quads)},
          {"position", Base64Of(packed)},
          {"box", std::vector<double>(box, box + 6)},
          {"displacement", Base64Of(d)},
          {"displacement_scale", d_scale},
          {"value", Base64Of(values)},
          {"value_scale", v_scale},
          {"value_name", map_kind.find("vector") != std::string::npos ? "D·N" : "h"},
          {"border", Base64Of(mesh.border)}};
}

// Per face: where it lies on the base, whether it is a hole, and a Ptex map's resolution.
json FaceTableJson(const LimitSurface& surface, const PtexFile* ptex, const UvMap* uv,
                   ViewPageReport& report) {
  const int num_faces = surface.num_ptex_faces();
  std::vector<std::int8_t> ulog2(static_cast<std::size_t>(num_faces), 0),
      vlog2(static_cast<std::size_t>(num_faces), 0);
  std::vector<std::uint8_t> constant(static_cast<std::size_t>(num_faces), 0),
      sub_face(static_cast<std::size_t>(num_faces), 255),
      hole(static_cast<std::size_t>(num_faces), 0);
  std::vector<std::int32_t> base_face(static_cast<std::size_t>(num_faces), 0);
  for (int f = 0; f < num_faces; ++f) {
    const PtexFaceId face(f);
    const auto k = static_cast<std::size_t>(f);
    base_face[k] = surface.base_face(face).value;
    if (surface.num_ptex_faces(surface.base_face(face)) != 1) {
      sub_face[k] = static_cast<std::uint8_t>(surface.sub_face(face));
    }
    hole[k] = surface.is_hole(face);
    if (ptex) {
      ulog2[k] = ptex->face_info(face).ulog2;
      vlog2[k] = ptex->face_info(face).vlog2;
      constant[k] = ptex->BlockInfo(face, 0).encoding == PtexBlockInfo::Encoding::kConstant;
    }
  }
  json faces_json = {{"count", num_faces},
                     {"base_face", Base64Of(base_face)},
                     {"sub_face", Base64Of(sub_face)},
                     {"hole", Base64Of(hole)}};
  if (ptex) {
    faces_json["ulog2"] = Base64Of(ulog2);
    faces_json["vlog2"] = Base64Of(vlog2);
    faces_json["constant"] = Base64Of(constant);
  } else {
    report.notes.push_back(
        fmt::format("resolution: a UV-space map has one resolution, {} texels per tile side; no "
                    "resolution per face",
                    uv->resolution()));
    faces_json["resolution_note"] = report.notes.back();
  }
  return faces_json;
}

// Per face: the samples the extraction missed and filled (a Ptex map's records), or why not.
void AddFaceHoles(const LimitSurface& surface, const MapSource& map, ViewPageReport& report,
                  json& faces_json) {
  std::string holes_note;
  std::optional<FaceHoles> holes;
  if (map.ptex) {
    holes = ReadFaceHoles(*map.ptex, surface, map.statistics, holes_note);
  } else {
    holes_note = "a UV-space map records no misses per face";
  }
  if (holes) {
    report.holes_per_face = true;
    faces_json["samples"] = Base64Of(holes->samples);
    faces_json["misses"] = Base64Of(holes->misses);
    faces_json["filled"] = Base64Of(holes->filled);
    faces_json["all_missed"] = Base64Of(holes->all_missed);
  } else {
    report.notes.push_back("holes: " + holes_note);
    faces_json["holes_note"] = holes_note;
  }
}

// A UV-space map's faces with points no tile holds.
void AddFacesWithoutTile(const MapSource& map, ViewPageReport& report, json& faces_json) {
  std::vector<std::int32_t> without;
  for (std::size_t f = 0; f < map.uv_missing.size(); ++f) {
    if (map.uv_missing[f].load()) without.push_back(static_cast<std::int32_t>(f));
  }
  faces_json["without_tile"] = without;
  if (!without.empty()) {
    report.notes.push_back(fmt::format(
        "uv: {} faces have points whose UVs no tile holds (displaced by 0 there)", without.size()));
  }
}

// Per face: the verify report's errors; its tolerance where the map records none.
Status AddFaceErrors(const ViewPageOptions& options, const json& verify, int num_faces,
                     MapSource& map, ViewPageReport& report, json& faces_json) {
  if (verify.contains("ptex_faces") && verify["ptex_faces"].is_number_integer() &&
      verify["ptex_faces"].get<std::int64_t>() != num_faces) {
    return Status::Error(
               StatusCode::kMismatch,
               fmt::format("{}: a report of a map of {} faces, but {} has {}",
                           options.verify_report_path, verify["ptex_faces"].get<std::int64_t>(),
                           options.map_path, num_faces))
        .WithPath(options.verify_report_path);
  }
  FaceErrors errors = ReadFaceErrors(verify, static_cast<std::size_t>(num_faces));
  if (!errors.map_to_sculpt.empty())
    faces_json["error_map_to_sculpt"] = Base64Of(errors.map_to_sculpt);
  if (!errors.truth.empty()) faces_json["error_truth"] = Base64Of(errors.truth);
  report.verify_per_face = errors.note.empty();
  if (!errors.note.empty()) {
    report.notes.push_back("verify: " + errors.note);
    faces_json["error_note"] = errors.note;
  }
  if (verify.contains("map") && verify["map"].is_object() &&
      verify["map"].value("tolerance", 0.0) > 0 && map.tolerance == 0) {
    map.tolerance = verify["map"].value("tolerance", 0.0);
    map.map_json["tolerance"] = map.tolerance;
  }
  return Status::Ok();
}

// Per face: resolution, where it lies on the base, misses, errors.
StatusOr<json> FacesJson(const ViewPageOptions& options, const LimitSurface& surface,
                         const std::optional<json>& verify, MapSource& map,
                         ViewPageReport& report) {
  json faces_json =
      FaceTableJson(surface, map.ptex ? &*map.ptex : nullptr, map.uv ? &*map.uv : nullptr, report);
  AddFaceHoles(surface, map, report, faces_json);
  if (map.uv) AddFacesWithoutTile(map, report, faces_json);
  if (verify) {
    DISPEX_RETURN_IF_ERROR(
        AddFaceErrors(options, *verify, surface.num_ptex_faces(), map, report, faces_json));
  }
  return faces_json;
}

// The sculpt, decimated (null when there is none or it is left out).
StatusOr<json> SculptJson(const ViewPageOptions& options, ViewPageReport& report) {
  if (options.sculpt_path.empty()) return json();
  if (options.max_sculpt_vertices <= 0) {
    report.notes.push_back("sculpt: max_sculpt_vertices = 0, left out");
    return json();
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh sculpt, ReadMesh(options.sculpt_path));
  report.sculpt_vertices_read = static_cast<std::int64_t>(sculpt.num_vertices());
  report.sculpt_faces_read = static_cast<std::int64_t>(sculpt.num_faces());
  view::DecimatedMesh small = view::DecimateByClustering(sculpt, options.max_sculpt_vertices);
  report.sculpt_vertices = static_cast<std::int64_t>(small.positions.size());
  report.sculpt_triangles = static_cast<std::int64_t>(small.triangles.size() / 3);
  report.sculpt_cell = small.cell;
  double box[6];
  const auto packed = view::PackPoints(small.positions, box);
  std::vector<std::int8_t> normals(3 * small.normals.size());
  for (std::size_t v = 0; v < small.normals.size(); ++v) {
    const float n[3] = {small.normals[v].x, small.normals[v].y, small.normals[v].z};
    for (std::size_t c = 0; c < 3; ++c) {
      normals[3 * v + c] = static_cast<std::int8_t>(std::lround(127.0f * n[c]));
    }
  }
  return json{{"vertices_read", report.sculpt_vertices_read},
              {"faces_read", report.sculpt_faces_read},
              {"vertices", report.sculpt_vertices},
              {"triangles", report.sculpt_triangles},
              {"cell", small.cell},
              {"max_vertices", options.max_sculpt_vertices},
              {"box", std::vector<double>(box, box + 6)},
              {"position", Base64Of(packed)},
              {"normal", Base64Of(normals)},
              {"index", Base64Of(small.triangles)}};
}

// The atlas's image: a Ptex map's faces, or a UV-space map's tiles; an error (the note) where
// it is left out.
StatusOr<Image> AtlasImage(const ViewPageOptions& options, const MapSource& map, int num_faces) {
  // About the atlas's pixels (tiles of 16 to 256 pixels a side and their separators): a PNG
  // seldom holds an atlas in less than a byte per 8 pixels, so a larger one is not drawn.
  double pixels = 0;
  if (map.ptex) {
    for (int f = 0; f < num_faces; ++f) {
      const PtexFaceInfo& info = map.ptex->face_info(PtexFaceId(f));
      pixels +=
          double(std::clamp(info.ures(), 16, 256) + 1) * (std::clamp(info.vres(), 16, 256) + 1);
    }
  }
  if (pixels > 8.0 * double(options.max_atlas_bytes)) {
    return Status::Error(
        fmt::format("about {:.0f} million pixels for {} faces, more than a PNG of "
                    "max_atlas_bytes ({:.1f} MB) "
                    "holds: left out (dispex preview draws it)",
                    pixels / 1e6, num_faces, double(options.max_atlas_bytes) / 1e6));
  }
  if (map.ptex) {
    AtlasOptions atlas_options;
    atlas_options.mode = DefaultAtlasMode(*map.ptex);
    atlas_options.labels = num_faces <= 1024;
    AtlasLayout layout;
    return RenderAtlas(*map.ptex, atlas_options, &layout);
  }
  return UvTilesImage(*map.uv);
}

// The atlas as a PNG data URL (null when left out, with a note).
StatusOr<json> AtlasJson(const ViewPageOptions& options, const MapSource& map, int num_faces,
                         ViewPageReport& report) {
  json atlas = json();
  if (options.max_atlas_bytes <= 0) return atlas;
  StatusOr<Image> image = AtlasImage(options, map, num_faces);
  if (!image.ok()) {
    report.notes.push_back("atlas: " + image.status().message());
    return atlas;
  }
  DISPEX_ASSIGN_OR_RETURN(std::vector<std::uint8_t> png, EncodePng(*image));
  if (static_cast<std::int64_t>(png.size()) <= options.max_atlas_bytes) {
    atlas = "data:image/png;base64," + view::Base64(png);
    report.atlas = true;
    report.atlas_bytes = static_cast<std::int64_t>(atlas.get_ref<const std::string&>().size());
  } else {
    report.notes.push_back(fmt::format(
        "atlas: its PNG ({:.1f} MB, {}x{}) is over max_atlas_bytes ({:.1f} MB): left out",
        double(png.size()) / 1e6, image->width, image->height,
        double(options.max_atlas_bytes) / 1e6));
  }
  return atlas;
}

// The page's parts, each a JSON value.
struct PageParts {
  json surface, faces, sculpt, atlas;
};

// The page's data: the header with every part, the notes and warnings so far; the parts'
// sizes go to the report.
void AddPageData(const ViewPageOptions& options, const MapSource& map, const Reports& reports,
                 const PageParts& parts, ViewPageReport& report, json& page) {
  // The verify report as it is, less the per-face arrays the faces already hold.
  json verify_json = json();
  if (reports.verify) {
    verify_json = *reports.verify;
    verify_json.erase("per_face");
  }
  page["map"] = map.map_json;
  page["lod"] = {{"grid", report.grid},
                 {"max_vertices", options.max_vertices},
                 {"max_grid", options.max_grid},
                 {"grid_given", options.grid != 0}};
  page["surface"] = parts.surface;
  page["faces"] = parts.faces;
  page["sculpt"] = parts.sculpt;
  page["verify"] = verify_json;
  page["extract_report"] = reports.extract ? *reports.extract : json();
  page["atlas"] = parts.atlas;
  page["notes"] = report.notes;
  page["warnings"] = report.warnings;
  report.surface_bytes = static_cast<std::int64_t>(parts.surface.dump().size());
  report.sculpt_bytes =
      parts.sculpt.is_null() ? 0 : static_cast<std::int64_t>(parts.sculpt.dump().size());
}

// The HTML file: the embedded page with the title, the data, three.js and the viewer in it.
std::string AssembleHtml(const json& page, ViewPageReport& report) {
  const std::string data =
      view::ScriptSafeJson(page.dump(-1, ' ', false, json::error_handler_t::replace));
  const std::string_view three = view::EmbeddedAsset(view::Asset::kThreeJs);
  report.three_js_bytes = static_cast<std::int64_t>(three.size());
  std::string html(view::EmbeddedAsset(view::Asset::kPageHtml));
  html = ReplaceOnce(std::move(html), "@TITLE@",
                     view::EscapeHtml(page["title"].get<std::string>() + " - dispex view"));
  html = ReplaceOnce(std::move(html), "@CSS@", view::EmbeddedAsset(view::Asset::kViewerCss));
  html = ReplaceOnce(std::move(html), "@DATA@", data);
  html = ReplaceOnce(std::move(html), "@THREE@", three);
  html = ReplaceOnce(std::move(html), "@ORBIT_CONTROLS@",
                     view::EmbeddedAsset(view::Asset::kOrbitControlsJs));
  html = ReplaceOnce(std::move(html), "@VIEWER@", view::EmbeddedAsset(view::Asset::kViewerJs));
  report.page_bytes = static_cast<std::int64_t>(html.size());
  return html;
}

}  // namespace

Status ValidateViewPageOptions(const ViewPageOptions& o) {
  if (o.base_path.empty()) return Status::Error(StatusCode::kInvalidArgument, "base_path: empty");
  if (o.map_path.empty()) return Status::Error(StatusCode::kInvalidArgument, "map_path: empty");
  if (o.max_vertices < 1000 || o.max_vertices > 50'000'000) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("max_vertices = {}: must be 1000..50000000", o.max_vertices));
  }
  if (o.max_sculpt_vertices < 0 || o.max_sculpt_vertices > 10'000'000) {
    return Status::Error(
        StatusCode::kInvalidArgument,
        fmt::format("max_sculpt_vertices = {}: must be 0..10000000", o.max_sculpt_vertices));
  }
  if (o.grid < 0 || o.grid > 256) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("grid = {}: must be 0 (automatic) or 1..256", o.grid));
  }
  if (o.max_grid < 1 || o.max_grid > 256) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("max_grid = {}: must be 1..256", o.max_grid));
  }
  if (o.max_atlas_bytes < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("max_atlas_bytes = {}: must be 0 or more", o.max_atlas_bytes));
  }
  if (o.threads < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         fmt::format("threads = {}: must be 0 or more", o.threads));
  }
  return Status::Ok();
}

StatusOr<std::string> MakeViewPage(const ViewPageOptions& options, ViewPageReport* report_out) {
  DISPEX_RETURN_IF_ERROR(ValidateViewPageOptions(options));
  Stopwatch clock, phase;
  ViewPageReport report;
  auto phase_done = [&](const char* name) {
    report.phase_seconds.emplace_back(name, phase.seconds());
    phase.Reset();
  };
  std::optional<tbb::global_control> limit;
  if (options.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(options.threads));
  }
  json page = PageHeader(options);

  // The inputs: the reports, the base and its limit surface, the map.
  DISPEX_ASSIGN_OR_RETURN(Reports reports, ReadReports(options));
  DISPEX_ASSIGN_OR_RETURN(Mesh base, ReadMesh(options.base_path));
  report.warnings = IgnoredTagWarnings(base);
  DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(base));
  const int num_faces = surface.num_ptex_faces();
  report.ptex_faces = num_faces;
  std::vector<PtexFaceInfo> faces = PtexFaceTable(surface);
  phase_done("base");
  MapSource map;
  DISPEX_RETURN_IF_ERROR(ReadMap(options, base, surface, faces, report, map));
  phase_done("map");

  // The surface grid.
  PageParts parts;
  DISPEX_ASSIGN_OR_RETURN(view::SurfaceGrid mesh,
                          BuildSurfaceMesh(options, surface, faces, *map.displacement, report));
  phase_done("surface");
  report.surface_vertices = static_cast<std::int64_t>(mesh.limit.size());
  report.surface_triangles = mesh.triangles;
  parts.surface = SurfaceJson(mesh, report.grid, report.map_kind);

  // The per-face values, the sculpt, the atlas.
  DISPEX_ASSIGN_OR_RETURN(parts.faces, FacesJson(options, surface, reports.verify, map, report));
  DISPEX_ASSIGN_OR_RETURN(parts.sculpt, SculptJson(options, report));
  phase_done("sculpt");
  DISPEX_ASSIGN_OR_RETURN(parts.atlas, AtlasJson(options, map, num_faces, report));
  phase_done("atlas");

  // The page data, the page, the report.
  AddPageData(options, map, reports, parts, report, page);
  std::string html = AssembleHtml(page, report);
  phase_done("page");
  report.seconds = clock.seconds();
  if (report_out != nullptr) *report_out = std::move(report);
  return html;
}

StatusOr<ViewPageReport> WriteViewPage(const ViewPageOptions& options,
                                       const std::string& output_path) {
  DISPEX_RETURN_IF_ERROR(CheckOutputFile(output_path).WithPath(output_path));
  ViewPageReport report;
  DISPEX_ASSIGN_OR_RETURN(std::string html, MakeViewPage(options, &report));
  DISPEX_RETURN_IF_ERROR(WriteFileAtomically(output_path, html.data(), html.size()));
  return report;
}

std::string ViewPageReportJson(const ViewPageReport& r) {
  json j;
  j["map_kind"] = r.map_kind;
  if (!r.vector_space.empty()) j["vector_space"] = r.vector_space;
  j["ptex_faces"] = r.ptex_faces;
  j["grid"] = r.grid;
  j["surface"] = {{"vertices", r.surface_vertices}, {"triangles", r.surface_triangles}};
  j["sculpt"] = {{"vertices_read", r.sculpt_vertices_read},
                 {"faces_read", r.sculpt_faces_read},
                 {"vertices", r.sculpt_vertices},
                 {"triangles", r.sculpt_triangles},
                 {"cell", r.sculpt_cell}};
  j["atlas"] = r.atlas;
  j["verify_per_face"] = r.verify_per_face;
  j["holes_per_face"] = r.holes_per_face;
  j["bytes"] = {{"page", r.page_bytes},
                {"three_js", r.three_js_bytes},
                {"surface", r.surface_bytes},
                {"sculpt", r.sculpt_bytes},
                {"atlas", r.atlas_bytes}};
  j["notes"] = r.notes;
  j["warnings"] = r.warnings;
  j["seconds"] = r.seconds;
  json phases = json::object();
  for (const auto& [name, seconds] : r.phase_seconds) phases[name] = seconds;
  j["phases_seconds"] = phases;
  return j.dump(2) + "\n";
}

}  // namespace dispex
