#include "extract/edge_matching.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include "dispex/ptex_sampler.h"
#include "extract/faces_around.h"
#include "extract/incremental/face_keys.h"
#include "extract/incremental/previous_map.h"
#include "extract/parallel_errors.h"
#include "extract/vector_faces.h"

namespace dispex::extract {

namespace {

constexpr int kMaxRounds = 8;
// A raise must bring an edge's step below this fraction of what it was to be worth another.
constexpr double kProgress = 0.75;
constexpr int kFutileRaises = 2;

// A face whose data may jump at its edges: samples filled over holes of the sculpt, or hits
// on another sheet (folds, thin parts). Its edges are not held; they are counted.
bool Discontinuous(const FaceStats& stats) {
  return stats.all_missed || stats.filled > 0 || stats.hits_opposed > 0;
}

// Whether face f's components are its kept channels, moved into the map the rounds measure
// and back (a scalar map, an object-space vector map, a hole); otherwise they are D turned
// into object space from them (VectorObjectComponents), and the texels stay where they are.
bool ComponentsAreChannels(const ExtractInputs& inputs, const ExtractSettings& settings,
                           std::size_t f) {
  return !settings.vector || *settings.vector == VectorSpace::kObject ||
         inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)));
}

// Face f's kept texels into the map the rounds measure (ReturnFace gives them back).
Status TakeFace(std::size_t f, const ExtractInputs& inputs, const ExtractSettings& settings,
                ProcessedFaces& processed, FaceScratch& w, EdgeRoundsMap& view) {
  KeptFace& kept = processed.kept[f];
  const PtexFaceId face(static_cast<int>(f));
  view.skip_faces[f] =
      !kept.kept || inputs.surface.is_hole(face) || Discontinuous(processed.stats[f]);
  if (!kept.kept) {  // missed entirely: not measured
    for (auto& component : view.components) component[f] = {0.0f};
    return Status::Ok();
  }
  view.faces[f].ulog2 = kept.ulog2;
  view.faces[f].vlog2 = kept.vlog2;
  if (kept.unread) return Status::Ok();  // until a measurement reads it (LoadFaces)
  const std::size_t channels = view.components.size();
  if (!ComponentsAreChannels(inputs, settings, f)) {
    return VectorObjectComponents(
        face, *settings.vector, kept.ulog2, kept.vlog2, kept.texels, w,
        {&view.components[0][f], &view.components[1][f], &view.components[2][f]});
  }
  if (channels == 1) {
    view.components[0][f].swap(kept.texels);
    return Status::Ok();
  }
  const std::size_t count = kept.texels.size() / channels;
  for (std::size_t c = 0; c < channels; ++c) {
    std::vector<float>& component = view.components[c][f];
    component.resize(count);
    for (std::size_t i = 0; i < count; ++i) component[i] = kept.texels[channels * i + c];
  }
  std::vector<float>().swap(kept.texels);  // the map is held once
  return Status::Ok();
}

void ReturnFace(std::size_t f, const ExtractInputs& inputs, const ExtractSettings& settings,
                ProcessedFaces& processed, EdgeRoundsMap& view) {
  KeptFace& kept = processed.kept[f];
  if (!kept.kept || kept.unread || !ComponentsAreChannels(inputs, settings, f)) return;
  const std::size_t channels = view.components.size();
  if (channels == 1) {
    kept.texels.swap(view.components[0][f]);
    return;
  }
  const std::size_t count = view.components[0][f].size();
  kept.texels.resize(channels * count);
  for (std::size_t c = 0; c < channels; ++c) {
    std::vector<float>& component = view.components[c][f];
    for (std::size_t i = 0; i < count; ++i) kept.texels[channels * i + c] = component[i];
    std::vector<float>().swap(component);
  }
}

// log2 texels of face f along its edge e and across it; a quad next to sub-faces counts one
// level less, as the filter reads it (a sub-face is a quarter of a quad to it).
struct EdgeRes {
  int along = 0, across = 0;
  int along_dim = 0;  // 0: u, 1: v
};
EdgeRes ResAt(const PtexFaceInfo& info, int e, bool quad_beside_subface) {
  EdgeRes r;
  r.along_dim = e % 2 == 0 ? 0 : 1;
  r.along = r.along_dim == 0 ? info.ulog2 : info.vlog2;
  r.across = r.along_dim == 0 ? info.vlog2 : info.ulog2;
  if (quad_beside_subface) --r.along, --r.across;
  return r;
}

std::int64_t Texels(const ProcessedFaces& processed, const ExtractInputs& inputs) {
  std::int64_t total = 0;
  for (std::size_t f = 0; f < processed.kept.size(); ++f) {
    if (inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)))) continue;
    const KeptFace& kept = processed.kept[f];
    total += kept.kept ? std::int64_t{1} << (kept.ulog2 + kept.vlog2) : 1;
  }
  return total;
}

