// The OBJ reader: two parallel passes over chunks of the (memory-mapped) file.
//
// 1. Cut the file into chunks of about ReadOptions::chunk_bytes that start at logical line
//    starts (a cut never splits a `\` continuation).
// 2. Counting pass, in parallel: per chunk, physical lines, `v`, `vt` and `f` lines, and the
//    corners of its face lines (obj_syntax.h, CountFaceCorners). Prefix sums give each chunk
//    its first line number, vertex, texture coordinate, face and corner bases, and the totals
//    size the final arrays.
// 3. Parsing pass, in parallel: each chunk writes its positions, UVs, face sizes and face
//    indices straight into the final arrays (its texture indices into a per-chunk buffer);
//    relative indices, index ranges and tag ids are checked there with the exact line number.
//    A file with a comment or a continuation in a face line, where the counting pass does not
//    count corners, has its face indices go to per-chunk buffers too.
// 4. Merge, in file order: the first error of the earliest chunk is the file's first error;
//    face sizes become offsets; index buffers are appended and freed one by one; groups and
//    tags are concatenated. UVs are kept only when every face had them (Mesh::uvs).
// Memory: the final arrays plus the index buffers of the chunks not yet appended (none for
// face indices parsed in place). Both passes over a file read copies of its chunks (pread, a
// buffer per thread), so the file itself is never resident in the process and its mapping's
// pages are not touched (but for a chunk that cannot be copied). The result is identical for
// any thread count and chunk size.
#include "mesh/obj_reader.h"

#include <fmt/format.h>
#include <sys/mman.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <new>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/check.h"
#include "core/first_touch.h"
#include "core/mapped_file.h"
#include "core/parallel.h"
#include "dispex/mesh.h"
#include "mesh/obj_chunk_parser.h"
#include "mesh/obj_syntax.h"
#include "mesh/text_scan.h"

