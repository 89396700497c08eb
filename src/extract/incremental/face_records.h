// What each face's first pass produced (its statistics and edge means), as stored in a map's
// meta data so that an incremental extraction can re-use the face without re-extracting it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/hash128.h"
#include "extract/face_pipeline.h"

namespace dispex::extract {

inline constexpr const char* kFaceKeysMetaKey = "dispex:face_keys";
inline constexpr const char* kFaceRecordsMetaKey = "dispex:face_records_v1";
inline constexpr const char* kInputsKeyMetaKey = "dispex:inputs_key";
inline constexpr const char* kVectorFaceRecordsMetaKey = "dispex:vector_face_records_v1";

struct FaceRecord {
  FaceStats stats;
  EdgeMeans edge_means;
};

// Little-endian, fixed size per face.
std::vector<std::int8_t> EncodeFaceRecords(std::span<const FaceStats> stats,
                                           std::span<const EdgeMeans> edge_means);
// nullopt when the bytes do not hold `num_faces` records.
std::optional<std::vector<FaceRecord>> DecodeFaceRecords(std::span<const std::uint8_t> bytes,
                                                         std::size_t num_faces);

// What one face of a vector map contributes to the report.
struct VectorFaceStats {
  std::int64_t samples = 0;
  float normal_min = 0, normal_max = 0;  // D . N
  double tangential_max = 0;             // |D - (D . N) N|
  double length_max = 0;                 // |D|
  double sum_squares = 0;                // of |D|
  SpectralFaceStats spectral;
  std::int8_t ulog2 = 0, vlog2 = 0;
};

std::vector<std::int8_t> EncodeVectorFaceRecords(std::span<const VectorFaceStats> stats);
std::optional<std::vector<VectorFaceStats>> DecodeVectorFaceRecords(
    std::span<const std::uint8_t> bytes, std::size_t num_faces);

std::vector<std::int8_t> EncodeFaceKeys(std::span<const Hash128> keys);
std::optional<std::vector<Hash128>> DecodeFaceKeys(std::span<const std::uint8_t> bytes,
                                                   std::size_t num_faces);

}  // namespace dispex::extract
