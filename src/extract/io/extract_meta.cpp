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
  j["method"] = std::string(ExtractMethodName(r.method.used));
  j["tolerance"] = r.settings.tolerance;
  j["tolerance_auto"] = r.settings.tolerance_auto;
  j["sculpt_median_edge"] = r.inputs.sculpt_median_edge;
  j["search_distance"] = r.settings.search_distance;
  j["search_distance_auto"] = r.settings.search_distance_auto;
  j["base_diagonal"] = r.inputs.base_diagonal;
  j["base"] = {{"vertices", r.inputs.base_vertices},
               {"faces", r.inputs.base_faces},
               {"ptex_faces", r.inputs.ptex_faces},
               {"hole_faces", r.inputs.hole_faces},
               {"inf_sharp_edges", r.inputs.inf_sharp_edges}};
  j["sculpt"] = {{"vertices", r.inputs.sculpt_vertices}, {"faces", r.inputs.sculpt_faces}};
  nlohmann::json oversample = nlohmann::json::object();
  for (std::size_t k = 0; k < r.sampling.oversample_faces.size(); ++k) {
    if (r.sampling.oversample_faces[k])
      oversample[std::to_string(1 << k)] = r.sampling.oversample_faces[k];
  }
  j["oversample_faces"] = oversample;
  j["oversample_rule"] = r.options.oversample > 0                       ? "fixed"
                         : r.sampling.oversample_subdivision_level >= 0 ? "subdivision level"
                                                                        : "sculpt density";
  j["samples"] = r.sampling.samples;
  j["rays_cast"] = r.sampling.rays_cast;
  j["hits"] = {{"positive", r.sampling.hits_positive},
               {"negative", r.sampling.hits_negative},
               {"opposed", r.sampling.hits_opposed}};
  j["retry_search_distance"] = r.sampling.retry_search_distance;
  j["misses_recovered"] = r.sampling.misses_recovered;
  j["misses"] = r.sampling.misses;
  j["miss_fraction"] = r.sampling.miss_fraction;
  j["holes_filled"] = r.sampling.holes_filled;
  j["faces_with_misses"] = r.sampling.faces_with_misses;
  j["faces_filled_from_neighbours"] = r.sampling.faces_filled_from_neighbours;
  j["faces_unreachable"] = r.sampling.faces_unreachable;
  j["fallback_normals"] = r.sampling.fallback_normals;
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
      {"min", r.displacement.min}, {"max", r.displacement.max}, {"rms", r.displacement.rms}};
  j["edges"] = {{"watertight", std::string(WatertightEdgesName(r.edges.rule))},
                {"rounds", r.edges.rounds},
                {"raised_faces", r.edges.raised_faces},
                {"texels_before", r.edges.texels_before},
                {"shared", r.edges.shared},
                {"sharp", r.edges.sharp},
                {"discontinuous", r.edges.discontinuous},
                {"over", r.edges.over},
                {"step_per_face", r.edges.step_per_face},
                {"step_across_faces", r.edges.step_across_faces},
                {"max_edge_error", s.max_edge_error},
                {"edge_limited_faces", s.edge_limited_faces}};
  if (!r.displacement.vector_space.empty()) {
    j["vector"] = {{"space", r.displacement.vector_space},
                   {"mapping_levels", r.method.levels},
                   {"mapping_max_offset", r.method.max_offset},
                   {"mapping_rms_offset", r.method.rms_offset},
                   {"length_max", r.displacement.length_max},
                   {"tangential_max", r.displacement.tangential_max}};
  }
  return j;
}

Hash128 InputsKey(const ExtractReport& report) {
  Hasher h;
  h.Add(std::string_view(report.version)).Add(std::string_view(report.shape));
  h.Add(std::string_view(ExtractOptionsJson(report.options).dump()));
  h.Add(std::string_view(report.inputs.base_fingerprint))
      .Add(std::string_view(report.inputs.sculpt_fingerprint));
  h.Add(std::string_view(FileName(report.inputs.base_path)));
  h.Add(std::string_view(FileName(report.inputs.sculpt_path)));
  return h.Digest();
}

Status AddExtractMetaData(PtexWriter& writer, const Mesh& base, const ExtractReport& report,
                          std::span<const Hash128> face_keys, std::span<const FaceStats> first_pass,
                          std::span<const EdgeMeans> edge_means,
                          std::span<const double> first_round_edge_steps) {
  DISPEX_RETURN_IF_ERROR(AddMeshMetaData(writer, base));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:version", report.version));
  if (!report.shape.empty()) {
    DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:shape", report.shape));
  }
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:base", FileName(report.inputs.base_path)));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:base_fingerprint", report.inputs.base_fingerprint));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:sculpt", FileName(report.inputs.sculpt_path)));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:sculpt_fingerprint", report.inputs.sculpt_fingerprint));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:options", ExtractOptionsJson(report.options).dump()));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData("dispex:statistics", ExtractStatisticsJson(report).dump()));
  const double tolerance = report.settings.tolerance, distance = report.settings.search_distance;
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:tolerance", std::span(&tolerance, 1)));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData("dispex:search_distance", std::span(&distance, 1)));
  if (!report.edges.discontinuous_faces.empty()) {
    DISPEX_RETURN_IF_ERROR(
        writer.AddMetaData("dispex:discontinuous_faces",
                           std::span<const std::int32_t>(report.edges.discontinuous_faces)));
  }
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(kInputsKeyMetaKey, report.incremental.inputs_key));
  if (face_keys.empty()) return Status::Ok();  // a map whose faces are not re-used
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(
      kFaceKeysMetaKey, std::span<const std::int8_t>(EncodeFaceKeys(face_keys))));
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData(kFaceEncodingMetaKey, PtexEncodingName(writer.options())));
  const std::optional<VectorSpace> vector = report.options.vector;
  const int channels = vector ? 3 : 1;
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(
      FaceRecordsMetaKey(channels),
      std::span<const std::int8_t>(EncodeFaceRecords(first_pass, edge_means, channels))));
  if (!first_round_edge_steps.empty()) {
    DISPEX_RETURN_IF_ERROR(writer.AddMetaData(kFirstRoundEdgeStepsMetaKey, first_round_edge_steps));
  }
  if (!vector) return Status::Ok();
  DISPEX_RETURN_IF_ERROR(
      writer.AddMetaData(std::string(kVectorSpaceMetaKey), std::string(VectorSpaceName(*vector))));
  DISPEX_RETURN_IF_ERROR(writer.AddMetaData(std::string(kVectorChannelsMetaKey),
                                            std::string(VectorSpaceChannels(*vector))));
  return writer.AddMetaData("dispex:frame", std::string(VectorSpaceFrame(*vector)));
}

}  // namespace dispex::extract
