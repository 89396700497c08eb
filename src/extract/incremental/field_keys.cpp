#include "extract/incremental/field_keys.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>

#include "core/byte_record.h"
#include "core/cache_files.h"
#include "dispex/version.h"
#include "extract/faces_around.h"
#include "extract/incremental/face_keys.h"

namespace dispex::extract {

namespace {

constexpr char kMagic[8] = {'d', 'x', 'f', 'i', 'e', 'l', 'd', '1'};
constexpr const char* kPrefix = "fields-";
constexpr std::uint64_t kFieldCacheBytes = std::uint64_t{1} << 30;
constexpr std::int32_t kNoHome = -1;  // a vertex no grid holds: no face reads it

// The key of a large array, hashed in parallel pieces.
template <class T>
Hash128 ArrayKey(std::span<const T> values) {
  constexpr std::size_t kPiece = std::size_t{1} << 20;
  const std::span<const std::byte> bytes = std::as_bytes(values);
  std::vector<Hash128> pieces((bytes.size() + kPiece - 1) / kPiece);
  tbb::parallel_for(std::size_t{0}, pieces.size(), [&](std::size_t k) {
    pieces[k] = HashBytes(bytes.subspan(k * kPiece, std::min(kPiece, bytes.size() - k * kPiece)));
  });
  Hasher h;
  h.Add(values.size()).AddArray(std::span<const Hash128>(pieces));
  return h.Digest();
}

// What a field key holds besides the positions of its vertices: which vertices each face's
// grid and apron are (the grids' vertex ids and crossings), and the Ptex faces and their limit
// patches.
Hash128 GridsKey(const ExtractInputs& inputs, std::span<const BaseFacePatch> patches) {
  const LimitSurface& surface = inputs.surface;
  const GridSource& source = *inputs.grids;
  Hasher h;
  h.Add(std::string_view("dispex field record 1")).Add(std::string_view(Version()));
  h.Add(inputs.sculpt.num_vertices());
  for (const BaseFacePatch& p : patches) h.Add(p.key[0]).Add(p.key[1]);
  for (int f = 0; f < surface.num_ptex_faces(); ++f) {
    h.Add(surface.base_face(PtexFaceId(f)).value).Add(surface.sub_face(PtexFaceId(f)));
    h.Add(source.grid_size(f));
    for (int e = 0; e < 4 && source.grid_size(f) > 0; ++e) {
      const SculptMapping::Crossing& c = source.crossing(f, e);
      h.Add(c.to).Add(c.kind).Add(c.q).Add(c.tx).Add(c.ty);
    }
  }
  if (inputs.correspondence) {
    h.Add(std::string_view("correspondence"));
    h.Add(ArrayKey(std::span<const VertexId>(inputs.correspondence->grid_vertices)));
  } else {
    h.Add(std::string_view("mapping"));
    h.Add(ArrayKey(inputs.mapping->cells()));
    h.Add(ArrayKey(std::span<const std::uint32_t>(inputs.sculpt.face_offsets)));
    h.Add(ArrayKey(std::span<const std::int32_t>(inputs.sculpt.face_indices)));
  }
  return h.Digest();
}

// A record as read: views into its mapped file.
struct Record {
  CacheRecord file;
  std::span<const Hash128> keys;        // per Ptex face
  std::span<const Float3> positions;    // the sculpt's, when the keys were taken
  std::span<const std::int32_t> homes;  // per sculpt vertex: the first face whose grid holds it
};

std::optional<Record> ReadRecord(const std::string& path, const Hash128& grids_key,
                                 std::size_t num_faces, std::size_t num_vertices) {
  std::optional<CacheRecord> read = ReadCacheRecord(path, std::string_view(kMagic, sizeof(kMagic)));
  if (!read) return std::nullopt;
  Record r{std::move(*read), {}, {}, {}};
  const std::string_view body = r.file.bytes;
  std::size_t at = sizeof(kMagic);
  Hash128 stored;
  if (!Take(body, at, stored) || !(stored == grids_key) || !TakeView(body, at, r.keys) ||
      !TakeView(body, at, r.positions) || !TakeView(body, at, r.homes) || at != body.size() ||
      r.keys.size() != num_faces || r.positions.size() != num_vertices ||
      r.homes.size() != num_vertices) {
    return std::nullopt;
  }
  return r;
}

void WriteRecord(const std::string& path, const Hash128& grids_key, std::span<const Hash128> keys,
                 std::span<const Float3> positions, std::span<const std::int32_t> homes) {
  std::string head(kMagic, sizeof(kMagic));
  Append(head, grids_key);
  Append(head, std::uint64_t{keys.size()});
  std::string positions_count, homes_count;
  Append(positions_count, std::uint64_t{positions.size()});
  Append(homes_count, std::uint64_t{homes.size()});
  const std::span<const std::byte> parts[] = {
      std::as_bytes(std::span(head.data(), head.size())),
      std::as_bytes(keys),
      std::as_bytes(std::span(positions_count.data(), positions_count.size())),
      std::as_bytes(positions),
      std::as_bytes(std::span(homes_count.data(), homes_count.size())),
      std::as_bytes(homes)};
  if (!WriteCacheRecord(path, parts)) return;
  EvictCacheFiles(std::filesystem::path(path).parent_path().string(), kPrefix, kFieldCacheBytes,
                  path);
}

// Per Ptex face, whether a sculpt vertex its grid holds first moved since the record; nullopt
// where the record names a face that is not there (a record that cannot be trusted).
std::optional<std::vector<std::uint8_t>> HomesOfMoved(const Record& record,
                                                      std::span<const Float3> positions,
                                                      std::size_t num_faces) {
  std::vector<std::uint8_t> moved(num_faces, 0);
  std::atomic<bool> bad{false};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, positions.size(), std::size_t{1} << 14),
      [&](const tbb::blocked_range<std::size_t>& r) {
        const std::size_t bytes = r.size() * sizeof(Float3);
        if (std::memcmp(&positions[r.begin()], &record.positions[r.begin()], bytes) == 0) return;
        for (std::size_t v = r.begin(); v != r.end(); ++v) {
          if (std::memcmp(&positions[v], &record.positions[v], sizeof(Float3)) == 0) continue;
          const std::int32_t home = record.homes[v];
          if (home == kNoHome) continue;
          if (home < 0 || static_cast<std::size_t>(home) >= num_faces) {
            bad.store(true, std::memory_order_relaxed);
            continue;
          }
          std::atomic_ref<std::uint8_t>(moved[static_cast<std::size_t>(home)])
              .store(1, std::memory_order_relaxed);
        }
      });
  if (bad.load()) return std::nullopt;
  return moved;
}

}  // namespace

