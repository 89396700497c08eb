#include "extract/incremental/face_records.h"

#include <cstring>
#include <type_traits>

namespace dispex::extract {

namespace {

// Writes or reads the same fields in the same order: one function for both directions.
template <class Io>
void Fields(Io& io, SpectralFaceStats& p) {
  io(p.texels_before), io(p.texels_after), io(p.bound), io(p.measured_error);
  io(p.bound_ulog2), io(p.bound_vlog2), io(p.step_ups), io(p.constant), io(p.edge_error);
  io(p.edge_limited);
}

template <class Io>
void Fields(Io& io, FaceRecord& r) {
  FaceStats& s = r.stats;
  io(s.samples), io(s.misses), io(s.recovered), io(s.filled), io(s.hits_negative);
  io(s.hits_opposed), io(s.all_missed), io(s.min), io(s.max), io(s.sum_squares);
  Fields(io, s.spectral);
  io(s.ulog2), io(s.vlog2), io(s.rays), io(s.fallback_normals);
  for (float& m : r.edge_means.mean) io(m);
}

// A vector map's record: the fields a vector face fills.
struct VectorRecord {
  FaceStats stats;
};

template <class Io>
void Fields(Io& io, VectorRecord& r) {
  FaceStats& s = r.stats;
  io(s.samples), io(s.min), io(s.max), io(s.tangential_max), io(s.length_max);
  io(s.sum_squares);
  Fields(io, s.spectral);
  io(s.ulog2), io(s.vlog2);
}

struct Writer {
  std::vector<std::int8_t>& out;
  template <class T>
  void operator()(const T& value) {
    static_assert(std::is_arithmetic_v<T>);
    const auto* p = reinterpret_cast<const std::int8_t*>(&value);
    out.insert(out.end(), p, p + sizeof(T));
  }
};

struct Reader {
  const std::uint8_t* at;
  template <class T>
  void operator()(T& value) {
    static_assert(std::is_arithmetic_v<T>);
    if constexpr (std::is_same_v<T, bool>) {
      value = *at != 0;
    } else {
      std::memcpy(&value, at, sizeof(T));
    }
    at += sizeof(T);
  }
};

// Values a map from another source could hold that index arrays or size buffers later.
bool Plausible(const SpectralFaceStats& p, std::int64_t samples, int ulog2, int vlog2) {
  auto log2_ok = [](int v) { return v >= 0 && v <= 15; };
  return log2_ok(ulog2) && log2_ok(vlog2) && log2_ok(p.bound_ulog2) && log2_ok(p.bound_vlog2) &&
         samples >= 0 && p.step_ups >= 0 && p.texels_before >= 0 && p.texels_after >= 0;
}
bool Plausible(const FaceRecord& r) {
  const FaceStats& s = r.stats;
  return Plausible(s.spectral, s.samples, s.ulog2, s.vlog2) && s.misses >= 0 && s.rays >= 0;
}
bool Plausible(const VectorRecord& r) {
  const FaceStats& s = r.stats;
  return Plausible(s.spectral, s.samples, s.ulog2, s.vlog2);
}

template <class Record>
std::size_t RecordSize() {
  std::vector<std::int8_t> bytes;
  Writer w{bytes};
  Record r;
  Fields(w, r);
  return bytes.size();
}

template <class Record>
std::optional<std::vector<Record>> Decode(std::span<const std::uint8_t> bytes,
                                          std::size_t num_faces) {
  if (bytes.size() != num_faces * RecordSize<Record>()) return std::nullopt;
  std::vector<Record> records(num_faces);
  Reader r{bytes.data()};
  for (Record& record : records) {
    Fields(r, record);
    if (!Plausible(record)) return std::nullopt;
  }
  return records;
}

}  // namespace

std::vector<std::int8_t> EncodeFaceRecords(std::span<const FaceStats> stats,
                                           std::span<const EdgeMeans> edge_means, int channels) {
  std::vector<std::int8_t> out;
  Writer w{out};
  if (channels == 3) {
    out.reserve(stats.size() * RecordSize<VectorRecord>());
    for (const FaceStats& s : stats) {
      VectorRecord r{s};
      Fields(w, r);
    }
    return out;
  }
  out.reserve(stats.size() * RecordSize<FaceRecord>());
  for (std::size_t f = 0; f < stats.size(); ++f) {
    FaceRecord r{stats[f], edge_means[f]};
    Fields(w, r);
  }
  return out;
}

std::optional<std::vector<FaceRecord>> DecodeFaceRecords(std::span<const std::uint8_t> bytes,
                                                         std::size_t num_faces, int channels) {
  if (channels != 3) return Decode<FaceRecord>(bytes, num_faces);
  std::optional<std::vector<VectorRecord>> vectors = Decode<VectorRecord>(bytes, num_faces);
  if (!vectors) return std::nullopt;
  std::vector<FaceRecord> out(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f) out[f].stats = (*vectors)[f].stats;
  return out;
}

std::vector<std::int8_t> EncodeFaceKeys(std::span<const Hash128> keys) {
  std::vector<std::int8_t> out;
  out.reserve(16 * keys.size());
  Writer w{out};
  for (const Hash128& k : keys) w(k.low), w(k.high);
  return out;
}

std::optional<std::vector<Hash128>> DecodeFaceKeys(std::span<const std::uint8_t> bytes,
                                                   std::size_t num_faces) {
  if (bytes.size() != 16 * num_faces) return std::nullopt;
  std::vector<Hash128> keys(num_faces);
  Reader r{bytes.data()};
  for (Hash128& k : keys) r(k.low), r(k.high);
  return keys;
}

Status CheckMapFaceData(const PtexFile& file) {
  const PtexMetaItem* recorded = file.FindMetaData(kLevelDataHashMetaKey);
  if (recorded != nullptr && recorded->type == PtexMetaType::kString &&
      recorded->AsString() == file.LevelDataHash()) {
    return Status::Ok();
  }
  return file.Validate();
}

}  // namespace dispex::extract
