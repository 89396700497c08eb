#include <fmt/format.h>

#include "dispex/extract.h"
#include "extract/extract_plan.h"
#include "extract/io/extract_meta.h"

namespace dispex {

namespace extract {

nlohmann::json ExtractReportObject(const ExtractReport& r) {
  nlohmann::json j;
  j["version"] = r.version;
  if (!r.shape.empty()) j["shape"] = r.shape;
  j["inputs"] = {{"base", r.inputs.base_path},
                 {"base_fingerprint", r.inputs.base_fingerprint},
                 {"sculpt", r.inputs.sculpt_path},
                 {"sculpt_fingerprint", r.inputs.sculpt_fingerprint}};
  j["output"] = {{"path", r.output.path}, {"bytes", r.output.bytes}};
  j["inputs_key"] = r.incremental.inputs_key;
  j["plan"] = ExtractPlanJson(r.plan);
  if (r.options.incremental) {
    j["incremental"] = {{"unchanged", r.incremental.unchanged},
                        {"faces_copied", r.incremental.faces_copied},
                        {"faces_extracted", r.incremental.faces_extracted},
                        {"faces_copied_redone", r.incremental.faces_copied_redone},
                        {"edges_copied", r.incremental.edges_copied},
                        {"fields_kept", r.incremental.fields_kept},
                        {"redo_reason", r.incremental.redo_reason},
                        {"tracer_faces", r.incremental.tracer_faces},
                        {"search_rays_recast", r.incremental.search_rays_recast},
                        {"search_rays", r.incremental.search_rays}};
  }
  if (r.options.shard_count > 0) {
    j["shard"] = {{"index", r.options.shard_index},
                  {"count", r.options.shard_count},
                  {"faces", {r.shard.begin, r.shard.end}},
                  {"cost_fraction", r.shard.cost_fraction},
                  {"faces_copied", r.incremental.faces_copied},
                  {"faces_extracted", r.incremental.faces_extracted},
                  {"tracer_faces", r.incremental.tracer_faces}};
  }
  if (r.shard.parts_merged > 0) j["parts_merged"] = r.shard.parts_merged;
  j["options"] = extract::ExtractOptionsJson(r.options);
  j["threads"] = r.settings.threads;
  j["statistics"] = extract::ExtractStatisticsJson(r);
  if (r.settings.search_distance_auto) {
    const SearchDistanceEstimate& e = r.settings.search_estimate;
    j["search_estimate"] = {{"samples", e.samples},
                            {"hits", e.hits},
                            {"ray_length", e.ray_length},
                            {"percentile", e.percentile},
                            {"percentile_abs_t", e.percentile_abs_t},
                            {"median_abs_t", e.median_abs_t},
                            {"max_abs_t", e.max_abs_t},
                            {"floored", e.floored},
                            {"capped", e.capped}};
  }
  j["method"] = {{"used", std::string(ExtractMethodName(r.method.used))},
                 {"levels", r.method.levels},
                 {"max_offset", r.method.max_offset},
                 {"rms_offset", r.method.rms_offset},
                 {"reason", r.method.reason},
                 {"sheet_bound", r.method.sheet_bound},
                 {"fallback_samples", r.method.fallback_samples},
                 {"fallback_faces", r.method.fallback_faces},
                 {"adjacency_cached", r.method.adjacency_cached},
                 {"labelling_cached", r.method.labelling_cached}};
  j["phases_seconds"] = {{"read_base", r.times.read_base},
                         {"read_sculpt", r.times.read_sculpt},
                         {"topology", r.times.topology},
                         {"match", r.times.match},
                         {"bvh", r.times.bvh},
                         {"auto_settings", r.times.search},
                         {"face_keys", r.times.keys},
                         {"sample_trace", r.times.sample_trace},
                         {"write", r.times.write},
                         {"total", r.times.total}};
  j["cpu_seconds"] = {{"limit", r.times.cpu_limit},
                      {"trace", r.times.cpu_trace},
                      {"spectral", r.times.cpu_spectral},
                      {"compress", r.times.cpu_compress}};
  j["mrays_per_second"] =
      r.times.sample_trace > 0 ? double(r.sampling.rays_cast) / r.times.sample_trace / 1e6 : 0.0;
  if (!r.options.uv_maps_dir.empty()) {
    j["uv_maps"] = {{"dir", r.options.uv_maps_dir},
                    {"resolution", r.options.uv_resolution},
                    {"padding", r.options.uv_padding},
                    {"files", r.uv.paths},
                    {"texels_inside", r.uv.texels_inside},
                    {"texels_missed", r.uv.texels_missed},
                    {"overlap_texels", r.uv.overlap_texels},
                    {"overlap_faces", r.uv.overlap_faces},
                    {"faces_outside_udim", r.uv.faces_outside_udim},
                    {"faces_copied", r.uv.faces_copied},
                    {"seconds", r.times.uv_maps}};
  }
  j["peak_rss_bytes"] = r.peak_rss_bytes;
  j["tracer"] = r.tracer;
  j["warnings"] = r.warnings;
  return j;
}

}  // namespace extract

std::string ExtractReportJson(const ExtractReport& r) {
  return extract::ExtractReportObject(r).dump(2) + "\n";
}

std::string AssetReportJson(const AssetReport& r) {
  nlohmann::json j;
  j["version"] = r.version;
  j["output_dir"] = r.output_dir;
  std::int64_t unchanged = 0, copied = 0, extracted = 0;
  std::uint64_t bytes = 0;
  nlohmann::json shapes = nlohmann::json::array();
  for (const AssetReport::Shape& s : r.shapes) {
    nlohmann::json shape = extract::ExtractReportObject(s.report);
    shape["file"] = s.file;
    shapes.push_back(std::move(shape));
    unchanged += s.report.incremental.unchanged;
    copied += s.report.incremental.faces_copied;
    extracted += s.report.incremental.faces_extracted;
    bytes += s.report.output.bytes;
  }
  j["shapes"] = std::move(shapes);
  j["totals"] = {{"shapes", r.shapes.size()},
                 {"unchanged", unchanged},
                 {"faces_copied", copied},
                 {"faces_extracted", extracted},
                 {"bytes_written", bytes}};
  j["phases_seconds"] = {{"read", r.t_read}, {"total", r.t_total}};
  j["peak_rss_bytes"] = r.peak_rss_bytes;
  j["warnings"] = r.warnings;
  return j.dump(2) + "\n";
}

std::string AssetReportSummary(const AssetReport& r) {
  std::string out = fmt::format(
      "dispex: {} shapes -> {}/ (read {:.2f}s, total {:.2f}s, peak {:.0f} MB)\n", r.shapes.size(),
      r.output_dir, r.t_read, r.t_total, double(r.peak_rss_bytes) / 1e6);
  for (const AssetReport::Shape& s : r.shapes) {
    const ExtractReport& e = s.report;
    if (e.incremental.unchanged) {
      out += fmt::format("  {:<20} {} up to date, not rewritten\n", s.name, s.file);
      continue;
    }
    out += fmt::format(
        "  {:<20} {} {} Ptex faces, texels {} -> {}, {:.2f}s{}\n", s.name, s.file,
        e.inputs.ptex_faces, e.spectral.texels_before, e.spectral.texels_after, e.times.total,
        e.options.incremental
            ? fmt::format(" ({} faces copied, {} extracted: {})", e.incremental.faces_copied,
                          e.incremental.faces_extracted, e.incremental.redo_reason)
            : "");
    for (const std::string& w : e.warnings) out += "    warning: " + w + "\n";
  }
  for (const std::string& w : r.warnings) out += "  warning: " + w + "\n";
  return out;
}

namespace {

// A shard's summary: its faces, what they cost, where they went.
std::string ShardSummary(const ExtractReport& r) {
  std::string copied =
      r.incremental.faces_copied > 0
          ? fmt::format(" ({} copied from the part there)", r.incremental.faces_copied)
          : "";
  return fmt::format(
      "dispex: shard {}/{}: faces {}..{} in shard order ({:.1f}% of the estimated cost), {} "
      "extracted{} -> {}\n  time {:.2f}s (read {:.2f}+{:.2f}, bvh {:.2f}, sample+trace {:.2f})  "
      "peak {:.0f} MB\n",
      r.options.shard_index, r.options.shard_count, r.shard.begin, r.shard.end - 1,
      100 * r.shard.cost_fraction, r.incremental.faces_extracted, copied, r.output.path,
      r.times.total, r.times.read_base, r.times.read_sculpt, r.times.bvh, r.times.sample_trace,
      double(r.peak_rss_bytes) / 1e6);
}

// Where the values came from -- the correspondence (vector maps, interpolation, the mapping)
// or rays -- with the tolerance, the samples and what the rays missed.
std::string SourceLines(const ExtractReport& r) {
  const char* tolerance_auto = r.settings.tolerance_auto ? " (auto)" : "";
  if (!r.displacement.vector_space.empty()) {
    return fmt::format(
               "  vector ({}): the sculpt is the base refined {} times; its vertices lie up to "
               "{:.4g} (rms {:.4g}) from their points on the limit surface\n",
               r.displacement.vector_space, r.method.levels, r.method.max_offset,
               r.method.rms_offset) +
           fmt::format("  tolerance {:.4g}{}  samples {}  matched in {:.2f}s\n",
                       r.settings.tolerance, tolerance_auto, r.sampling.samples, r.times.match);
  }
  if (r.method.used == ExtractMethod::kInterpolate) {
    return fmt::format(
               "  the sculpt's vertex displacements interpolated through the subdivision "
               "correspondence (level {}, {:.2f}s; vertices up to {:.4g} from their points)\n",
               r.method.levels, r.times.match, r.method.max_offset) +
           fmt::format("  tolerance {:.4g}{}  samples {}\n", r.settings.tolerance, tolerance_auto,
                       r.sampling.samples);
  }
  std::string out;
  if (r.method.used == ExtractMethod::kMapping) {
    out += fmt::format(
        "  through the subdivision correspondence (level {}, {:.2f}s); {} samples of {} "
        "faces left to a BVH\n",
        r.method.levels, r.times.match, r.method.fallback_samples, r.method.fallback_faces);
  }
  out += fmt::format("  tolerance {:.4g}{}  search distance {:.4g}{}\n", r.settings.tolerance,
                     tolerance_auto, r.settings.search_distance,
                     r.settings.search_distance_auto ? " (auto)" : "");
  out += fmt::format(
      "  samples {}  rays {}  misses {} ({} filled in-face, {} faces from "
      "neighbours; {} more found by the {:.4g} search)\n",
      r.sampling.samples, r.sampling.rays_cast, r.sampling.misses, r.sampling.holes_filled,
      r.sampling.faces_filled_from_neighbours, r.sampling.misses_recovered,
      r.sampling.retry_search_distance);
  return out;
}

// The watertight edges: a vector map's pinned edge texels, and the steps across shared edges.
std::string EdgeLines(const ExtractReport& r) {
  const SpectralTotals& s = r.spectral;
  std::string out;
  if (r.edges.rule == WatertightEdges::kAll && !r.displacement.vector_space.empty()) {
    out += fmt::format(
        "  edges ({}): texels pinned to the edges, each face's own reading there within {:.3g} "
        "({:.2g} tolerances); {} faces whose finest samples are too coarse for it\n",
        WatertightEdgesName(r.edges.rule), s.max_edge_error,
        s.max_edge_error / r.settings.tolerance, s.edge_limited_faces);
  }
  if (r.edges.rule == WatertightEdges::kOff) return out;
  out += fmt::format(
      "  edges ({}): {} shared, largest step{} {:.3g} across faces ({:.2g} "
      "tolerances)",
      WatertightEdgesName(r.edges.rule), r.edges.shared,
      r.displacement.vector_space.empty() ? "" : " of D", r.edges.step_across_faces,
      r.edges.step_across_faces / r.settings.tolerance);
  if (r.edges.rule == WatertightEdges::kAll) {
    out += fmt::format(", {:.3g} per face ({:.2g} tolerances)", r.edges.step_per_face,
                       r.edges.step_per_face / r.settings.tolerance);
  }
  out += fmt::format("; {} faces raised in {} rounds, texels {} -> {}", r.edges.raised_faces,
                     r.edges.rounds, r.edges.texels_before, s.texels_after);
  if (r.edges.over + r.edges.sharp + r.edges.discontinuous > 0) {
    out += fmt::format(
        "; not held: {} over the tolerance, {} on sharp creases, {} beside "
        "filled holes or other sheets",
        r.edges.over, r.edges.sharp, r.edges.discontinuous);
  }
  return out + "\n";
}

// The values of the map: along the normal, or a vector map's lengths.
std::string DisplacementLine(const ExtractReport& r) {
  if (r.displacement.vector_space.empty()) {
    return fmt::format("  displacement [{:.4g}, {:.4g}] rms {:.4g}\n", r.displacement.min,
                       r.displacement.max, r.displacement.rms);
  }
  return fmt::format(
      "  displacement |D| up to {:.4g} (rms {:.4g}), along the normal [{:.4g}, {:.4g}], "
      "across it up to {:.4g}\n",
      r.displacement.length_max, r.displacement.rms, r.displacement.min, r.displacement.max,
      r.displacement.tangential_max);
}

// What an incremental run redid and why: the faces whose inputs changed, those copied but
// extracted again for a neighbour's edge, and what the BVH held.
std::string IncrementalLine(const ExtractReport& r) {
  std::string out = fmt::format("dispex: incremental: {} faces copied, {} extracted ({})",
                                r.incremental.faces_copied, r.incremental.faces_extracted,
                                r.incremental.redo_reason);
  if (r.incremental.faces_copied_redone > 0) {
    out += fmt::format("; {} copied extracted again for a neighbour's edge",
                       r.incremental.faces_copied_redone);
  }
  if (r.incremental.edges_copied > 0) {
    out += fmt::format("; {} of {} shared edges' steps copied", r.incremental.edges_copied,
                       r.edges.shared);
  }
  if (r.incremental.fields_kept >= 0) {
    out += fmt::format("; {} faces' sculpt keys kept", r.incremental.fields_kept);
  }
  if (r.incremental.tracer_faces > 0) {
    out += fmt::format("; the BVH held the sculpt within reach of {} faces",
                       r.incremental.tracer_faces);
  }
  if (r.incremental.search_rays_recast >= 0) {
    out += fmt::format("; the search distance's rays: {} of {} cast again",
                       r.incremental.search_rays_recast, r.incremental.search_rays);
  }
  return out + "\n";
}

}  // namespace

std::string ExtractReportSummary(const ExtractReport& r) {
  const SpectralTotals& s = r.spectral;
  if (r.options.plan_only) return ExtractPlanSummary(r.plan);
  if (r.incremental.unchanged) {
    return fmt::format(
        "dispex: {} is up to date (made from the same inputs and options): not rewritten, "
        "{:.2f}s\n",
        r.output.path, r.times.total);
  }
  if (r.options.shard_count > 0) return ShardSummary(r);
  std::string out;
  if (r.options.incremental) out += IncrementalLine(r);
  if (r.shard.parts_merged > 0)
    out += fmt::format("dispex: merged {} parts\n", r.shard.parts_merged);
  out += fmt::format("dispex: {} ({} Ptex faces) <- {} ({} faces)\n", r.output.path,
                     r.inputs.ptex_faces, r.inputs.sculpt_path, r.inputs.sculpt_faces);
  out += SourceLines(r);
  if (r.sampling.hits_opposed > 0) {
    out += fmt::format(
        "  {} hits on sculpt faces facing against the normal (folds or other "
        "sheets)\n",
        r.sampling.hits_opposed);
  }
  out += fmt::format("  texels {} -> {} ({:.1f}%)  constant faces {}  max error {:.3g}\n",
                     s.texels_before, s.texels_after,
                     s.texels_before ? 100.0 * double(s.texels_after) / double(s.texels_before) : 0,
                     s.constant_faces, s.max_measured_error);
  out += EdgeLines(r);
  out += DisplacementLine(r);
  out += fmt::format(
      "  time {:.2f}s (read {:.2f}+{:.2f}, bvh {:.2f}, sample+trace {:.2f}, "
      "write {:.2f})  {:.1f} MB  peak {:.0f} MB\n",
      r.times.total, r.times.read_base, r.times.read_sculpt, r.times.bvh, r.times.sample_trace,
      r.times.write, double(r.output.bytes) / 1e6, double(r.peak_rss_bytes) / 1e6);
  if (!r.uv.paths.empty()) {
    out += fmt::format("  UV maps: {} tiles of {}x{} in {} ({} texels inside UV faces), {:.2f}s\n",
                       r.uv.paths.size(), r.options.uv_resolution, r.options.uv_resolution,
                       r.options.uv_maps_dir, r.uv.texels_inside, r.times.uv_maps);
  }
  for (const std::string& w : r.warnings) out += "  warning: " + w + "\n";
  return out;
}

}  // namespace dispex