namespace dispex {
namespace {

constexpr std::size_t kDefaultChunkBytes = std::size_t{4} << 20;
// Face corners whose pages are first touched at once (AppendInOrder).
constexpr std::size_t kTouchWindowCorners = std::size_t{1} << 18;

struct Chunk {
  const char* begin;
  const char* end;
};

struct ChunkCounts {
  std::int64_t lines = 0;  // '\n' bytes in the chunk
  std::int64_t vertices = 0;
  std::int64_t texcoords = 0;
  std::int64_t faces = 0;
  std::int64_t corners = 0;  // of its faces, meaningful while `plain` (CountFaceCorners)
  bool plain = true;
};

std::vector<Chunk> CutIntoChunks(std::string_view bytes, std::size_t chunk_bytes) {
  std::vector<Chunk> chunks;
  const char* begin = bytes.data();
  const char* end = begin + bytes.size();
  const char* start = begin;
  while (start < end) {
    const char* stop = end;
    if (static_cast<std::size_t>(end - start) > chunk_bytes) {
      stop = mesh::NextLineStart(begin, start + chunk_bytes - 1, end);
    }
    chunks.push_back({start, stop});
    start = stop;
  }
  return chunks;
}

// A logical line starts at the chunk's start and after every '\n' that is not continued; each
// is classified exactly as the parsing pass will classify it (SkipBlanks, then ReadKeyword),
// and a face line's corners are counted up to its end.
ChunkCounts CountChunk(const char* file_begin, const Chunk& chunk) {
  ChunkCounts counts;
  const char* face = nullptr;  // the arguments of the face line being read
  auto classify = [&](const char* p) {
    std::int64_t crossed = 0;  // continuations at the line start: counted below, as newlines
    mesh::SkipBlanks(p, chunk.end, crossed);
    const mesh::LineKind kind = mesh::ReadKeyword(p, chunk.end);
    counts.vertices += kind == mesh::LineKind::kVertex;
    counts.texcoords += kind == mesh::LineKind::kTexCoord;
    counts.faces += kind == mesh::LineKind::kFace;
    face = kind == mesh::LineKind::kFace ? p : nullptr;
  };
  auto end_line = [&](const char* end) {
    if (face != nullptr) counts.corners += mesh::CountFaceCorners(face, end, counts.plain);
    face = nullptr;
  };
  classify(chunk.begin);
  mesh::ForEachNewline(chunk.begin, chunk.end, [&](const char* newline) {
    ++counts.lines;
    if (mesh::IsContinuedNewline(file_begin, newline)) return;
    end_line(newline);
    if (newline + 1 < chunk.end) classify(newline + 1);
  });
  end_line(chunk.end);
  return counts;
}

// Drops the resident pages that lie wholly inside [begin, end) of a read-only file mapping:
// they are read again from the page cache if touched later. Only for mapped files.
void ReleaseMappedPages(const char* begin, const char* end) {
  static const std::uintptr_t page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(begin) + page - 1) & ~(page - 1);
  const std::uintptr_t last = reinterpret_cast<std::uintptr_t>(end) & ~(page - 1);
  if (last > first) {
    ::madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
  }
}

Status LineError(const std::string& name, std::int64_t line, const std::string& message) {
  return Status::Error(fmt::format("{}:{}: {}", name, line, message));
}

// Assigns group ids in order of first appearance, keeping only groups that own faces.
void MergeGroups(const std::vector<mesh::ChunkOutput>& outputs, Mesh& mesh) {
  std::vector<const mesh::GroupStart*> starts;
  for (const auto& out : outputs) {
    for (const auto& g : out.groups) starts.push_back(&g);
  }
  if (starts.empty()) return;
  const std::int64_t num_faces = static_cast<std::int64_t>(mesh.num_faces());
  mesh.face_groups.resize(static_cast<std::size_t>(num_faces));
  std::unordered_map<std::string, std::int32_t> ids;
  auto id_of = [&](const std::string& name) {
    auto [it, inserted] = ids.try_emplace(name, static_cast<std::int32_t>(mesh.group_names.size()));
    if (inserted) mesh.group_names.push_back(name);
    return it->second;
  };
  // A group line names the faces that follow it; faces before the first one are "default".
  std::int64_t face = 0;
  const std::string* current = nullptr;
  for (std::size_t i = 0; i <= starts.size(); ++i) {
    const std::int64_t stop = i < starts.size() ? starts[i]->first_face : num_faces;
    if (stop > face) {
      const std::int32_t id = id_of(current != nullptr ? *current : std::string("default"));
      std::fill(mesh.face_groups.begin() + face, mesh.face_groups.begin() + stop, id);
      face = stop;
    }
    if (i < starts.size()) current = &starts[i]->name;
  }
}

// Appends every chunk's `buffer` to `all` in file order, each freed once appended. The pages
// they go to are first touched by every thread a window of chunks at a time, so that the peak
// holds at most one window more than the final arrays. Runs in the caller's arena.
void AppendInOrder(std::vector<mesh::ChunkOutput>& outputs,
                   mesh::ChunkBuffer<std::int32_t> mesh::ChunkOutput::*buffer, std::uint64_t total,
                   std::vector<std::int32_t>& all) {
  all.reserve(static_cast<std::size_t>(total));
  for (std::size_t next = 0; next < outputs.size();) {
    std::size_t stop = next, window = 0;
    while (stop < outputs.size() && window < kTouchWindowCorners) {
      window += (outputs[stop++].*buffer).size();
    }
    if (window * sizeof(std::int32_t) >= kFirstTouchBytes) {
      TouchPages(all.data() + all.size(), window * sizeof(std::int32_t));
    }
    for (; next < stop; ++next) {
      auto& from = outputs[next].*buffer;
      all.insert(all.end(), from.begin(), from.end());
      from.Release();
    }
  }
}

// Reads `size` bytes at `offset` of `fd` into `out`; false on an error or a short read.
bool ReadFully(int fd, char* out, std::size_t size, std::size_t offset) {
  while (size > 0) {
    const ssize_t got = ::pread(fd, out, size, static_cast<off_t>(offset));
    if (got <= 0) return false;
    out += got;
    size -= static_cast<std::size_t>(got);
    offset += static_cast<std::size_t>(got);
  }
  return true;
}

// A chunk read into a buffer: `chunk` within it, `file_begin` where the look-back stops.
struct ChunkCopy {
  const char* file_begin;
  Chunk chunk;
};

// Reads `chunk` of the mapped file `fd` (mapped at `file_begin`), with the two bytes before it,
// into `buffer`; nothing when the buffer cannot grow (a chunk of one enormous line) or the read
// fails.
std::optional<ChunkCopy> CopyChunk(int fd, const char* file_begin, const Chunk& chunk,
                                   std::vector<char>& buffer) {
  const std::size_t offset = static_cast<std::size_t>(chunk.begin - file_begin);
  const std::size_t before = std::min<std::size_t>(offset, 2);
  const std::size_t size = before + static_cast<std::size_t>(chunk.end - chunk.begin);
  try {
    if (buffer.size() < size) buffer.resize(size);
  } catch (const std::bad_alloc&) {
    return std::nullopt;
  }
  if (!ReadFully(fd, buffer.data(), size, offset - before)) return std::nullopt;
  const char* begin = buffer.data() + before;
  return ChunkCopy{buffer.data(), {begin, begin + (chunk.end - chunk.begin)}};
}

// Both passes read a mapped file's chunks as copies, each with the two bytes before it that a
// continued newline looks back at, into a buffer of its thread's (CopyChunk): the buffers'
// pages are first touched once and reused chunk after chunk, where the mapping's pages were each
// first touched by a pass (docs/bench-notes/extract.md, "Memory"). The file is the one mapped
// (MappedFile::fd), not whatever its path names now. A chunk that cannot be copied is read
// through the mapping, its pages mapped in one call and dropped after it. A buffer in memory
// (no file descriptor) is read in place.
class ChunkReader {
 public:
  ChunkReader(std::string_view bytes, const std::vector<Chunk>& chunks, int mapped_fd)
      : file_begin_(bytes.data()), chunks_(chunks), mapped_fd_(mapped_fd) {}

