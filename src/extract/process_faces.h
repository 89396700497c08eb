// The per-face stage of an extraction: ProcessFace for every Ptex face in parallel, each face
// written to the map as soon as it is done, so its buffers live only while it is processed.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "dispex/ptex.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"
#include "extract/face_pipeline.h"

namespace dispex::extract {

// The worker threads' counters, summed.
struct WorkerTotals {
  std::uint64_t rays_cast = 0;
  std::int64_t fallback_normals = 0;
  double cpu_limit = 0, cpu_trace = 0, cpu_spectral = 0, cpu_write = 0;
};

// A face's texels held back from the writer until its neighbours are final (watertight edges).
struct KeptFace {
  std::int8_t ulog2 = 0, vlog2 = 0;
  bool kept = false;          // false: a face that missed entirely (written when filled)
  bool unread = false;        // copied, its texels still in ProcessedFaces::previous
  std::vector<float> texels;  // ures x vres, or one value for a constant face (per channel)
};

// Texels rounded to what a map of `type` stores (half: to the nearest half; float as is).
void RoundToDataType(PtexDataType type, std::span<float> texels);

class PreviousMap;

struct ProcessedFaces {
  int channels = 1;                   // of the map
  std::vector<FaceStats> stats;       // per Ptex face
  std::vector<FaceStats> first_pass;  // per Ptex face, before edges raised any (the map keeps it)
  std::vector<EdgeMeans> edge_means;  // per Ptex face
  std::vector<KeptFace> kept;         // per Ptex face, when settings.watertight is on
  WorkerTotals workers;
  std::vector<std::uint8_t> copied;  // per Ptex face: its first pass taken from the previous map
  std::vector<std::uint8_t> redone;  // per Ptex face: extracted again by the edge pass
  std::int64_t faces_copied = 0;     // taken from the previous map
  // The map they were taken from: a kept face's texels are read from it only when the edges
  // measure them (KeptFace::unread), and a copied face the edges did not redo is written still
  // encoded where that map encoded it as the new map does (PreviousMap::EncodedAs).
  const PreviousMap* previous = nullptr;
  // With watertight edges, per face the first round's steps of its edges
  // (PtexEdgeStepsByFace), which the map keeps for the next incremental run.
  std::vector<double> first_round_edge_steps;
  // Through the mapping: samples it left undecided and the faces they were in, over every face
  // extracted (the edge pass's too).
  std::int64_t fallback_samples = 0, fallback_faces = 0;
};

// Where a Ptex face's texels come from in this run (PlanFaces decides it): its first pass run
// here, copied from the previous map or the parts, another shard's (not in this part), or a
// hole (written as 0).
enum class FaceSource : std::uint8_t { kRun, kCopy, kElsewhere, kHole };

// Every face as `sources` (per Ptex face, PlanFaces') says: through ProcessFace in parallel,
// its first pass copied from `previous`, or left out. Each face is written to the map as soon
// as it is done, or, with watertight edges, kept for MatchEdges and WriteKeptFaces. Through the
// mapping, faces with samples it leaves undecided wait until every face has been through it;
// then one tracer is built for them (TraceFallback) and they are processed again. On an error,
// the error of the lowest face id (whatever the scheduling), or the cancellation.
StatusOr<ProcessedFaces> ProcessFaces(ExtractInputs& inputs, const ExtractSettings& settings,
                                      const PreviousMap* previous,
                                      std::span<const FaceSource> sources, bool progress,
                                      ProgressCounter* counter, PtexWriter& writer);

// Runs ProcessFace again for `faces` with their least resolutions (`least_log2`, per Ptex
// face), replacing their kept texels and statistics; the rays cast count in the totals. Swaps
// in the whole sculpt's tracer first when the current one does not hold their reach
// (EnsureTraced), or traces them in runs when the sculpt is in parts (ForEachTracedRun);
// through the mapping, a tracer only for the faces that need one, afterwards (TraceFallback).
Status ReprocessFaces(ExtractInputs& inputs, const ExtractSettings& settings,
                      std::span<const int> faces, std::span<const std::array<int, 2>> least_log2,
                      ProcessedFaces& processed);

// Writes every kept face.
Status WriteKeptFaces(PtexWriter& writer, const ExtractInputs& inputs,
                      const ProcessedFaces& processed);

// The map's record of `face` (numbering, adjacency) at 2^ulog2 x 2^vlog2 texels.
PtexFaceInfo FaceInfo(const ExtractInputs& inputs, PtexFaceId face, int ulog2, int vlog2);

// Writes a constant face with the face table's adjacency.
Status WriteConstantFace(PtexWriter& writer, const ExtractInputs& inputs, PtexFaceId face,
                         float value);

}  // namespace dispex::extract
