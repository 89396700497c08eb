// See uv_maps.h.
#include "extract/uv_maps.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <span>
#include <sstream>

#include "core/check.h"
#include "core/system.h"
#include "dispex/cancel.h"
#include "dispex/uv_charts.h"
#include "dispex/uv_map.h"
#include "dispex/vector_space.h"
#include "dispex/version.h"
#include "extract/face_pipeline.h"
#include "extract/parallel_errors.h"

namespace dispex::extract {

namespace {

namespace fs = std::filesystem;

// The texels of each Ptex face, in tile and texel order: (tile index, texel index) pairs.
struct FaceTexels {
  std::vector<std::size_t> offsets;  // num_faces + 1
  std::vector<std::pair<std::uint32_t, std::uint32_t>> texels;
};

FaceTexels GroupByFace(const UvRaster& raster, int num_faces) {
  FaceTexels out;
  out.offsets.assign(static_cast<std::size_t>(num_faces) + 1, 0);
  for (const UvTile& tile : raster.tiles) {
    for (const UvTexelPlace& p : tile.places) {
      if (p.face >= 0) ++out.offsets[static_cast<std::size_t>(p.face) + 1];
    }
  }
  for (std::size_t f = 1; f < out.offsets.size(); ++f) out.offsets[f] += out.offsets[f - 1];
  out.texels.resize(out.offsets.back());
  std::vector<std::size_t> next(out.offsets.begin(), out.offsets.end() - 1);
  for (std::size_t t = 0; t < raster.tiles.size(); ++t) {
    const auto& places = raster.tiles[t].places;
    for (std::size_t i = 0; i < places.size(); ++i) {
      if (places[i].face < 0) continue;
      out.texels[next[static_cast<std::size_t>(places[i].face)]++] = {
          static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(i)};
    }
  }
  return out;
}

struct UvScratch {
  explicit UvScratch(const LimitSurface& surface) : face(surface) {}
  FaceScratch face;  // its evaluator and the rays' retry buffers
  std::vector<float> uv, positions, normals, t;
  std::vector<std::uint8_t> flags;
};

std::string FaceList(const std::vector<std::int32_t>& faces) {
  std::string out;
  for (std::size_t i = 0; i < faces.size() && i < 10; ++i) {
    out += fmt::format("{}{}", i ? ", " : "", faces[i]);
  }
  if (faces.size() > 10) out += ", ...";
  return out;
}

// "dispex:inputs_key": the map's they were written with; "dispex:uv_missed_faces": the Ptex
// faces whose texels missed the sculpt (dilated), which an incremental run extracts again;
// "dispex:udims": the tiles of the set, so that a missing one is noticed.
constexpr const char* kInputsKeyAttribute = "dispex:inputs_key";
constexpr const char* kMissedFacesAttribute = "dispex:uv_missed_faces";
constexpr const char* kTilesAttribute = "dispex:udims";  // the set's tiles, ascending

std::vector<std::pair<std::string, std::string>> TileAttributes(
    const ExtractOptions& options, const ExtractReport& report,
    const std::vector<std::int64_t>& face_misses) {
  std::vector<std::size_t> missed;
  for (std::size_t f = 0; f < face_misses.size(); ++f) {
    if (face_misses[f] > 0) missed.push_back(f);
  }
  const bool vector = options.vector.has_value();
  std::vector<std::pair<std::string, std::string>> attributes{
      {"dispex:version", DISPEX_VERSION_STRING},
      {"dispex:space", vector ? "object" : "normal"},
      {"dispex:channels",
       vector ? "R, G, B: x, y, z of sculpt - limit surface in the base mesh's object space"
              : "Y: signed distance along the limit surface's unit normal"},
      {"dispex:midpoint", "0"},
      {"dispex:scale", "1"},
      {"dispex:units", "object units of the base mesh"},
      {"dispex:uv_rule",
       "face-varying linear (OpenSubdiv FVAR_LINEAR_ALL; Blender Subdivision Surface UV "
       "Smooth: None); texel (i, j) centred at ((i+0.5)/N, (j+0.5)/N) of its UDIM tile"},
      {"dispex:padding", fmt::format("{}", options.uv_padding)},
      {"dispex:base", report.inputs.base_path},
      {"dispex:sculpt", report.inputs.sculpt_path},
      {"dispex:base_fingerprint", report.inputs.base_fingerprint},
      {"dispex:sculpt_fingerprint", report.inputs.sculpt_fingerprint},
      // The Ptex map's tolerance, which verify's truth bounds scale with (the texels
      // themselves are samples, not fitted to it).
      {"dispex:tolerance", fmt::format("{}", report.settings.tolerance)},
      {kInputsKeyAttribute, report.incremental.inputs_key},
      {kMissedFacesAttribute, fmt::format("{}", fmt::join(missed, " "))},
  };
  // A vector map's samples read the correspondence: no rays, no search distance.
  if (!vector) {
    attributes.emplace_back("dispex:search_distance",
                            fmt::format("{}", report.settings.search_distance));
  }
  return attributes;
}

// The tiles of `shape` in `dir`: its <shape>.NNNN.exr files, by UDIM.
std::map<int, fs::path> ShapeTiles(const std::string& dir, const std::string& shape) {
  std::map<int, fs::path> tiles;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() != shape.size() + 9 || name.compare(0, shape.size() + 1, shape + ".") != 0 ||
        name.compare(name.size() - 4, 4, ".exr") != 0) {
      continue;
    }
    const std::string digits = name.substr(shape.size() + 1, 4);
    if (std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      tiles.emplace(std::stoi(digits), entry.path());
    }
  }
  return tiles;
}

