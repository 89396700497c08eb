#include "extract/io/extract_meta.h"

#include <fmt/format.h>

#include <filesystem>

#include "dispex/vector_space.h"
#include "extract/incremental/face_records.h"

namespace dispex::extract {

namespace {
std::string FileName(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

}  // namespace

nlohmann::json ExtractStatisticsJson(const ExtractReport& r) {
  nlohmann::json j;
  j["method"] = std::string(ExtractMethodName(r.method));
  j["tolerance"] = r.tolerance;
  j["tolerance_auto"] = r.tolerance_auto;
  j["sculpt_median_edge"] = r.sculpt_median_edge;
  j["search_distance"] = r.search_distance;
  j["search_distance_auto"] = r.search_distance_auto;
  j["base_diagonal"] = r.base_diagonal;
  j["base"] = {{"vertices", r.base_vertices},
               {"faces", r.base_faces},
               {"ptex_faces", r.ptex_faces},
               {"hole_faces", r.hole_faces},
               {"inf_sharp_edges", r.inf_sharp_edges}};
  j["sculpt"] = {{"vertices", r.sculpt_vertices}, {"faces", r.sculpt_faces}};
  nlohmann::json oversample = nlohmann::json::object();
  for (std::size_t k = 0; k < r.oversample_faces.size(); ++k) {
    if (r.oversample_faces[k]) oversample[std::to_string(1 << k)] = r.oversample_faces[k];
  }
  j["oversample_faces"] = oversample;
  j["oversample_rule"] = r.options.oversample > 0              ? "fixed"
                         : r.oversample_subdivision_level >= 0 ? "subdivision level"
                                                               : "sculpt density";
  j["samples"] = r.samples;
  j["rays_cast"] = r.rays_cast;
  j["hits"] = {
      {"positive", r.hits_positive}, {"negative", r.hits_negative}, {"opposed", r.hits_opposed}};
  j["retry_search_distance"] = r.retry_search_distance;
  j["misses_recovered"] = r.misses_recovered;
  j["misses"] = r.misses;
  j["miss_fraction"] = r.miss_fraction;
  j["holes_filled"] = r.holes_filled;
  j["faces_with_misses"] = r.faces_with_misses;
  j["faces_filled_from_neighbours"] = r.faces_filled_from_neighbours;
  j["faces_unreachable"] = r.faces_unreachable;
  j["fallback_normals"] = r.fallback_normals;
  const SpectralTotals& s = r.spectral;
  nlohmann::json resolutions = nlohmann::json::object();
  for (std::size_t k = 0; k < s.ulog2_faces.size(); ++k) {
    if (s.ulog2_faces[k] || s.vlog2_faces[k]) {
      resolutions[std::to_string(1 << k)] = {{"u", s.ulog2_faces[k]}, {"v", s.vlog2_faces[k]}};
    }
  }
  j["texels"] = {{"oversampled", s.texels_before},
                 {"written", s.texels_after},
                 {"written_fraction",
                  s.texels_before ? double(s.texels_after) / double(s.texels_before) : 0.0}};
  j["spectral"] = {{"faces", s.faces},
                   {"constant_faces", s.constant_faces},
                   {"stepped_up_faces", s.stepped_up_faces},
                   {"max_bound", s.max_bound},
                   {"max_measured_error", s.max_measured_error},
                   {"faces_by_resolution", resolutions}};
  j["displacement"] = {
      {"min", r.displacement_min}, {"max", r.displacement_max}, {"rms", r.displacement_rms}};
  j["edges"] = {{"watertight", std::string(WatertightEdgesName(r.watertight))},
                {"rounds", r.edge_rounds},
                {"raised_faces", r.edge_raised_faces},
                {"texels_before", r.texels_before_edges},
                {"shared", r.edges_shared},
                {"sharp", r.edges_sharp},
                {"discontinuous", r.edges_discontinuous},
                {"over", r.edges_over},
                {"step_per_face", r.edge_step_per_face},
                {"step_across_faces", r.edge_step_across_faces},
                {"max_edge_error", s.max_edge_error},
                {"edge_limited_faces", s.edge_limited_faces}};
  if (!r.vector_space.empty()) {
    j["vector"] = {{"space", r.vector_space},
                   {"mapping_levels", r.mapping_levels},
                   {"mapping_max_offset", r.mapping_max_offset},
                   {"mapping_rms_offset", r.mapping_rms_offset},
                   {"length_max", r.vector_length_max},
                   {"tangential_max", r.vector_tangential_max}};
  }
  return j;
}

Hash128 InputsKey(const ExtractReport& report) {
  Hasher h;
  h.Add(std::string_view(report.version)).Add(std::string_view(report.shape));
  h.Add(std::string_view(ExtractOptionsJson(report.options).dump()));
  h.Add(std::string_view(report.base_fingerprint)).Add(std::string_view(report.sculpt_fingerprint));
  h.Add(std::string_view(FileName(report.base_path)));
  h.Add(std::string_view(FileName(report.sculpt_path)));
  return h.Digest();
}

Status AddExtractMetaData(PtexWriter& writer, const Mesh& base, const ExtractReport& report,
                          std::span<const Hash128> face_keys, std::span<const FaceStats> first_pass,
                          std::span<const EdgeMeans> edge_means) {
  DISPEX_RETURN_IF_ERROR(AddMeshMetaData(writer, base));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:version", report.version));
  if (!report.shape.empty()) {
    DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:shape", report.shape));
  }
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:base", FileName(report.base_path)));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:base_fingerprint", report.base_fingerprint));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:sculpt", FileName(report.sculpt_path)));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:sculpt_fingerprint", report.sculpt_fingerprint));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:options", ExtractOptionsJson(report.options).dump()));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:statistics", ExtractStatisticsJson(report).dump()));
  const double tolerance = report.tolerance, distance = report.search_distance;
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:tolerance", std::span(&tolerance, 1)));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:search_distance", std::span(&distance, 1)));
  if (!report.discontinuous_faces.empty()) {
    DISPEX_RETURN_IF_ERROR(writer.AddMetaData(
        "dispex:discontinuous_faces", std::span<const std::int32_t>(report.discontinuous_faces)));
  }
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(kInputsKeyMetaKey, report.inputs_key));
  if (face_keys.empty()) return Status::Ok();  // a map whose faces are not re-used
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(
      kFaceKeysMetaKey, std::span<const std::int8_t>(EncodeFaceKeys(face_keys))));
  const std::optional<VectorSpace> vector = report.options.vector;
  const int channels = vector ? 3 : 1;
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(
      FaceRecordsMetaKey(channels),
      std::span<const std::int8_t>(EncodeFaceRecords(first_pass, edge_means, channels))));
  if (!vector) return Status::Ok();
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData(std::string(kVectorSpaceMetaKey), std::string(VectorSpaceName(*vector))));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(std::string(kVectorChannelsMetaKey),
                                            std::string(VectorSpaceChannels(*vector))));
  return writer.AddMetaData("dispex:frame", std::string(VectorSpaceFrame(*vector)));
}

}  // namespace dispex::extract