  // Calls use(look_back_start, chunk) on chunk i's bytes.
  template <class Use>
  void WithBytes(std::size_t i, Use&& use) {
    const Chunk& chunk = chunks_[i];
    const bool mapped = mapped_fd_ >= 0;
    if (mapped) {
      if (const std::optional<ChunkCopy> copy =
              CopyChunk(mapped_fd_, file_begin_, chunk, copies_.local())) {
        use(copy->file_begin, copy->chunk);
        return;
      }
      PopulateMappedPages(chunk.begin, static_cast<std::size_t>(chunk.end - chunk.begin));
    }
    use(file_begin_, chunk);
    if (mapped) ReleaseMappedPages(chunk.begin, chunk.end);
  }

 private:
  const char* file_begin_;
  const std::vector<Chunk>& chunks_;
  int mapped_fd_;
  tbb::enumerable_thread_specific<std::vector<char>> copies_;
};

// The counting pass (step 2), in parallel.
std::vector<ChunkCounts> CountChunks(ChunkReader& reader, std::size_t n, int threads) {
  std::vector<ChunkCounts> counts(n);
  RunWithThreads(threads, [&] {
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      reader.WithBytes(i, [&](const char* look_back, const Chunk& chunk) {
        counts[i] = CountChunk(look_back, chunk);
      });
    });
  });
  return counts;
}

// The file's totals from the counting pass.
struct FileCounts {
  std::int64_t lines = 0, vertices = 0, texcoords = 0, faces = 0, corners = 0;
  // Whether every face line's corners were counted: they are then parsed in place.
  bool in_place = true;
};

