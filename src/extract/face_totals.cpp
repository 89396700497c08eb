#include "extract/face_totals.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace dispex::extract {

namespace {

void SumFaces(const ExtractInputs& inputs, const ExtractSettings& settings,
              const ProcessedFaces& faces, ExtractReport& report) {
  double sum_squares = 0;
  bool first = true;
  for (int f = 0; f < inputs.surface.num_ptex_faces(); ++f) {
    const FaceStats& r = faces.stats[static_cast<std::size_t>(f)];
    if (inputs.surface.is_hole(PtexFaceId(f))) continue;
    report.sampling.oversample_faces[settings.plan.log2[static_cast<std::size_t>(f)]]++;
    report.sampling.samples += r.samples;
    report.sampling.misses += r.misses;
    report.sampling.misses_recovered += r.recovered;
    report.sampling.holes_filled += r.filled;
    report.sampling.faces_with_misses += r.misses > 0;
    report.sampling.hits_negative += r.hits_negative;
    // A vector map's samples are read through the correspondence: no rays, no hits.
    if (!settings.vector) report.sampling.hits_positive += r.samples - r.misses - r.hits_negative;
    report.sampling.hits_opposed += r.hits_opposed;
    report.displacement.length_max = std::max(report.displacement.length_max, r.length_max);
    report.displacement.tangential_max =
        std::max(report.displacement.tangential_max, r.tangential_max);
    if (r.all_missed) {
      SpectralFaceStats constant;
      constant.texels_before = r.samples;
      constant.texels_after = 1;
      constant.constant = true;
      report.spectral.Add(constant, 0, 0);
    } else {
      report.spectral.Add(r.spectral, r.ulog2, r.vlog2);
    }
    sum_squares += r.sum_squares;
    report.displacement.min = first ? r.min : std::min<double>(report.displacement.min, r.min);
    report.displacement.max = first ? r.max : std::max<double>(report.displacement.max, r.max);
    first = false;
  }
  report.displacement.rms =
      report.sampling.samples ? std::sqrt(sum_squares / double(report.sampling.samples)) : 0;
  report.sampling.miss_fraction =
      report.sampling.samples ? double(report.sampling.misses) / double(report.sampling.samples)
                              : 0;
}

Status CheckMissFraction(const ExtractOptions& options, const ExtractReport& report) {
  if (!(report.sampling.miss_fraction > options.max_miss_fraction)) return Status::Ok();
  return Status::Error(
      StatusCode::kMismatch,
      fmt::format(
          "{:.1f}% of the samples ({} of {}) found no surface of {} within the search distance "
          "{:.6g} ({}){}, more than max_miss_fraction ({:.4g}%): the sculpt covers only part of {} "
          "or is not aligned with it; align the meshes, give a longer search_distance, or raise "
          "max_miss_fraction",
          100 * report.sampling.miss_fraction, report.sampling.misses, report.sampling.samples,
          options.sculpt_path, report.settings.search_distance,
          options.search_distance.kind == SearchDistanceSpec::Kind::kAuto ? "automatic" : "given",
          report.sampling.retry_search_distance > report.settings.search_distance
              ? fmt::format(" (and {:.6g} on the second search)",
                            report.sampling.retry_search_distance)
              : "",
          100 * options.max_miss_fraction, options.base_path));
}

}  // namespace

Status AddFaceTotals(const ExtractOptions& options, const ExtractInputs& inputs,
                     const ExtractSettings& settings, const ProcessedFaces& faces,
                     ExtractReport& report) {
  SumFaces(inputs, settings, faces, report);
  DISPEX_RETURN_IF_ERROR(CheckMissFraction(options, report));
  // A sculpt that is the base refined is read reversed when it winds the other way
  // (MatchSculpt); any other can only be named.
  const std::int64_t hits = report.sampling.samples - report.sampling.misses;
  if (hits > 0 && 2 * report.sampling.hits_opposed > hits) {
    report.warnings.push_back(fmt::format(
        "{} of {} hits are on sculpt faces facing against the base's normal: {} may wind the "
        "other way from {} (flipped normals), and edges beside those faces are not held; "
        "reverse its faces",
        report.sampling.hits_opposed, hits, options.sculpt_path, options.base_path));
  }
  const WorkerTotals& w = faces.workers;
  report.sampling.rays_cast += w.rays_cast;
  report.times.cpu_limit += w.cpu_limit;
  report.times.cpu_trace += w.cpu_trace;
  report.times.cpu_spectral += w.cpu_spectral;
  report.times.cpu_compress += w.cpu_write;
  report.sampling.fallback_normals += w.fallback_normals;
  return inputs.tracer ? inputs.tracer->status() : Status::Ok();
}

}  // namespace dispex::extract