// Tiles of `shape` in `dir` that this run did not write.
void RemoveStaleTiles(const std::string& dir, const std::string& shape,
                      const std::set<std::string>& written, ExtractReport& report) {
  for (const auto& [udim, path] : ShapeTiles(dir, shape)) {
    if (written.count(path.string()) != 0) continue;
    std::error_code remove_error;
    if (fs::remove(path, remove_error)) {
      report.warnings.push_back(fmt::format(
          "{}: removed, a tile of an earlier run that these UVs no longer touch", path.string()));
    }
  }
}

// Scalar maps traced by rays need the whole sculpt's tracer for `faces`: build it unless the
// run's tracer already is that, or holds the sculpt within reach of every one of them.
Status BuildTracerIfNeeded(const ExtractOptions& options, const ExtractSettings& settings,
                           std::span<const int> faces, ExtractInputs& inputs,
                           ExtractReport& report) {
  if (options.vector.has_value() || settings.interpolate || faces.empty() ||
      inputs.sculpt_parts > 1) {  // in parts: each run builds its own (ForEachTracedRun)
    return Status::Ok();
  }
  const bool within_reach =
      !inputs.traced.empty() && std::all_of(faces.begin(), faces.end(), [&](int f) {
        return inputs.traced[static_cast<std::size_t>(f)] != 0;
      });
  if (inputs.mapping != nullptr || inputs.tracer == nullptr ||
      (!inputs.traced.empty() && !within_reach)) {
    DISPEX_RETURN_IF_ERROR(BuildTracer(options, inputs, report));
  }
  return Status::Ok();
}

// The tiles being filled: each tile's values (`channels` a texel) and which texels hold one.
struct UvTileValues {
  UvTileValues(const UvRaster& raster, int channels) {
    const int n = raster.resolution;
    const std::size_t tile_texels = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    values.assign(raster.tiles.size(), std::vector<float>(tile_texels * channels, 0));
    filled.assign(raster.tiles.size(), std::vector<std::uint8_t>(tile_texels, 0));
  }
  std::vector<std::vector<float>> values;
  std::vector<std::vector<std::uint8_t>> filled;
};

// A face's texels: (tile index, texel index) pairs, a slice of FaceTexels::texels.
using TexelSpan = std::span<const std::pair<std::uint32_t, std::uint32_t>>;