// Prefix sums of the counts: each chunk's first line number and its vertex, texture
// coordinate and face bases in `inputs`, its first corner in `corner_base`.
FileCounts SumCounts(const std::vector<ChunkCounts>& counts, std::vector<mesh::ChunkInput>& inputs,
                     std::vector<std::int64_t>& corner_base) {
  FileCounts total;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    corner_base[i] = total.corners;
    total.corners += counts[i].corners;
    total.in_place = total.in_place && counts[i].plain;
    inputs[i].first_line = total.lines + 1;
    inputs[i].vertex_base = total.vertices;
    inputs[i].texcoord_base = total.texcoords;
    inputs[i].face_base = total.faces;
    total.lines += counts[i].lines;
    total.vertices += counts[i].vertices;
    total.texcoords += counts[i].texcoords;
    total.faces += counts[i].faces;
  }
  total.in_place = total.in_place && total.corners <= std::numeric_limits<std::uint32_t>::max();
  return total;
}

// Vertex ids are int32 (OpenSubdiv, Embree) and so are face ids.
Status CheckCounts(const FileCounts& total, const std::string& name) {
  if (total.vertices > std::numeric_limits<std::int32_t>::max()) {
    return Status::Error(
        fmt::format("{}: {} vertices: more than the 2^31-1 supported", name, total.vertices));
  }
  if (total.faces > std::numeric_limits<std::int32_t>::max()) {
    return Status::Error(
        fmt::format("{}: {} faces: more than the 2^31-1 supported", name, total.faces));
  }
  if (total.texcoords > std::numeric_limits<std::int32_t>::max()) {
    return Status::Error(fmt::format("{}: {} texture coordinates: more than the 2^31-1 supported",
                                     name, total.texcoords));
  }
  return Status::Ok();
}

// Sizes the final arrays (their pages first touched in parallel) and points each chunk's input
// at its part of them.
void AllocateArrays(const FileCounts& total, const std::vector<ChunkCounts>& counts,
                    const std::vector<std::int64_t>& corner_base, int threads, Mesh& mesh,
                    std::vector<mesh::ChunkInput>& inputs) {
  // Embree reads 16 bytes at the last vertex: keep one spare element of capacity.
  RunWithThreads(threads, [&] {
    ReserveTouched(mesh.positions, static_cast<std::size_t>(total.vertices) + 1);
    AssignTouched(mesh.face_offsets, static_cast<std::size_t>(total.faces) + 1, 0u);
    AssignTouched(mesh.uvs, 2 * static_cast<std::size_t>(total.texcoords), 0.0f);
    if (total.in_place) {
      AssignTouched(mesh.face_indices, static_cast<std::size_t>(total.corners), 0);
    }
  });
  mesh.positions.resize(static_cast<std::size_t>(total.vertices));
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    mesh::ChunkInput& in = inputs[i];
    in.num_vertices = total.vertices;
    in.num_texcoords = total.texcoords;
    in.num_faces = total.faces;
    in.positions = mesh.positions.data();
    in.uvs = mesh.uvs.data();
    in.face_sizes = mesh.face_offsets.data() + 1;
    if (total.in_place) {
      in.indices = mesh.face_indices.data() + corner_base[i];
      in.corners = counts[i].corners;
    }
  }
}

// The parsing pass (step 3), in parallel; false when a chunk ran out of memory.
bool ParseChunks(ChunkReader& reader, std::vector<mesh::ChunkInput>& inputs,
                 std::vector<mesh::ChunkOutput>& outputs, int threads) {
  std::atomic<bool> out_of_memory{false};
  RunWithThreads(threads, [&] {
    tbb::parallel_for(std::size_t{0}, inputs.size(), [&](std::size_t i) {
      reader.WithBytes(i, [&](const char* look_back, const Chunk& chunk) {
        mesh::ChunkInput& in = inputs[i];
        in.file_begin = look_back;
        in.begin = chunk.begin;
        in.end = chunk.end;
        if (!mesh::ParseChunk(in, outputs[i])) out_of_memory.store(true);
      });
    });
  });
  return !out_of_memory.load();
}

