// One Ptex face through the pipeline: limit points and normals on its grid of texel centres
// -> rays along +-n (and a longer second search for the samples that missed) -> signed
// distances -> holes -> the DCT resolution; interpolated (ExtractSettings::interpolate), the
// signed distances are the sculpt's vertex heights over the limit surface interpolated at the
// texel centres instead (vertex_displacements.h); a vector map's face reads D through the
// correspondence (vector_faces.h). ProcessFace can be run for any face, any number of times,
// on any thread that has its own FaceScratch; it does not write the map.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dispex/spectral.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/hole_fill.h"
#include "extract/mapping/mapping_trace.h"
#include "extract/mapping/vertex_displacements.h"

namespace dispex::extract {

// What a face contributes to the report, kept for every face until the totals.
struct FaceStats {
  std::int64_t samples = 0;
  std::int32_t misses = 0;
  std::int32_t recovered = 0;  // misses found by the longer search
  std::int32_t filled = 0;     // misses filled within the face
  std::int32_t hits_negative = 0;
  std::int32_t hits_opposed = 0;
  bool all_missed = false;  // no value at all: filled from the neighbours later
  float min = 0, max = 0;   // of the displacement (a vector map: of D . N)
  double sum_squares = 0;   // of the displacement (a vector map: of |D|)
  // A vector map's: the largest |D - (D . N) N| and |D|.
  double tangential_max = 0, length_max = 0;
  SpectralFaceStats spectral;
  std::int8_t ulog2 = 0, vlog2 = 0;
  std::int64_t rays = 0;              // cast for this face
  std::int32_t fallback_normals = 0;  // LimitEvaluatorStats::fallback_normals of this face
};

struct FaceResult {
  enum class Kind : std::uint8_t {
    kHole,       // no limit surface: written as constant 0
    kAllMissed,  // every ray missed under HolePolicy::kFill: nothing to write yet
    kAnalysed,   // `analysed` holds the face to write
  };
  Kind kind = Kind::kHole;
  // Through the mapping (ExtractInputs::mapping): samples it left undecided were traced by the
  // BVH; with no tracer holding this face, nothing else is set and the face must be processed
  // again once one does (TraceFallback).
  std::int32_t fallback_samples = 0;
  bool needs_tracer = false;
  FaceStats stats;
  EdgeMeans edge_means;  // what a neighbour that missed entirely is filled from (scalar maps)
  // kAnalysed: the face at 2^ulog2 x 2^vlog2 texels of the map's channels, interleaved (one
  // texel: a constant face). They live in the scratch until its next ProcessFace.
  int ulog2 = 0, vlog2 = 0;
  std::span<const float> texels;
};

// Per-thread buffers and evaluators, reused across faces, and the thread's counters.
struct FaceScratch {
  explicit FaceScratch(const LimitSurface& surface) : evaluator(surface) {}
  LimitEvaluator evaluator;
  SpectralAnalyzer analyzer;
  SpectralVectorAnalyzer vector_analyzer;
  std::array<float, 3> constant{};  // a constant face's texel
  std::vector<float> positions, normals, t, values;
  // Vector maps: the limit frame's derivatives, D in the map's space, the texels as stored.
  std::vector<float> du, dv, channels, vector_texels;
  std::vector<std::uint8_t> flags, valid;
  std::vector<Float3> retry_origins, retry_normals;  // missed samples, for the longer search
  std::vector<float> retry_t;
  std::vector<std::uint8_t> retry_flags;
  std::vector<std::int32_t> retry_index;
  // Through the mapping: its neighbourhoods, its second search, the undecided samples.
  MappingScratch mapping;
  MappingCounters mapping_counters;
  std::vector<std::uint8_t> undecided, mapped_flags, fallback_flags;
  std::vector<std::int32_t> mapped_index;
  std::vector<float> mapped_t, fallback_t;
  std::vector<Float3> fallback_origins, fallback_normals;
  // Interpolated (ExtractSettings::interpolate): the face's grid of vertex displacements.
  GridDisplacements grid;
  PullPushScratch pull_push;
  TraceCounters counters;
  double cpu_limit = 0, cpu_trace = 0, cpu_spectral = 0, cpu_write = 0;  // this thread's seconds
};

// Rays along +-n from each origin under settings.query; with a retry distance (and `retry`), the
// samples that missed are searched again that far. Returns how many the second search found.
std::int32_t TraceRays(const Tracer& tracer, const ExtractSettings& settings,
                       std::span<const Float3> origins, std::span<const Float3> normals,
                       std::span<float> t, std::span<std::uint8_t> flags, FaceScratch& w,
                       bool retry = true);

// One face of the map: a scalar map's (below), or a vector map's (settings.vector:
// ProcessVectorFace, vector_faces.h).
// Fails on an evaluation or analysis error, or on a miss under HolePolicy::kFail.
// `least_log2`: the least resolution (log2 of u and v texels) the face may get, e.g. for its
// neighbours to meet it without a step (SpectralOptions::min_ulog2); beyond the planned
// samples per side the face is sampled that finely.
StatusOr<FaceResult> ProcessFace(PtexFaceId face, const ExtractInputs& inputs,
                                 const ExtractSettings& settings, FaceScratch& scratch,
                                 std::array<int, 2> least_log2 = {0, 0});

}  // namespace dispex::extract