// The Ptex faces that hold at least one texel, in face order.
std::vector<int> FacesWithTexels(const FaceTexels& by_face, int num_faces) {
  std::vector<int> faces;
  for (int f = 0; f < num_faces; ++f) {
    if (by_face.offsets[static_cast<std::size_t>(f) + 1] >
        by_face.offsets[static_cast<std::size_t>(f)]) {
      faces.push_back(f);
    }
  }
  return faces;
}

// The texels' (u, v) on their face, interleaved into `uv`.
void GatherTexelUvs(const UvRaster& raster, TexelSpan texels, std::vector<float>& uv) {
  uv.resize(2 * texels.size());
  for (std::size_t k = 0; k < texels.size(); ++k) {
    const auto [tile, texel] = texels[k];
    const UvTexelPlace& p = raster.tiles[tile].places[texel];
    uv[2 * k] = p.u;
    uv[2 * k + 1] = p.v;
  }
}

// Interpolated, no rays: the face's grid of vertex displacements read at each texel.
Status InterpolateTexels(PtexFaceId face, TexelSpan texels, bool vector,
                         const ExtractInputs& inputs, UvScratch& w, UvTileValues& tiles) {
  DISPEX_RETURN_IF_ERROR(w.face.grid.Evaluate(face, *inputs.grids, inputs.sculpt, w.face.evaluator,
                                              /*normals=*/!vector));
  w.face.grid.SetSampling(0);  // UV texels sit at no fixed place against the vertices
  for (std::size_t k = 0; k < texels.size(); ++k) {
    const auto [tile, texel] = texels[k];
    const double u = w.uv[2 * k], v = w.uv[2 * k + 1];
    if (vector) {
      double d[3];
      w.face.grid.DisplacementAt(u, v, d);
      float* out = &tiles.values[tile][3 * static_cast<std::size_t>(texel)];
      for (int a = 0; a < 3; ++a) out[a] = static_cast<float>(d[a]);
    } else {
      tiles.values[tile][texel] = static_cast<float>(w.face.grid.HeightAt(u, v));
    }
    tiles.filled[tile][texel] = 1;
  }
  return Status::Ok();
}

// A vector map, no rays: the sculpt's point through the correspondence less the limit point.
Status ReadVectorTexels(PtexFaceId face, TexelSpan texels,
                        const SculptCorrespondence& correspondence, const ExtractInputs& inputs,
                        UvScratch& w, UvTileValues& tiles) {
  w.positions.resize(3 * texels.size());
  DISPEX_RETURN_IF_ERROR(w.face.evaluator.EvaluatePoints(face, w.uv, w.positions, {}));
  for (std::size_t k = 0; k < texels.size(); ++k) {
    const auto [tile, texel] = texels[k];
    const Float3 sculpt =
        SculptPointAt(correspondence, inputs.sculpt, face, w.uv[2 * k], w.uv[2 * k + 1]);
    float* out = &tiles.values[tile][3 * static_cast<std::size_t>(texel)];
    out[0] = static_cast<float>(double(sculpt.x) - w.positions[3 * k]);
    out[1] = static_cast<float>(double(sculpt.y) - w.positions[3 * k + 1]);
    out[2] = static_cast<float>(double(sculpt.z) - w.positions[3 * k + 2]);
    tiles.filled[tile][texel] = 1;
  }
  return Status::Ok();
}

