// What each face's first pass produced (its statistics and edge means), as stored in a map's
// meta data so that an incremental extraction can re-use the face without re-extracting it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/hash128.h"
#include "dispex/ptex.h"
#include "dispex/status.h"
#include "extract/face_pipeline.h"

namespace dispex::extract {

inline constexpr const char* kFaceKeysMetaKey = "dispex:face_keys";
inline constexpr const char* kFaceRecordsMetaKey = "dispex:face_records_v1";
inline constexpr const char* kInputsKeyMetaKey = "dispex:inputs_key";
inline constexpr const char* kVectorFaceRecordsMetaKey = "dispex:vector_face_records_v1";
// How the map's faces are encoded (PtexEncodingName): a face of a map encoded as the new one
// is copied into it still encoded.
inline constexpr const char* kFaceEncodingMetaKey = "dispex:face_encoding";
// Per face, the first round's steps of its edges when the watertight edges were made
// (PtexEdgeStepsByFace): an incremental run measures again only the edges near faces that
// changed.
inline constexpr const char* kFirstRoundEdgeStepsMetaKey = "dispex:first_round_edge_steps";
// The hash of the map's face data as it was written (PtexWriterOptions::level_data_hash_key).
inline constexpr const char* kLevelDataHashMetaKey = "dispex:level_data_hash";

// A map's face data checked before its faces are re-used: by the hash its writer recorded when
// the bytes still have it (they are those dispex wrote), else by inflating every block
// (PtexFile::Validate).
Status CheckMapFaceData(const PtexFile& file);

struct FaceRecord {
  FaceStats stats;
  EdgeMeans edge_means;
};

// The meta data key of a map of `channels` channels' records.
inline const char* FaceRecordsMetaKey(int channels) {
  return channels == 3 ? kVectorFaceRecordsMetaKey : kFaceRecordsMetaKey;
}

// Little-endian, fixed size per face. A scalar map's record holds every field of FaceStats
// and the edge means; a vector map's (3 channels) the fields a vector face fills: samples,
// min and max (of D . N), tangential_max, length_max, sum_squares, spectral, ulog2, vlog2.
std::vector<std::int8_t> EncodeFaceRecords(std::span<const FaceStats> stats,
                                           std::span<const EdgeMeans> edge_means, int channels);
// nullopt when the bytes do not hold `num_faces` records.
std::optional<std::vector<FaceRecord>> DecodeFaceRecords(std::span<const std::uint8_t> bytes,
                                                         std::size_t num_faces, int channels);

std::vector<std::int8_t> EncodeFaceKeys(std::span<const Hash128> keys);
std::optional<std::vector<Hash128>> DecodeFaceKeys(std::span<const std::uint8_t> bytes,
                                                   std::size_t num_faces);

}  // namespace dispex::extract
