// The first stage of an extraction: everything read or built from the input files before
// any setting is resolved.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "dispex/correspondence.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/mapping/mapping_trace.h"
#include "extract/mapping/vertex_displacements.h"
#include "extract/memory_check.h"

namespace dispex::extract {

struct FaceKeys;

struct ExtractInputs {
  Mesh base;
  Mesh sculpt;
  LimitSurface surface;              // of the base
  std::vector<PtexFaceInfo> faces;   // the map's face table, from `surface`
  std::unique_ptr<Tracer> tracer{};  // the sculpt's BVH; reads the sculpt's arrays
  // An incremental run may trace against only the part of the sculpt that the faces it
  // extracts can reach (BuildLocalTracer): `traced` flags those Ptex faces, and EnsureTraced
  // swaps in the whole sculpt's tracer before any other face is extracted. Empty: the tracer
  // holds the whole sculpt.
  std::vector<std::uint8_t> traced{};
  Mesh traced_part{};    // the part of the sculpt that tracer reads, when it reads a part
  bool widened = false;  // EnsureTraced replaced a part's tracer by a larger one
  // The part holds the sculpt within reach of the first search only (the search distance, not
  // the retry's: FaceKeys::first_search_boxes): a face with samples that miss it waits
  // (FaceResult::needs_tracer) for WidenToRetryReach.
  bool first_search_only = false;
  bool widened_for_retry = false;  // WidenToRetryReach did
  TracerOptions tracer_options{};
  // The sculpt as the base refined (ExtractMethod, extract_mapping.h): samples are traced
  // through it, and `tracer` is built only for those it leaves undecided (TraceFallback), over
  // the sculpt within reach of their faces (`face_keys`, the run's).
  std::unique_ptr<SculptMapping> mapping{};
  // With `mapping`: the sculpt's vertex displacements are interpolated (vertex_displacements.h)
  // instead of traced; no tracer, no search distance.
  bool interpolate = false;
  // A vector map's sculpt as the base refined (MatchVectorSculpt, vector_faces.h): every face
  // reads the sculpt through it.
  std::unique_ptr<SculptCorrespondence> correspondence{};
  // With `interpolate`: the grids the displacements are read from, over `mapping` or, for
  // vector maps, `correspondence`.
  std::unique_ptr<GridSource> grids{};
  const FaceKeys* face_keys = nullptr;
  double fallback_bvh_seconds = 0;  // building those tracers
  // The memory limit the plan keeps within (bytes; 0: none), the estimate it is made from, and
  // the runs the faces are traced in when the whole sculpt's BVH does not fit (ForEachTracedRun).
  std::uint64_t memory_limit = 0;
  MemoryNeed memory;
  int sculpt_parts = 1;
  std::size_t part_faces = 0;  // with sculpt_parts > 1: the sculpt faces a run's BVH may hold
  bool compact_bvh = false;    // the BVHs built compact at medium quality (SculptParts)
  // Without a tracer of the whole sculpt: the parts its automatic search distance is estimated
  // in (NearestHitsInParts), at least sculpt_parts.
  int estimate_parts = 1;
  // An incremental run's file of the automatic search distance's rays (ray_cache.h): read to
  // update the estimate when there is no tracer of the whole sculpt, written after it ("": none).
  std::string ray_cache_path{};
  double run_bvh_seconds = 0;  // building the runs' BVHs (TraceRun) ...
  int runs_traced = 0;         // ... of this many runs
  std::string run_backend{};   // their TracerStats::backend
};

// Reads the sculpt while the base is read and its limit surface built, fingerprints both
// meshes (MeshContentKey), and checks the estimated memory against `memory_limit` (bytes; 0:
// no check) before reading and again once the sculpt's size is known. Fills the report's
// input counts, fingerprints, timings and warnings. The tracer is left to BuildTracer.
StatusOr<ExtractInputs> ReadInputs(const ExtractOptions& options, std::uint64_t memory_limit,
                                   ExtractReport& report);

// The same from meshes already read (the shapes of an asset): fingerprints, limit surface,
// counts, memory check. Read times stay 0.
StatusOr<ExtractInputs> InputsFromMeshes(const ExtractOptions& options, Mesh base, Mesh sculpt,
                                         std::uint64_t memory_limit, ExtractReport& report);

// The power of two at or above the base's largest |coordinate|: the tracer's scale
// (TracerOptions::scale), the magnitude of the ray origins, and independent of the sculpt.
float TracerScale(const Mesh& base);

// The tracer's options from the extraction's (quality, ISA) and the base (TracerScale).
void SetTracerOptions(const ExtractOptions& options, ExtractInputs& inputs);

// The sculpt's BVH.
Status BuildTracer(const ExtractOptions& options, ExtractInputs& inputs, ExtractReport& report);

// The BVH of `part` (sculpt faces, BuildLocalTracer's choice; kept in `inputs` for the tracer
// to read) for the Ptex faces `traced` flags.
Status BuildPartTracer(Mesh part, std::vector<std::uint8_t> traced, ExtractInputs& inputs,
                       ExtractReport& report);

// Faces the edge pass re-extracts lie near those whose first pass runs (it raises a ring of
// faces per round, in at most 8 rounds, and most raises are beside the faces that changed):
// a local tracer covers this many rings around them.
inline constexpr int kLocalRings = 2;

// Flags in `traced` the faces `rings` rings of neighbours around `ring` (faces already flagged).
void AddRings(const std::vector<PtexFaceInfo>& faces, int rings, std::vector<int> ring,
              std::vector<std::uint8_t>& traced);

// Before `faces` are extracted: when the tracer holds a part of the sculpt that their rays may
// reach beyond, a tracer of the part within reach of them, kLocalRings around them and the
// faces it already served (the whole sculpt's when that is more than half the faces).
Status EnsureTraced(ExtractInputs& inputs, std::span<const int> faces);

// A part's tracer that holds the first search's reach only (first_search_only) replaced by one of
// the whole reach of the faces it serves, so that their samples can search the retry distance.
Status WidenToRetryReach(ExtractInputs& inputs);

// The faces' runs when the sculpt is traced in parts (ExtractInputs::sculpt_parts): `faces` in
// shard order (ShardOrder, so that a run's faces lie together), cut where the sculpt within
// reach of a run's faces and their rings would pass part_faces (RunsWithinReach). One run of
// `faces` otherwise.
// A kOverBudget error when one face's reach alone passes part_faces.
StatusOr<std::vector<std::vector<int>>> TracedRuns(const ExtractInputs& inputs,
                                                   std::span<const int> faces);

// Before a run of TracedRuns is extracted, with the sculpt in parts: the BVH of the sculpt
// within reach of exactly those faces, the previous run's freed first. `run` empty: frees it.
// Otherwise EnsureTraced.
Status TraceRun(ExtractInputs& inputs, std::span<const int> run);

// Calls `work(run)` for each run of TracedRuns(faces) once TraceRun has built its BVH; the last
// BVH of a sculpt in parts is freed afterwards. The hits, so the map, are those of the whole
// sculpt's BVH: a run's part holds every sculpt face its rays can reach.
template <typename Work>
Status ForEachTracedRun(ExtractInputs& inputs, std::span<const int> faces, Work work) {
  DISPEX_ASSIGN_OR_RETURN(const std::vector<std::vector<int>> runs, TracedRuns(inputs, faces));
  if (inputs.sculpt_parts > 1) inputs.runs_traced += static_cast<int>(runs.size());
  for (const std::vector<int>& run : runs) {
    DISPEX_RETURN_IF_ERROR(TraceRun(inputs, run));
    DISPEX_RETURN_IF_ERROR(work(std::span<const int>(run)));
    if (inputs.sculpt_parts > 1 && inputs.tracer) DISPEX_RETURN_IF_ERROR(inputs.tracer->status());
  }
  if (inputs.sculpt_parts > 1) return TraceRun(inputs, {});
  return Status::Ok();
}

// The long rays of the automatic search distance (EstimateSearchDistance) against the sculpt
// in `parts` parts, one BVH at a time: per query, |t| of its nearest hit, or infinity (and its
// side, LowerNearestHits's, when `side` is given). The same whatever `parts`.
StatusOr<std::vector<float>> NearestHitsInParts(const ExtractInputs& inputs, int parts,
                                                std::span<const Float3> origins,
                                                std::span<const Float3> normals, float length,
                                                std::span<std::int8_t> side = {});

// Frees the sculpt's arrays (its source stays) once a part's tracer holds all a run needs: a
// shard's, whose faces' keys, settings and BVH are made. EnsureTraced must not be called then.
void ReleaseSculpt(ExtractInputs& inputs);

}  // namespace dispex::extract