// A scalar map traced: rays along the limit normal; the texels that miss are counted in
// `misses` and left unfilled (for dilation).
Status TraceTexels(PtexFaceId face, TexelSpan texels, const ExtractSettings& settings,
                   const ExtractInputs& inputs, UvScratch& w, UvTileValues& tiles,
                   std::int64_t& misses) {
  const std::size_t count = texels.size();
  w.positions.resize(3 * count);
  w.normals.resize(3 * count);
  w.t.resize(count);
  w.flags.resize(count);
  DISPEX_RETURN_IF_ERROR(w.face.evaluator.EvaluatePoints(face, w.uv, w.positions, w.normals));
  const std::span<const Float3> origins(reinterpret_cast<const Float3*>(w.positions.data()), count);
  const std::span<const Float3> normals(reinterpret_cast<const Float3*>(w.normals.data()), count);
  TraceRays(*inputs.tracer, settings, origins, normals, w.t, w.flags, w.face);
  for (std::size_t k = 0; k < count; ++k) {
    const auto [tile, texel] = texels[k];
    if (!(w.flags[k] & HitFlags::kHit)) {
      ++misses;
      continue;
    }
    tiles.values[tile][texel] = w.t[k];
    tiles.filled[tile][texel] = 1;
  }
  return Status::Ok();
}

// The texels of `faces`, in parallel over them: interpolated, vector or traced. Counts each
// face's misses in `face_misses` (num_faces long).
Status ExtractTexels(const ExtractSettings& settings, ExtractInputs& inputs,
                     const SculptCorrespondence* correspondence, bool vector,
                     const UvRaster& raster, const FaceTexels& by_face, std::span<const int> faces,
                     UvTileValues& tiles, std::vector<std::int64_t>& face_misses) {
  tbb::enumerable_thread_specific<UvScratch> scratches([&] { return UvScratch(inputs.surface); });
  auto extract = [&](PtexFaceId face, UvScratch& w) {
    const auto f = static_cast<std::size_t>(face.value);
    const std::size_t begin = by_face.offsets[f], count = by_face.offsets[f + 1] - begin;
    const TexelSpan texels = TexelSpan(by_face.texels).subspan(begin, count);
    GatherTexelUvs(raster, texels, w.uv);
    if (settings.interpolate) return InterpolateTexels(face, texels, vector, inputs, w, tiles);
    if (vector) return ReadVectorTexels(face, texels, *correspondence, inputs, w, tiles);
    return TraceTexels(face, texels, settings, inputs, w, tiles, face_misses[f]);
  };
  auto each = [&](std::span<const int> run) {
    return ForEachFace(
        static_cast<int>(run.size()), [&](int k) { return run[static_cast<std::size_t>(k)]; },
        scratches, nullptr, extract);
  };
  if (vector || settings.interpolate) return each(faces);
  DISPEX_RETURN_IF_ERROR(ForEachTracedRun(inputs, faces, each));
  return inputs.tracer ? inputs.tracer->status() : Status::Ok();
}

// The raster's and the misses' part of the report, and their warnings.
void ReportTexels(const ExtractOptions& options, const UvRaster& raster,
                  const std::vector<std::int64_t>& face_misses, ExtractReport& report) {
  for (std::int64_t m : face_misses) report.uv.texels_missed += m;
  report.uv.texels_inside = raster.inside;
  report.uv.overlap_texels = raster.overlap_texels;
  report.uv.overlap_faces = raster.overlap_faces;
  report.uv.faces_outside_udim = raster.faces_outside_udim;
  if (raster.overlap_texels > 0) {
    report.warnings.push_back(fmt::format(
        "{}: {} texel centres of the UV maps lie in more than one UV face (overlapping UVs, "
        "{} faces: {}); each takes the face it lies deepest in",
        options.base_path, raster.overlap_texels, raster.overlap_faces.size(),
        FaceList(raster.overlap_faces)));
  }
  if (!raster.faces_outside_udim.empty()) {
    report.warnings.push_back(fmt::format(
        "{}: {} faces have UVs reaching outside the UDIM tiles (u in [0, 10), v in [0, 99)); "
        "only their part inside the tiles is in the UV maps: {}",
        options.base_path, raster.faces_outside_udim.size(), FaceList(raster.faces_outside_udim)));
  }
  for (const UvTile& tile : raster.tiles) {
    if (tile.inside > 0) continue;
    report.warnings.push_back(fmt::format(
        "{}: UDIM tile {} is not written: the UVs of {} faces reach into it by less than a "
        "texel, no texel centre inside ({})",
        options.base_path, tile.udim, tile.faces.size(), FaceList(tile.faces)));
  }
  if (report.uv.texels_missed > 0) {
    report.warnings.push_back(
        fmt::format("{} of {} UV map texels missed the sculpt and were filled by dilation",
                    report.uv.texels_missed, raster.inside));
  }
}

