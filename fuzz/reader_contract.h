// What the readers promise for any bytes, checked from the outside: the contracts that
// include/dispex/mesh.h (ReadMesh and the parsers) and include/dispex/ptex.h (PtexFile) state
// for every input. The fuzz targets (fuzz/*_fuzzer.cpp) abort on a broken promise, so
// libFuzzer records the input; the regression test (tests/fuzz/) runs the same checks over
// the saved inputs and the seed corpora with gcc and the sanitizers of the normal build.
//
// Every function returns "" when the contract holds, else one line naming the first
// violation. None of them trusts the reader: they only read what its public API exposes.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/status.h"

namespace dispex::fuzz {

// The failed-Status contract shared by every reader: a non-empty message on one printable
// line (no control bytes: a '\n', '\r' or terminal escape copied from the file breaks logs and
// terminals) that starts with "<name>:".
std::string CheckErrorMessage(const Status& status, const std::string& name);

// ParseObj / ParsePly result for bytes named `name`. On success: at least one face, every
// face has >= 3 corners, face_offsets starts at 0, grows and ends at face_indices.size(),
// every index in [0, num_vertices()), every position finite, positions.capacity() >
// positions.size(), source == name; face_groups empty or one valid group id per face, every
// listed group owning a face; tag vertex and face ids in range, sharpness finite and >= 0;
// UVs absent, or one in-range UV index per corner and finite UVs (Mesh::uvs).
// A successful mesh is also run through ValidateMesh, ComputeBounds and MedianEdgeLength
// (their results must be consistent with the mesh). On failure: CheckErrorMessage.
std::string CheckMeshResult(const StatusOr<Mesh>& result, const std::string& name);

// The success half of CheckMeshResult, for a mesh in hand (tests that break one promise by
// hand; a copy into a StatusOr would lose the spare capacity the contract asks for).
std::string CheckMesh(const Mesh& mesh, const std::string& name);

// "" when `a` and `b` are the same result: both failed with the same message, or both
// succeeded with bit-identical meshes (positions, faces, groups, tags, UVs). The OBJ reader
// promises this for any ReadOptions (chunk size, threads).
std::string CompareMeshResults(const StatusOr<Mesh>& a, const StatusOr<Mesh>& b);

// Limits that keep one Ptex input within a fuzzer's time and memory: the reader's own
// per-read limit, and how many values all reads of one file may decode in total (faces past
// the budget are not read; the reader is not at fault for a file that describes more data
// than a harness wants to look at).
struct PtexExerciseLimits {
  std::size_t max_values_per_read = std::size_t{1} << 20;
  std::size_t value_budget = std::size_t{1} << 23;
};

// Parses `bytes` with ParsePtex and, for a file that opens, reads everything the API
// offers: the header, every face record, every face at every stored level (as floats and
// raw), its constant value and block info, Sample at texel centres, corners and midpoints of
// the first and last channel, Validate, and every meta data item in every type. Checks that sizes
// agree with the resolutions, that a read over max_values_per_read fails and every other read of a
// constant face succeeds, that a quad face's Sample at a texel centre returns that texel, that
// Sample is NaN exactly where the face cannot be decoded, that Validate fails exactly when a
// face read failed, and that every failed Status keeps CheckErrorMessage.
std::string ExercisePtex(std::string_view bytes, const std::string& name,
                         const PtexExerciseLimits& limits = {});

}  // namespace dispex::fuzz
