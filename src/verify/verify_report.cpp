// The verify report as written: JSON (VerifyReportJson) and the summary on stdout
// (VerifyReportSummary).
#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "dispex/vector_space.h"
#include "dispex/verify.h"

namespace dispex {

namespace {
nlohmann::json StatsJson(const ErrorStats& s, double diagonal) {
  return {{"count", s.count},
          {"mean", s.mean},
          {"rms", s.rms},
          {"p99", s.p99},
          {"max", s.max},
          {"rms_rel", s.rms / diagonal},
          {"p99_rel", s.p99 / diagonal},
          {"max_rel", s.max / diagonal}};
}
// With `tau` > 0, the mean, p99 and max in tolerances too.
std::string StatsLine(const char* what, const ErrorStats& s, double diagonal, double tau = 0) {
  const std::string tolerances =
      tau > 0 ? fmt::format("mean / p99 / max {:.3g} / {:.3g} / {:.3g} tolerances; ", s.mean / tau,
                            s.p99 / tau, s.max / tau)
              : "";
  return fmt::format(
      "  {:<12} rms {:.4g}  p99 {:.4g}  max {:.4g}  (max {:.3g} of the diagonal; {}"
      "{} points)\n",
      what, s.rms, s.p99, s.max, s.max / diagonal, tolerances, s.count);
}
}  // namespace

std::string VerifyReportJson(const VerifyReport& r) {
  nlohmann::json j;
  j["diagonal"] = r.diagonal;
  j["ptex_faces"] = r.ptex_faces;
  j["map_kind"] = r.displaced_mesh ? "displaced mesh" : r.map_vector ? "vector" : "scalar";
  if (r.map_vector) j["vector_space"] = VectorSpaceName(r.map_space);
  if (r.measured_distances) {
    j["samples_per_face"] = {r.samples_per_face_min, r.samples_per_face_max};
    j["map_to_sculpt"] = StatsJson(r.map_to_sculpt, r.diagonal);
    j["sculpt_to_map"] = StatsJson(r.sculpt_to_map, r.diagonal);
    nlohmann::json worst = nlohmann::json::array();
    for (const auto& w : r.worst_faces) worst.push_back({{"face", w.face}, {"max", w.max}});
    j["worst_faces"] = worst;
  }
  if (r.measured_truth) {
    j["truth"] = StatsJson(r.truth, r.diagonal);
    j["truth"]["version"] = r.truth_version;
    j["truth"]["quantity"] = r.truth_quantity;
    j["truth"]["signed_mean"] = r.truth_signed_mean;
    nlohmann::json bound = {{"tolerance", r.truth_tolerance},
                            {"rms_limit", r.truth_rms_limit},
                            {"p99_limit", r.truth_p99_limit},
                            {"local_checked", r.truth_local_checked},
                            {"local_tolerance_factor", r.truth_local_tolerance_factor}};
    if (r.truth_local_checked) {
      const auto& w = r.truth_worst;
      bound["records_over"] = r.truth_over_bound;
      bound["records_unbounded"] = r.truth_unbounded;
      bound["worst_ratio"] = r.truth_worst_ratio;
      bound["local_error"] = StatsJson(r.truth_local_error, r.diagonal);
      bound["worst_record"] = {{"index", w.index},
                               {"face", w.face},
                               {"u", w.u},
                               {"v", w.v},
                               {"h", w.h},
                               {"map", w.map},
                               {"local_error", w.local_error}};
      if (w.vector) {
        bound["worst_record"]["d"] = {w.d[0], w.d[1], w.d[2]};
        bound["worst_record"]["map_d"] = {w.map_d[0], w.map_d[1], w.map_d[2]};
      }
    }
    j["truth"]["bound"] = bound;
  }
  if (r.measured_edges) {
    auto steps = [&](const ErrorStats& s) {
      nlohmann::json out = StatsJson(s, r.diagonal);
      if (r.edge_tolerance > 0) {
        out["p99_tolerances"] = s.p99 / r.edge_tolerance;
        out["max_tolerances"] = s.max / r.edge_tolerance;
      }
      return out;
    };
    nlohmann::json worst = nlohmann::json::array();
    for (const auto& w : r.worst_edges) {
      worst.push_back({{"face", w.face},
                       {"edge", w.edge},
                       {"neighbour", w.neighbour},
                       {"t", w.t},
                       {"step", w.step},
                       {"reader", w.reader}});
    }
    j["edges"] = {{"object_space", r.edges_object_space},
                  {"shared", r.edges},
                  {"sharp_creases", r.crease_edges},
                  {"discontinuous", r.discontinuous_edges},
                  {"tolerance", r.edge_tolerance},
                  {"max_limit", r.edge_max_limit},
                  {"p99_limit", r.edge_p99_limit},
                  {"per_face", steps(r.edge_per_face)},
                  {"across_faces", steps(r.edge_across_faces)},
                  {"worst", worst}};
  }
  j["map"] = {{"misses", r.map_misses},
              {"holes_filled", r.map_holes_filled},
              {"faces_filled_from_neighbours", r.map_faces_filled_from_neighbours},
              {"tolerance", r.map_tolerance}};
  j["passed"] = r.passed;
  if (!r.passed) j["failure"] = r.failure;
  j["warnings"] = r.warnings;
  if (!r.uv_faces_without_tile.empty()) j["uv_faces_without_tile"] = r.uv_faces_without_tile;
  j["seconds"] = r.seconds;
  // Last, being long: every face's error (null for a face without samples or records).
  if (!r.face_map_to_sculpt_max.empty() || !r.face_truth_max.empty()) {
    nlohmann::json per_face = nlohmann::json::object();
    if (!r.face_map_to_sculpt_max.empty()) per_face["map_to_sculpt_max"] = r.face_map_to_sculpt_max;
    if (!r.face_truth_max.empty()) per_face["truth_max"] = r.face_truth_max;
    j["per_face"] = per_face;
  }
  return j.dump(2) + "\n";
}

std::string VerifyReportSummary(const VerifyReport& r) {
  if (r.displaced_mesh) {
    return fmt::format(
               "verify: a displaced mesh against the sculpt, bounding-box diagonal {:.4g}\n",
               r.diagonal) +
           StatsLine("displaced->sculpt", r.map_to_sculpt, r.diagonal) +
           StatsLine("sculpt->displaced", r.sculpt_to_map, r.diagonal);
  }
  std::string out = fmt::format(
      "verify: {} Ptex faces, bounding-box diagonal {:.4g}, {}\n", r.ptex_faces, r.diagonal,
      r.map_vector ? fmt::format("vector map ({} space: P + D)", VectorSpaceName(r.map_space))
                   : std::string("scalar map (P + h N)"));
  if (r.measured_distances) {
    out += StatsLine("map->sculpt", r.map_to_sculpt, r.diagonal, r.distance_tolerance);
    out += StatsLine("sculpt->map", r.sculpt_to_map, r.diagonal, r.distance_tolerance);
    if (!r.worst_faces.empty()) {
      out += "  worst faces:";
      for (const auto& w : r.worst_faces) out += fmt::format(" {} ({:.3g})", w.face, w.max);
      out += "\n";
    }
  }
  if (r.measured_truth) {
    out += StatsLine("truth", r.truth, r.diagonal);
    out += fmt::format("  truth (version {}) measured as {}\n", r.truth_version, r.truth_quantity);
    if (r.truth_local_checked) {
      out += fmt::format(
          "  truth bound {} x tolerance {:.4g} + 2 x local linear error: {} of {} records "
          "over, worst {:.3g} x the bound; RMS {:.3g} and p99 {:.3g} tolerances\n",
          r.truth_local_tolerance_factor, r.truth_tolerance, r.truth_over_bound, r.truth.count,
          r.truth_worst_ratio, r.truth.rms / r.truth_tolerance, r.truth.p99 / r.truth_tolerance);
      if (r.truth_unbounded > 0) {
        out +=
            fmt::format("  {} records near folded sculpt faces not bounded\n", r.truth_unbounded);
      }
    }
  }
  if (r.measured_edges) {
    auto line = [&](const char* what, const ErrorStats& s) {
      std::string tolerances;
      if (r.edge_tolerance > 0) {
        tolerances = fmt::format(" ({:.3g} / {:.3g} tolerances)", s.p99 / r.edge_tolerance,
                                 s.max / r.edge_tolerance);
      }
      return fmt::format("  {:<12} p99 {:.4g}  max {:.4g}{}\n", what, s.p99, s.max, tolerances);
    };
    out += fmt::format(
        "  edge steps{} on {} shared edges ({} points; not measured: {} on sharp "
        "creases, {} beside faces the map lists as discontinuous):\n",
        r.edges_object_space ? " of |D| in object space" : "",
        r.edges - r.crease_edges - r.discontinuous_edges, r.edge_per_face.count, r.crease_edges,
        r.discontinuous_edges);
    out += line("per-face", r.edge_per_face);
    out += line("across-faces", r.edge_across_faces);
    if (!r.worst_edges.empty()) {
      out += "  worst edges:";
      for (std::size_t i = 0; i < std::min<std::size_t>(3, r.worst_edges.size()); ++i) {
        const auto& w = r.worst_edges[i];
        out += fmt::format(" face {} edge {} ({}, {:.3g})", w.face, w.edge, w.reader, w.step);
      }
      out += "\n";
    }
  }
  if (r.map_misses >= 0) {
    out += fmt::format(
        "  map: {} misses ({} filled in-face, {} faces from neighbours), "
        "tolerance {:.4g}\n",
        r.map_misses, r.map_holes_filled, r.map_faces_filled_from_neighbours, r.map_tolerance);
  }
  out += r.passed ? "  passed\n" : "  FAILED: " + r.failure + "\n";
  return out;
}

}  // namespace dispex
