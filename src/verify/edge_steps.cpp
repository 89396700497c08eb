// dispex verify: the steps of a Ptex map at shared face edges, as the per-face reader and the
// reader across faces see them (VerifyReport's edge fields), and their bounds.
#include "verify/edge_steps.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "core/first_error.h"
#include "dispex/extract.h"
#include "dispex/ptex_sampler.h"
#include "dispex/subdiv.h"
#include "verify/verify_stats.h"

namespace dispex::verify {

namespace {

// The map's face table for the sampler: resolutions from the map, adjacency and sub-face
// flags from the base's limit surface (the map's own adjacency is not trusted).
std::vector<PtexFaceInfo> MapFacesOnSurface(const LimitSurface& surface, const PtexFile& map) {
  std::vector<PtexFaceInfo> faces = PtexFaceTable(surface);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const PtexFaceInfo& stored = map.face_info(PtexFaceId(static_cast<int>(f)));
    faces[f].ulog2 = stored.ulog2;
    faces[f].vlog2 = stored.vlog2;
  }
  return faces;
}

// Per field and face, the level-0 values whose steps at face edges are measured: the map's
// one channel (one value for a constant face), or a vector map's D in object space as three
// fields x, y, z. A tangent or parametric map's texels are converted with the frame at their
// centres (constant faces expanded, as D turns over them); an object map's channels are D.
Status EdgeFields(const LimitSurface& surface, const PtexFile& map,
                  std::optional<VectorSpace> space, std::span<const PtexFaceInfo> faces,
                  std::vector<std::vector<std::vector<float>>>& fields) {
  const int channels = map.header().num_channels;
  const bool convert = space && *space != VectorSpace::kObject;
  fields.assign(space ? 3 : 1, std::vector<std::vector<float>>(faces.size()));
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<FrameScratch> scratch;
  FirstError error;
  tbb::parallel_for(std::size_t{0}, faces.size(), [&](std::size_t f) {
    const PtexFaceId face(static_cast<std::int32_t>(f));
    const bool hole = surface.is_hole(face);
    std::vector<float> all;
    if ((hole || !convert) &&
        map.BlockInfo(face, 0).encoding == PtexBlockInfo::Encoding::kConstant) {
      all.resize(static_cast<std::size_t>(channels));
      map.ConstantValue(face, all.data());
    } else {
      Status read = map.ReadFace(face, 0, all);
      if (!read.ok()) return error.Record(static_cast<int>(f), read);
    }
    for (float x : all) {
      if (!std::isfinite(x)) {
        return error.Record(static_cast<int>(f),
                            Status::Error(fmt::format(
                                "{}: face {} holds a value that is not finite", map.name(), f)));
      }
    }
    const std::size_t texels = all.size() / static_cast<std::size_t>(channels);
    for (std::size_t c = 0; c < fields.size(); ++c) fields[c][f].resize(texels);
    if (convert && !hole) {
      auto& evaluator = evaluators.local();
      if (!evaluator) evaluator.emplace(surface);
      FrameScratch& s = scratch.local();
      s.Resize(texels);
      Status st = evaluator->EvaluateGridFrames(face, faces[f].ures(), faces[f].vres(), s.Frames());
      if (!st.ok()) return error.Record(static_cast<int>(f), st);
      VectorsFromChannels(*space, s.du, s.dv, s.nrm, all, fields[0][f], fields[1][f], fields[2][f]);
      return;
    }
    for (std::size_t c = 0; c < fields.size(); ++c) {
      for (std::size_t i = 0; i < texels; ++i) {
        fields[c][f][i] = all[i * static_cast<std::size_t>(channels) + c];
      }
    }
  });
  return error.failed() ? error.status() : Status::Ok();
}

// `faces` and `fields` as EdgeFields makes them.
Status MeasureEdges(const Mesh& base, const LimitSurface& surface, const PtexFile& map,
                    std::span<const PtexFaceInfo> faces,
                    std::span<const std::vector<std::vector<float>>> fields,
                    const VerifyOptions& options, VerifyReport& r) {
  std::vector<std::uint8_t> holes(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    holes[f] = surface.is_hole(PtexFaceId(static_cast<std::int32_t>(f)));
  }
  std::vector<std::uint8_t> skip = holes, discontinuous(faces.size(), 0);
  if (const PtexMetaItem* listed = map.FindMetaData("dispex:discontinuous_faces")) {
    for (std::int32_t f : listed->AsInt32()) {
      if (f < 0 || static_cast<std::size_t>(f) >= faces.size()) {
        return Status::Error(
            fmt::format("{}: dispex:discontinuous_faces names face {}, not one of "
                        "its {} faces",
                        map.name(), f, faces.size()));
      }
      if (!holes[static_cast<std::size_t>(f)]) discontinuous[static_cast<std::size_t>(f)] = 1;
      skip[static_cast<std::size_t>(f)] = 1;
    }
  }
  const std::vector<std::uint8_t> creases = SharpCreaseEdges(base, surface);
  PtexEdgeSteps steps = MeasurePtexVectorEdgeSteps(faces, fields, creases, skip);
  r.edges_object_space = fields.size() == 3;
  r.measured_edges = true;
  r.discontinuous_edges = CountEdgesTouching(faces, discontinuous, holes);
  r.edges = steps.edges + r.discontinuous_edges;
  r.crease_edges = steps.skipped_edges;
  r.edge_per_face = Summarise(steps.per_face);
  r.edge_across_faces = Summarise(steps.across_faces);
  std::vector<VerifyReport::WorstEdge> worst;
  for (const PtexEdgeStep& s : steps.edge_max) {
    worst.push_back({s.face, s.edge, s.neighbour, s.t_per_face, s.per_face, "per-face"});
    worst.push_back(
        {s.face, s.edge, s.neighbour, s.t_across_faces, s.across_faces, "across-faces"});
  }
  std::stable_sort(worst.begin(), worst.end(),
                   [](const auto& x, const auto& y) { return x.step > y.step; });
  for (const auto& w : worst) {
    if (r.worst_edges.size() == 10 || w.step == 0) break;
    r.worst_edges.push_back(w);
  }
  const double tau = options.tolerance > 0 ? options.tolerance : r.map_tolerance;
  if ((options.max_edge_step > 0 || options.max_edge_step_p99 > 0) && !(tau > 0)) {
    return Status::Error(
        fmt::format("{}: the edge-step bounds are in tolerances, and the map carries none (no "
                    "dispex:statistics): give the tolerance",
                    map.name()));
  }
  r.edge_tolerance = tau;
  r.edge_max_limit = options.max_edge_step * tau;
  r.edge_p99_limit = options.max_edge_step_p99 * tau;
  return Status::Ok();
}

}  // namespace