// What the parsing pass read, over all chunks.
struct ParsedCounts {
  std::uint64_t corners = 0;
  std::int64_t faces_without_uvs = 0, first_face_without_uvs = -1;
};

// The first error of the earliest chunk, else the corners and the faces without UVs; fails for
// a file without faces or with more corners than 32-bit offsets hold.
StatusOr<ParsedCounts> CheckOutputs(const std::vector<mesh::ChunkOutput>& outputs,
                                    const std::vector<ChunkCounts>& counts, const FileCounts& total,
                                    const std::string& name) {
  ParsedCounts parsed;
  std::int64_t faces_before = 0;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const mesh::ChunkOutput& out = outputs[i];
    if (out.error) return LineError(name, out.error->line, out.error->message);
    DISPEX_CHECK_EQ(out.vertices, counts[i].vertices);
    DISPEX_CHECK_EQ(out.texcoords, counts[i].texcoords);
    DISPEX_CHECK_EQ(out.faces, counts[i].faces);
    // In place, a chunk parsed without error read the corners counted (CountFaceCorners).
    if (total.in_place) DISPEX_CHECK_EQ(out.corners, counts[i].corners);
    parsed.corners += total.in_place ? static_cast<std::uint64_t>(out.corners) : out.indices.size();
    parsed.faces_without_uvs += out.faces - out.faces_with_uvs;
    if (parsed.first_face_without_uvs < 0 && out.first_face_without_uvs >= 0) {
      parsed.first_face_without_uvs = faces_before + out.first_face_without_uvs;
    }
    faces_before += out.faces;
  }
  if (total.faces == 0) {
    return Status::Error(
        fmt::format("{}: no faces ({} vertices): not a polygon mesh", name, total.vertices));
  }
  if (parsed.corners > std::numeric_limits<std::uint32_t>::max()) {
    return Status::Error(
        fmt::format("{}: {} face corners: more than the 2^32-1 supported", name, parsed.corners));
  }
  return parsed;
}

void FaceSizesToOffsets(Mesh& mesh) {
  std::uint32_t offset = 0;
  for (std::size_t f = 1; f < mesh.face_offsets.size(); ++f) {
    offset += mesh.face_offsets[f];
    mesh.face_offsets[f] = offset;
  }
}

// The face indices not parsed in place, and the UV indices when every face had them (see
// Mesh::faces_without_uvs), appended in file order; the UVs dropped otherwise.
void MergeIndices(std::vector<mesh::ChunkOutput>& outputs, const FileCounts& total,
                  const ParsedCounts& parsed, int threads, Mesh& mesh) {
  if (!total.in_place) {
    RunWithThreads(threads, [&] {
      AppendInOrder(outputs, &mesh::ChunkOutput::indices, parsed.corners, mesh.face_indices);
    });
  }
  if (parsed.faces_without_uvs == 0 && total.texcoords > 0) {
    RunWithThreads(threads, [&] {
      AppendInOrder(outputs, &mesh::ChunkOutput::uv_indices, parsed.corners, mesh.face_uv_indices);
    });
    DISPEX_CHECK_EQ(mesh.face_uv_indices.size(), mesh.face_indices.size());
    return;
  }
  for (auto& out : outputs) out.uv_indices.Release();
  std::vector<float>().swap(mesh.uvs);
  if (parsed.faces_without_uvs < total.faces) {
    mesh.faces_without_uvs = static_cast<std::size_t>(parsed.faces_without_uvs);
    mesh.first_face_without_uvs = static_cast<std::size_t>(parsed.first_face_without_uvs);
  }
}