// What the previous map lets the first round take: the steps it recorded, for the edges away
// from the faces whose first pass is not the previous map's (another key, or no previous map).
FirstRoundBefore StepsBefore(const ExtractInputs& inputs, const ProcessedFaces& faces) {
  FirstRoundBefore before;
  if (faces.previous == nullptr || inputs.face_keys == nullptr) return before;
  before.steps = faces.previous->FirstRoundEdgeSteps(inputs.faces);
  if (before.steps.empty()) return before;
  const std::vector<Hash128>& keys = inputs.face_keys->keys;
  std::vector<std::uint8_t> changed(keys.size(), 0);
  for (std::size_t f = 0; f < keys.size(); ++f) changed[f] = !faces.previous->SameKey(f, keys[f]);
  before.changed = WithFacesAround(inputs, std::move(changed));
  return before;
}

}  // namespace

Status RaiseEdgeResolutions(const ExtractInputs& inputs, const ExtractSettings& settings,
                            EdgeRoundsMap& view, const FirstRoundBefore& before,
                            const LoadFaces& load, const RedoFaces& redo_faces,
                            std::vector<double>& first_round, ExtractReport& report) {
  const double budget = settings.edge_step_budget;
  const bool per_face = settings.watertight == WatertightEdges::kAll;
  const std::vector<std::uint8_t> sharp = SharpCreaseEdges(inputs.base, inputs.surface);
  const std::size_t n = view.faces.size();

  std::vector<std::array<int, 2>> least(n, {0, 0});
  std::vector<std::uint8_t> raised(n, 0), redone;
  std::map<std::pair<int, int>, double> last_step;      // (face, edge) -> step when last raised
  std::map<std::pair<int, int>, int> futile;            // raises that did not bring it down
  std::map<std::pair<int, int>, PtexEdgeStep> current;  // every measured edge, as it stands
  PtexEdgeMeasure measure;
  measure.per_face = per_face;
  measure.keep_points = false;
  for (int round = 0;; ++round) {
    // The first round measures every edge (or takes it from before), later ones the edges of
    // the faces just redone.
    measure.only_faces = redone;
    if (round == 0) {
      measure.known = before.steps;
      measure.changed = before.changed;
    } else {
      measure.known = {};
      measure.changed = {};
    }
    DISPEX_RETURN_IF_ERROR(load(
        WithFacesAround(inputs, PtexFacesSampled(view.faces, sharp, view.skip_faces, measure))));
    const PtexEdgeSteps steps =
        MeasurePtexVectorEdgeSteps(view.faces, view.components, sharp, view.skip_faces, measure);
    if (round == 0) {
      report.edges.shared = static_cast<std::int64_t>(steps.edges);
      report.edges.sharp = static_cast<std::int64_t>(steps.skipped_edges);
      report.incremental.edges_copied = static_cast<std::int64_t>(steps.known_edges);
      first_round = PtexEdgeStepsByFace(steps.edge_max, n);
    }
    for (const PtexEdgeStep& s : steps.edge_max) current[{s.face, s.edge}] = s;
    if (round == kMaxRounds) break;
    std::vector<std::array<int, 2>> want = least;
    auto raise = [&](int f, int dim) {
      const PtexFaceInfo& info = view.faces[static_cast<std::size_t>(f)];
      const int now = dim == 0 ? info.ulog2 : info.vlog2;
      const int cap =
          std::max<int>(settings.plan.log2[static_cast<std::size_t>(f)], settings.max_samples_log2);
      if (now + 1 > cap) return false;
      int& w = want[static_cast<std::size_t>(f)][static_cast<std::size_t>(dim)];
      w = std::max(w, now + 1);
      return true;
    };
    for (const PtexEdgeStep& s : steps.edge_max) {
      const bool over_filter = s.across_faces > budget;
      const bool over_face = per_face && s.per_face > budget;
      if (!over_filter && !over_face) continue;
      const double step =
          std::max(over_filter ? s.across_faces : 0.0, over_face ? s.per_face : 0.0);
      const auto key = std::make_pair(s.face, s.edge);
      if (auto it = last_step.find(key); it != last_step.end() && step > kProgress * it->second) {
        // The last raise did not help; after two such the displacement itself steps here.
        if (++futile[key] >= kFutileRaises) continue;
      }
      const PtexFaceInfo& a = view.faces[static_cast<std::size_t>(s.face)];
      const PtexFaceInfo& b = view.faces[static_cast<std::size_t>(s.neighbour)];
      const int b_edge = a.adjedges[static_cast<std::size_t>(s.edge)];
      const EdgeRes ra = ResAt(a, s.edge, !a.subface && b.subface);
      const EdgeRes rb = ResAt(b, b_edge, !b.subface && a.subface);
      bool any = false;
      if (over_filter) {
        if (ra.along != rb.along) {
          any |=
              ra.along < rb.along ? raise(s.face, ra.along_dim) : raise(s.neighbour, rb.along_dim);
        } else if (ra.across != rb.across) {
          any |= ra.across < rb.across ? raise(s.face, 1 - ra.along_dim)
                                       : raise(s.neighbour, 1 - rb.along_dim);
        } else {
          any |= raise(s.face, ra.along_dim);
          any |= raise(s.neighbour, rb.along_dim);
        }
      }
      if (over_face) {
        any |= raise(s.face, 1 - ra.along_dim);
        any |= raise(s.neighbour, 1 - rb.along_dim);
      }
      if (any) last_step[key] = step;
    }
    std::vector<int> redo;
    redone.assign(n, 0);
    for (std::size_t f = 0; f < n; ++f) {
      if (want[f] == least[f]) continue;
      least[f] = want[f];
      redo.push_back(static_cast<int>(f));
      raised[f] = redone[f] = 1;
    }
    if (redo.empty()) break;
    ++report.edges.rounds;
    DISPEX_RETURN_IF_ERROR(redo_faces(redo, least, view));
  }

  for (std::size_t f = 0; f < n; ++f) report.edges.raised_faces += raised[f];
  for (const auto& [key, s] : current) {
    report.edges.step_per_face = std::max(report.edges.step_per_face, s.per_face);
    report.edges.step_across_faces = std::max(report.edges.step_across_faces, s.across_faces);
    report.edges.over += s.across_faces > budget || (per_face && s.per_face > budget);
  }
  return Status::Ok();
}

