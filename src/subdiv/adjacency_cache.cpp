#include "subdiv/adjacency_cache.h"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <span>

#include "core/cache_files.h"
#include "core/hash128.h"

namespace dispex::subdiv {
namespace {

namespace fs = std::filesystem;

// The file: this magic, the key, the counts, the four arrays, and the hash of all that.
constexpr char kMagic[8] = {'D', 'X', 'A', 'D', 'J', '0', '0', '1'};
constexpr const char* kPrefix = "adjacency-";

struct Counts {
  std::uint64_t half_edges = 0, vertices = 0;
};

template <class T>
std::span<const std::byte> Bytes(const T& values) {
  return std::as_bytes(std::span(values.data(), values.size()));
}

// Hashes the parts in order, as the file holds them.
Hash128 ContentHash(const Hash128& key, const Counts& counts, const QuadAdjacency& a) {
  Hasher hasher;
  hasher.Add(std::string_view(kMagic, sizeof(kMagic)))
      .Add(key)
      .Add(counts.half_edges)
      .Add(counts.vertices);
  hasher.Add(Bytes(a.opposite)).Add(Bytes(a.first_half_edge));
  hasher.Add(Bytes(a.valence)).Add(Bytes(a.boundary));
  return hasher.Digest();
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

bool ReadInto(std::FILE* f, void* data, std::size_t bytes) {
  return bytes == 0 || std::fread(data, 1, bytes, f) == bytes;
}

bool Read(const std::string& path, const Hash128& key, const Mesh& mesh, QuadAdjacency& out) {
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) return false;
  char magic[8];
  Hash128 stored;
  Counts counts;
  if (!ReadInto(f.get(), magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(magic)) ||
      !ReadInto(f.get(), &stored, sizeof(stored)) || !(stored == key) ||
      !ReadInto(f.get(), &counts, sizeof(counts)) ||
      counts.half_edges != mesh.face_indices.size() || counts.vertices != mesh.num_vertices()) {
    return false;
  }
  out.opposite.resize(counts.half_edges);
  out.first_half_edge.resize(counts.vertices);
  out.valence.resize(counts.vertices);
  out.boundary.resize(counts.vertices);
  Hash128 check;
  if (!ReadInto(f.get(), out.opposite.data(), counts.half_edges * 4) ||
      !ReadInto(f.get(), out.first_half_edge.data(), counts.vertices * 4) ||
      !ReadInto(f.get(), out.valence.data(), counts.vertices * 2) ||
      !ReadInto(f.get(), out.boundary.data(), counts.vertices) ||
      !ReadInto(f.get(), &check, sizeof(check)) || std::fgetc(f.get()) != EOF) {
    return false;
  }
  return ContentHash(key, counts, out) == check;
}

// Written without syncing: a file cut short by a crash fails its hash and is built again.
void Write(const std::string& path, const Hash128& key, const QuadAdjacency& a) {
  const Counts counts{a.opposite.size(), a.first_half_edge.size()};
  const Hash128 check = ContentHash(key, counts, a);
  const std::span<const std::byte> parts[] = {std::as_bytes(std::span(kMagic)),
                                              Bytes(std::span(&key, 1)),
                                              Bytes(std::span(&counts, 1)),
                                              Bytes(a.opposite),
                                              Bytes(a.first_half_edge),
                                              Bytes(a.valence),
                                              Bytes(a.boundary),
                                              Bytes(std::span(&check, 1))};
  WriteCacheFile(path, parts);
}

}  // namespace

Hash128 SculptFacesKey(const Mesh& mesh) {
  Hasher hasher;
  hasher.Add(std::string_view("dispex quad adjacency 1")).Add(mesh.num_vertices());
  hasher.AddArray(std::span<const std::int32_t>(mesh.face_indices));
  return hasher.Digest();
}

StatusOr<QuadAdjacency> CachedQuadAdjacency(const Mesh& mesh, const std::string& folder,
                                            bool& from_cache, const Hash128* faces_key) {
  from_cache = false;
  if (folder.empty() || !mesh.all_quads()) return BuildQuadAdjacency(mesh);
  const Hash128 key = faces_key != nullptr ? *faces_key : SculptFacesKey(mesh);
  const fs::path path = fs::path(folder) / (kPrefix + key.Hex() + ".bin");
  QuadAdjacency cached;
  std::error_code ec;
  if (Read(path.string(), key, mesh, cached)) {
    fs::last_write_time(path, fs::file_time_type::clock::now(), ec);  // recently used
    from_cache = true;
    return cached;
  }
  DISPEX_ASSIGN_OR_RETURN(QuadAdjacency built, BuildQuadAdjacency(mesh));
  fs::create_directories(folder, ec);
  if (!ec) {
    Write(path.string(), key, built);
    EvictCacheFiles(folder, kPrefix, kAdjacencyCacheBytes, path.string());
  }
  return built;
}

}  // namespace dispex::subdiv