// Dilates the tiles with a texel centre inside and writes them, all or none, then removes the
// stale tiles of an earlier run. Moves the values out of `tiles`.
Status WriteTiles(const ExtractOptions& options, const UvRaster& raster, int channels,
                  const std::vector<std::int64_t>& face_misses, UvTileValues& tiles,
                  ExtractReport& report) {
  std::error_code ec;
  fs::create_directories(options.uv_maps_dir, ec);
  if (ec) {
    return Status::Error(
        fmt::format("{}: cannot create the directory: {}", options.uv_maps_dir, ec.message()));
  }
  const int n = raster.resolution;
  const std::string shape = fs::path(options.output_path).stem().string();
  auto attributes = TileAttributes(options, report, face_misses);
  std::vector<int> udims;
  for (const UvTile& tile : raster.tiles) {
    if (tile.inside > 0) udims.push_back(tile.udim);
  }
  attributes.emplace_back(kTilesAttribute, fmt::format("{}", fmt::join(udims, " ")));
  std::vector<UvMapTile> out;
  std::vector<std::string> paths;
  for (std::size_t t = 0; t < raster.tiles.size(); ++t) {
    if (CancelRequested()) return Cancelled();
    if (raster.tiles[t].inside == 0) continue;  // nothing of the surface (warned above)
    UvMapTile& tile = out.emplace_back();
    tile.udim = raster.tiles[t].udim;
    tile.resolution = n;
    tile.channels = channels;
    DilateTile(n, channels, options.uv_padding, tiles.values[t], tiles.filled[t]);
    tile.values = std::move(tiles.values[t]);
    tile.attributes = attributes;
    tile.attributes.emplace_back("dispex:udim", fmt::format("{}", tile.udim));
    paths.push_back(UvMapTilePath(options.uv_maps_dir, shape, tile.udim));
  }
  // All the tiles or none: a failure leaves the previous run's set as it was.
  DISPEX_RETURN_IF_ERROR(WriteUvMapTiles(paths, out, options.data_type == PtexDataType::kHalf));
  report.uv.paths = paths;
  const std::set<std::string> written(paths.begin(), paths.end());
  RemoveStaleTiles(options.uv_maps_dir, shape, written, report);
  return Status::Ok();
}

std::string AttributeOf(const UvMapTile& tile, std::string_view name) {
  for (const auto& [key, value] : tile.attributes) {
    if (key == name) return value;
  }
  return {};
}

// The texels the previous tiles give: copied into `tiles` (marked filled) for the faces whose
// key is unchanged and whose texels all hit then, when every tile the raster needs was written
// with the previous map at this resolution. Returns which faces were copied (empty: none).
std::vector<std::uint8_t> CopyPreviousTexels(const ExtractOptions& options, const UvRaster& raster,
                                             int channels, const FaceTexels& by_face,
                                             const UvPrevious& previous, UvTileValues& tiles) {
  const std::string shape = fs::path(options.output_path).stem().string();
  std::vector<std::uint8_t> copied = previous.same_key;
  std::vector<std::vector<float>> before(raster.tiles.size());
  for (std::size_t t = 0; t < raster.tiles.size(); ++t) {
    if (raster.tiles[t].inside == 0) continue;
    StatusOr<UvMapTile> tile =
        ReadUvMapTile(UvMapTilePath(options.uv_maps_dir, shape, raster.tiles[t].udim));
    if (!tile.ok() || tile->resolution != raster.resolution || tile->channels != channels ||
        AttributeOf(*tile, kInputsKeyAttribute) != previous.inputs_key) {
      return {};
    }
    std::istringstream missed(AttributeOf(*tile, kMissedFacesAttribute));
    for (std::size_t f; missed >> f;) {
      if (f < copied.size()) copied[f] = 0;
    }
    before[t] = std::move(tile->values);
  }
  const auto c = static_cast<std::size_t>(channels);
  for (std::size_t f = 0; f < copied.size(); ++f) {
    if (!copied[f]) continue;
    for (std::size_t k = by_face.offsets[f]; k < by_face.offsets[f + 1]; ++k) {
      const auto [tile, texel] = by_face.texels[k];
      std::copy_n(&before[tile][c * texel], c, &tiles.values[tile][c * texel]);
      tiles.filled[tile][texel] = 1;
    }
  }
  return copied;
}

}  // namespace