Status MatchEdges(ExtractInputs& inputs, const ExtractSettings& settings, ProcessedFaces& faces,
                  ExtractReport& report) {
  report.edges.texels_before = Texels(faces, inputs);
  const std::size_t n = faces.kept.size();
  EdgeRoundsMap view;
  view.faces = inputs.faces;
  view.components.assign(static_cast<std::size_t>(faces.channels),
                         std::vector<std::vector<float>>(n));
  view.skip_faces.resize(n);
  tbb::enumerable_thread_specific<FaceScratch> scratches(
      [&] { return FaceScratch(inputs.surface); });
  auto take = [&](std::span<const int> which) {
    return ForEachFace(
        static_cast<int>(which.size()), [&](int k) { return which[static_cast<std::size_t>(k)]; },
        scratches, nullptr,
        [&](PtexFaceId face, FaceScratch& w) {
          return TakeFace(static_cast<std::size_t>(face.value), inputs, settings, faces, w, view);
        });
  };
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  DISPEX_RETURN_IF_ERROR(take(all));
  // Copied faces are read from the previous map once a measurement reads them.
  auto load = [&](std::span<const std::uint8_t> flags) {
    std::vector<int> unread;
    for (std::size_t f = 0; f < n; ++f) {
      if (flags[f] && faces.kept[f].unread) unread.push_back(static_cast<int>(f));
    }
    return ForEachFace(
        static_cast<int>(unread.size()), [&](int k) { return unread[static_cast<std::size_t>(k)]; },
        scratches, nullptr,
        [&](PtexFaceId face, FaceScratch& w) {
          const auto f = static_cast<std::size_t>(face.value);
          DISPEX_RETURN_IF_ERROR(faces.previous->ReadTexels(f, faces.kept[f]));
          return TakeFace(f, inputs, settings, faces, w, view);
        });
  };
  const Status raised = RaiseEdgeResolutions(
      inputs, settings, view, StepsBefore(inputs, faces), load,
      [&](std::span<const int> redo, std::span<const std::array<int, 2>> least, EdgeRoundsMap&) {
        for (int f : redo) ReturnFace(static_cast<std::size_t>(f), inputs, settings, faces, view);
        DISPEX_RETURN_IF_ERROR(ReprocessFaces(inputs, settings, redo, least, faces));
        return take(redo);
      },
      faces.first_round_edge_steps, report);
  DISPEX_RETURN_IF_ERROR(raised);
  for (std::size_t f = 0; f < n; ++f) ReturnFace(f, inputs, settings, faces, view);
  return Status::Ok();
}

void ListDiscontinuousFaces(const ExtractInputs& inputs, const ProcessedFaces& faces,
                            ExtractReport& report) {
  const std::size_t n = faces.stats.size();
  std::vector<std::uint8_t> holes(n), discontinuous(n);
  report.edges.discontinuous_faces.clear();
  for (std::size_t f = 0; f < n; ++f) {
    holes[f] = inputs.surface.is_hole(PtexFaceId(static_cast<int>(f)));
    discontinuous[f] = !holes[f] && Discontinuous(faces.stats[f]);
    if (discontinuous[f]) report.edges.discontinuous_faces.push_back(static_cast<std::int32_t>(f));
  }
  report.edges.discontinuous =
      static_cast<std::int64_t>(CountEdgesTouching(inputs.faces, discontinuous, holes));
}

}  // namespace dispex::extract