// The chunks' tags in file order; a setting from the file is the last chunk's that has one.
void MergeTags(const std::vector<mesh::ChunkOutput>& outputs, Mesh& mesh) {
  SubdivTags& tags = mesh.tags;
  for (const auto& out : outputs) {
    tags.creases.insert(tags.creases.end(), out.tags.creases.begin(), out.tags.creases.end());
    tags.corners.insert(tags.corners.end(), out.tags.corners.begin(), out.tags.corners.end());
    tags.holes.insert(tags.holes.end(), out.tags.holes.begin(), out.tags.holes.end());
    if (out.tags.boundary_from_file) {
      tags.boundary = out.tags.boundary;
      tags.boundary_from_file = true;
    }
    if (out.tags.crease_method_from_file) {
      tags.crease_method = out.tags.crease_method;
      tags.crease_method_from_file = true;
    }
    if (out.tags.triangles_from_file) {
      tags.triangles = out.tags.triangles;
      tags.triangles_from_file = true;
    }
    tags.ignored_tag_names.insert(tags.ignored_tag_names.end(), out.tags.ignored_tag_names.begin(),
                                  out.tags.ignored_tag_names.end());
  }
}

// `bytes` is the mapping of the open file `mapped_fd`, or a buffer in memory when it is -1: a
// mapping's chunks are counted and parsed from copies read from `mapped_fd` (ChunkReader).
// The steps are those of the comment at the top of this file.
StatusOr<Mesh> ParseObjBuffer(std::string_view bytes, const std::string& name,
                              const ReadOptions& options, int mapped_fd) {
  const std::size_t chunk_bytes =
      options.chunk_bytes > 0 ? options.chunk_bytes : kDefaultChunkBytes;
  const std::vector<Chunk> chunks = CutIntoChunks(bytes, chunk_bytes);
  const std::size_t n = chunks.size();
  ChunkReader reader(bytes, chunks, mapped_fd);
  const std::vector<ChunkCounts> counts = CountChunks(reader, n, options.threads);

  std::vector<mesh::ChunkInput> inputs(n);
  std::vector<std::int64_t> corner_base(n);
  const FileCounts total = SumCounts(counts, inputs, corner_base);
  DISPEX_RETURN_IF_ERROR(CheckCounts(total, name));
  Mesh mesh;
  mesh.source = name;
  AllocateArrays(total, counts, corner_base, options.threads, mesh, inputs);

  std::vector<mesh::ChunkOutput> outputs(n);
  if (!ParseChunks(reader, inputs, outputs, options.threads)) {
    return Status::Error(name + ": out of memory while reading");
  }
  DISPEX_ASSIGN_OR_RETURN(const ParsedCounts parsed, CheckOutputs(outputs, counts, total, name));
  FaceSizesToOffsets(mesh);
  MergeIndices(outputs, total, parsed, options.threads, mesh);
  MergeGroups(outputs, mesh);
  MergeTags(outputs, mesh);
  return mesh;
}

}  // namespace

MeshSize CountObjElements(std::string_view bytes) {
  const std::vector<Chunk> chunks = CutIntoChunks(bytes, kDefaultChunkBytes);
  std::vector<ChunkCounts> counts(chunks.size());
  tbb::parallel_for(std::size_t{0}, chunks.size(),
                    [&](std::size_t i) { counts[i] = CountChunk(bytes.data(), chunks[i]); });
  MeshSize size;
  size.corners_counted = true;
  for (const ChunkCounts& c : counts) {
    size.vertices += static_cast<std::uint64_t>(c.vertices);
    size.faces += static_cast<std::uint64_t>(c.faces);
    size.corners += static_cast<std::uint64_t>(c.corners);
    size.corners_counted = size.corners_counted && c.plain;
  }
  if (!size.corners_counted) size.corners = 4 * size.faces;
  return size;
}

StatusOr<Mesh> ParseObj(std::string_view bytes, const std::string& name,
                        const ReadOptions& options) {
  return ParseObjBuffer(bytes, name, options, /*mapped_fd=*/-1);
}

StatusOr<Mesh> ReadObj(const std::string& path, const ReadOptions& options) {
  DISPEX_ASSIGN_OR_RETURN(MappedFile file, MappedFile::Open(path));
  return ParseObjBuffer(file.view(), path, options, file.fd());
}

}  // namespace dispex