FieldKeys ComputeFieldKeys(const ExtractInputs& inputs, std::span<const BaseFacePatch> patches,
                           const std::string& cache_folder) {
  const auto num_faces = static_cast<std::size_t>(inputs.surface.num_ptex_faces());
  const std::span<const Float3> positions(inputs.sculpt.positions);
  std::optional<Record> record;
  std::vector<std::uint8_t> again;  // with a record: the faces to key again
  std::string path;
  Hash128 grids_key;
  if (!cache_folder.empty()) {
    grids_key = GridsKey(inputs, patches);
    path = (std::filesystem::path(cache_folder) / (kPrefix + grids_key.Hex() + ".bin")).string();
    record = ReadRecord(path, grids_key, num_faces, positions.size());
    if (record) {
      std::optional<std::vector<std::uint8_t>> moved = HomesOfMoved(*record, positions, num_faces);
      if (moved) {
        again = WithFacesAround(inputs, std::move(*moved));
      } else {
        record.reset();
      }
    }
  }
  // Without a record, every vertex's home is found as the faces are keyed.
  std::vector<std::int32_t> homes;
  if (!path.empty() && !record) {
    homes.assign(positions.size(), std::numeric_limits<std::int32_t>::max());
  }

  FieldKeys out;
  out.keys.resize(num_faces);
  struct Scratch {
    std::vector<VertexId> ids;
    std::vector<int> faces;
    std::vector<Float3> points;
  };
  tbb::enumerable_thread_specific<Scratch> scratches;
  tbb::parallel_for(std::size_t{0}, num_faces, [&](std::size_t f) {
    if (record && !again[f]) {
      out.keys[f] = record->keys[f];
      return;
    }
    Scratch& w = scratches.local();
    Hasher h;
    AddFieldKey(h, inputs, patches, static_cast<int>(f), w.ids, w.faces, w.points);
    out.keys[f] = h.Digest();
    if (homes.empty()) return;
    const auto m = static_cast<std::size_t>(inputs.grids->grid_size(static_cast<int>(f)));
    const std::size_t grid = m > 0 ? (m + 1) * (m + 1) : 0;  // the grid's ids come first
    for (std::size_t k = 0; k < grid; ++k) {
      std::atomic_ref<std::int32_t> home(homes[static_cast<std::size_t>(w.ids[k].value)]);
      std::int32_t current = home.load(std::memory_order_relaxed);
      const auto face = static_cast<std::int32_t>(f);
      while (face < current && !home.compare_exchange_weak(current, face)) {
      }
    }
  });
  if (path.empty()) return out;
  if (record) {
    const auto keyed_again = static_cast<std::int64_t>(std::count(again.begin(), again.end(), 1));
    out.kept = static_cast<std::int64_t>(num_faces) - keyed_again;
    if (16 * keyed_again > static_cast<std::int64_t>(num_faces)) {
      WriteRecord(path, grids_key, out.keys, positions, record->homes);
    }
    return out;
  }
  for (std::int32_t& home : homes) {
    if (home == std::numeric_limits<std::int32_t>::max()) home = kNoHome;
  }
  WriteRecord(path, grids_key, out.keys, positions, homes);
  return out;
}

}  // namespace dispex::extract