bool UvTilesCurrent(const ExtractOptions& options, const std::string& inputs_key) {
  const auto tiles = ShapeTiles(options.uv_maps_dir, fs::path(options.output_path).stem().string());
  std::vector<int> udims;
  for (const auto& [udim, path] : tiles) udims.push_back(udim);
  const std::string listed = fmt::format("{}", fmt::join(udims, " "));
  // Headers only: the texels are not read.
  return !tiles.empty() && std::all_of(tiles.begin(), tiles.end(), [&](const auto& tile) {
    const StatusOr<UvMapTile> header = ReadUvMapTileHeader(tile.second.string());
    return header.ok() && header->resolution == options.uv_resolution &&
           AttributeOf(*header, kInputsKeyAttribute) == inputs_key &&
           AttributeOf(*header, kTilesAttribute) == listed &&
           AttributeOf(*header, "dispex:padding") == fmt::format("{}", options.uv_padding);
  });
}

Status WriteUvMaps(const ExtractOptions& options, ExtractInputs& inputs,
                   const ExtractSettings& settings, const UvPrevious* previous,
                   ExtractReport& report) {
  Stopwatch clock;
  const SculptCorrespondence* correspondence = inputs.correspondence.get();
  const bool vector = options.vector.has_value();
  DISPEX_CHECK(!vector || (*options.vector == VectorSpace::kObject && correspondence != nullptr));
  const int channels = vector ? 3 : 1;
  DISPEX_ASSIGN_OR_RETURN(PtexUvCharts charts, PtexUvCharts::Build(inputs.base, inputs.surface));
  DISPEX_ASSIGN_OR_RETURN(UvRaster raster,
                          RasterizeUvCharts(charts, inputs.surface, options.uv_resolution));
  const int num_faces = inputs.surface.num_ptex_faces();
  const FaceTexels by_face = GroupByFace(raster, num_faces);
  UvTileValues tiles(raster, channels);
  // Half tiles hold their texels rounded, and dilation reads them at full precision: those
  // are extracted again.
  const std::vector<std::uint8_t> copied =
      previous != nullptr && options.data_type != PtexDataType::kHalf
          ? CopyPreviousTexels(options, raster, channels, by_face, *previous, tiles)
          : std::vector<std::uint8_t>();
  std::vector<int> faces = FacesWithTexels(by_face, num_faces);
  if (!copied.empty()) {
    report.uv.faces_copied = static_cast<std::int64_t>(
        std::erase_if(faces, [&](int f) { return copied[static_cast<std::size_t>(f)] != 0; }));
  }
  DISPEX_RETURN_IF_ERROR(BuildTracerIfNeeded(options, settings, faces, inputs, report));
  std::vector<std::int64_t> face_misses(static_cast<std::size_t>(num_faces), 0);
  DISPEX_RETURN_IF_ERROR(ExtractTexels(settings, inputs, correspondence, vector, raster, by_face,
                                       faces, tiles, face_misses));
  ReportTexels(options, raster, face_misses, report);
  DISPEX_RETURN_IF_ERROR(WriteTiles(options, raster, channels, face_misses, tiles, report));
  report.times.uv_maps = clock.seconds();
  return Status::Ok();
}

}  // namespace dispex::extract
