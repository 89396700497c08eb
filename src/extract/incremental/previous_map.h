// The map an earlier extraction left at the output path, read for what an incremental
// extraction can re-use: its inputs key, and per face the key, the first-pass record and the
// texels.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "dispex/ptex.h"
#include "extract/incremental/face_records.h"
#include "extract/incremental/shard_parts.h"
#include "extract/process_faces.h"

namespace dispex::extract {

class PreviousMap {
 public:
  // Never fails: a missing file re-uses nothing and leaves notice() empty; a map that cannot be
  // read, was not written by this version of dispex, has another number of faces or is not of
  // the kind asked for (a scalar map, or a vector map when `vector`) re-uses nothing, and
  // notice() says why in one line.
  static PreviousMap Open(const std::string& path, std::size_t num_faces, bool vector = false);
  // The parts of a sharded extraction (CheckShardParts' order) as one map: each face as the part
  // of its shard holds it, a part holding the faces order[begin..end) (ShardOrder).
  static PreviousMap FromParts(std::vector<ShardPart> parts, std::span<const std::int32_t> order);

  bool usable() const { return !files_.empty(); }
  // Inflates every face's data (Open checks the structure only): corrupt data makes the map
  // unusable, with a notice, instead of failing the extraction when a face is copied.
  void CheckFaceData();
  const std::string& notice() const { return notice_; }
  // The previous map's meta data string for `key` ("" when absent or unusable).
  std::string MetaString(const std::string& key) const;

  // True when face f's key is `key` and its stored texels are what its first pass wrote (the
  // watertight edges did not raise its resolution afterwards).
  bool Reusable(std::size_t f, const Hash128& key) const;
  // True when face f's key is `key`, whatever its stored texels: what else the run before made
  // of the face (its UV-space texels) holds.
  bool SameKey(std::size_t f, const Hash128& key) const {
    return !files_.empty() && keys_[f] == key;
  }
  const FaceRecord& record(std::size_t f) const { return records_[f]; }
  // The face's texels as KeptFace holds them (one value per channel for a constant face).
  Status ReadTexels(std::size_t f, KeptFace& out) const;
  // The face kept with its resolution, its texels left in the map (KeptFace::unread).
  void KeepUnread(std::size_t f, KeptFace& out) const;
  // Per face, the first round's steps of its edges when the map's watertight edges were made
  // (PtexEdgeStepsByFace), for a map whose faces meet as `faces` say; empty when it has none.
  std::span<const double> FirstRoundEdgeSteps(std::span<const PtexFaceInfo> faces) const;
  // Whether face f is stored as a writer of `encoding` (PtexEncodingName) would store its
  // texels, so that ReadEncoded's bytes can go to that writer as they are.
  bool EncodedAs(std::size_t f, const std::string& encoding) const {
    return !files_.empty() && encodings_[part_of_.empty() ? 0 : part_of_[f]] == encoding;
  }
  Status ReadEncoded(std::size_t f, PtexEncodedFace& out) const {
    return file(f).ReadEncodedFace(PtexFaceId(static_cast<int>(f)), out);
  }

 private:
  void AddFile(PtexFile file);
  const PtexFile& file(std::size_t f) const { return files_[part_of_.empty() ? 0 : part_of_[f]]; }

  std::vector<PtexFile> files_;
  std::vector<std::string> encodings_;  // per file, kFaceEncodingMetaKey's value ("" if none)
  std::vector<std::uint32_t> part_of_;  // per face, its file; empty: one file
  std::vector<Hash128> keys_;
  std::vector<FaceRecord> records_;
  std::vector<double> first_round_edge_steps_;
  std::string notice_;
};

}  // namespace dispex::extract
