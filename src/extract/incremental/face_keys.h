// What each Ptex face's first pass (ProcessFace with no least resolution) is made from, as a
// key: incremental extraction re-uses a face whose key is unchanged.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "extract/box.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"

namespace dispex::extract {

// Everything a mesh as read holds that can change a map: positions, faces, subdivision tags
// (not its groups, UVs or file name).
Hash128 MeshContentKey(const Mesh& mesh);

// Adds to `h` what a face that reads a grid of sculpt vertices (interpolated or vector maps) is
// made from: the grid size m and the vertices' positions in order (the (m + 1)^2 of its grid,
// and for interpolated faces its apron's, FaceFieldVertices). `scratch`: reused storage.
void AddGridKey(Hasher& h, const Mesh& sculpt, int m, std::span<const VertexId> grid,
                std::vector<Float3>& scratch);

// Adds to `h` what face `f` of an interpolated map reads besides its own patch
// (AddFacePatchKey): its grid and apron vertices' positions (AddGridKey, FaceFieldVertices)
// and the limit patches of the faces its apron lies on. `ids`, `faces`, `points`: reused
// storage.
void AddFieldKey(Hasher& h, const ExtractInputs& inputs, std::span<const BaseFacePatch> patches,
                 int f, std::vector<VertexId>& ids, std::vector<int>& faces,
                 std::vector<Float3>& points);

// The settings every face's first pass reads (distances, spectral options, holes, data type,
// watertight mode, sampling caps) and the version of the pipeline.
Hash128 SettingsKey(const ExtractSettings& settings);

// Adds to `h` what every kind of map's key of Ptex face `f` holds besides its settings and
// its sculpt: the face's limit patch (`patches`: BaseFacePatches), its sub-face, whether it is
// a hole, and its planned samples.
void AddFacePatchKey(Hasher& h, const LimitSurface& surface, std::span<const BaseFacePatch> patches,
                     const ExtractSettings& settings, std::size_t f);

// Per Ptex face: SettingsKey and the tracer's scale (TracerStats::scale), the face's limit patch
// (BaseFacePatches) and sub-face, its planned samples, and every sculpt face its rays can reach:
// those whose bounding box meets the face's reach box (the patch's box grown by the longest search
// distance and a margin), as an order-free sum of each sculpt face's key (its corners' positions,
// in order). Interpolated (ExtractSettings::interpolate), the sculpt part is the face's grid of
// sculpt vertices and its apron (the key of AddFieldKey, ComputeFieldKeys, which with a
// `cache_folder` keeps them there for the next run), reach_faces its cells, and there are no
// reach boxes.
// The keys do not depend on the thread count.

struct FaceKeys {
  std::vector<Hash128> keys;     // per Ptex face
  std::vector<Box> reach_boxes;  // per Ptex face: where its rays can go (empty: no rays)
  // Per Ptex face, where the rays of its first search can go (the search distance), when the
  // retry search reaches farther; empty otherwise.
  std::vector<Box> first_search_boxes;
  float sculpt_half_extent = 0;  // the largest half-size of a sculpt face's bounding box
  // Per Ptex face: the sculpt faces in the grid cells its key sums (about those its rays reach).
  std::vector<std::int64_t> reach_faces;
  // Interpolated: the faces whose field key the cache folder kept (FieldKeys::kept; -1: none).
  std::int64_t fields_kept = -1;
};
FaceKeys ComputeFaceKeys(const ExtractInputs& inputs, const ExtractSettings& settings,
                         const std::string& cache_folder);

// The sculpt faces the rays of the flagged Ptex faces can reach (a superset: those ComputeFaceKeys
// sums for them), their vertices renumbered in ascending order: enough to trace those faces
// exactly as against the whole sculpt. `first_search`: those their first search's rays can
// reach (keys.first_search_boxes; the whole reach when there are none).
Mesh SculptWithinReach(const ExtractInputs& inputs, const FaceKeys& keys,
                       std::span<const std::uint8_t> faces, bool first_search = false);

// `faces` cut, in their order, into runs whose sculpt within reach -- of the run's faces and
// `rings` rings of Ptex faces around them, in SculptWithinReach's cells -- holds at most
// `part_faces` sculpt faces (a face whose own reach holds more is a run alone: the largest
// such is reported).
struct ReachRuns {
  std::vector<std::vector<int>> runs;
  std::int64_t largest_single = 0;  // the sculpt faces within reach of a run's first face alone
  int largest_face = -1;            // that face
};
ReachRuns RunsWithinReach(const ExtractInputs& inputs, const FaceKeys& keys,
                          std::span<const int> faces, int rings, std::size_t part_faces);

// The sculpt faces flagged in `keep` (one flag per sculpt face), in their order, their vertices
// renumbered in ascending order.
Mesh SculptPart(const Mesh& sculpt, std::span<const std::uint8_t> keep);

}  // namespace dispex::extract