// A Ptex map's steps at shared face edges (EdgeFields, MeasureEdges).
Status MeasureEdgeSteps(const VerifyOptions& options, const Mesh& base, const LimitSurface& surface,
                        const PtexFile& map, std::optional<VectorSpace> space,
                        std::vector<PtexFaceInfo>& faces,
                        std::vector<std::vector<std::vector<float>>>& fields, VerifyReport& r) {
  faces = MapFacesOnSurface(surface, map);
  DISPEX_RETURN_IF_ERROR(EdgeFields(surface, map, space, faces, fields));
  return MeasureEdges(base, surface, map, faces, fields, options, r);
}

void EdgeThresholds(VerifyReport& r, const VerifyOptions& options) {
  if (!r.passed) return;
  const std::pair<const char*, const ErrorStats*> readers[] = {
      {"per-face", &r.edge_per_face}, {"across-faces", &r.edge_across_faces}};
  for (const auto& [reader, stats] : readers) {
    if (r.edge_max_limit > 0 && stats->max > r.edge_max_limit) {
      r.passed = false;
      r.failure = fmt::format(
          "edge steps ({} reader): max {:.4g} exceeds max_edge_step {} x tolerance {:.4g}", reader,
          stats->max, options.max_edge_step, r.edge_tolerance);
    } else if (r.edge_p99_limit > 0 && stats->p99 > r.edge_p99_limit) {
      r.passed = false;
      r.failure = fmt::format(
          "edge steps ({} reader): p99 {:.4g} exceeds max_edge_step_p99 {} x tolerance {:.4g}",
          reader, stats->p99, options.max_edge_step_p99, r.edge_tolerance);
    }
    if (!r.passed) {
      for (const auto& w : r.worst_edges) {
        if (std::string_view(w.reader) != reader) continue;
        r.failure += fmt::format(" (worst: face {} edge {} at t {:.4g}, neighbour {}, step {:.4g})",
                                 w.face, w.edge, w.t, w.neighbour, w.step);
        break;
      }
      return;
    }
  }
}

}  // namespace dispex::verify
