// Splitting a mesh into its shapes (OBJ groups), their file names, and pairing base and sculpt
// shapes by name.
//
// SplitShapes, for G groups, F faces and V vertices, in linear time:
// 1. One pass over the faces checks the group ids and counts each shape's faces and corners; a
//    second lists the faces shape by shape, in file order (a counting sort).
// 2. ElementSplit, for the vertices and again for the texture coordinates: in parallel over the
//    faces, each vertex's lowest shape (an atomic minimum), then the vertices some face of
//    another shape also uses ("shared"); the shapes of a shared vertex are listed by a counting
//    sort of the corners at shared vertices. One ascending pass over the vertices numbers them
//    in each of their shapes, which keeps the parent's order.
// 3. The tags go to the shapes that hold their vertices (faces), in tag order.
// 4. In parallel over the shapes (and over each shape's faces), positions, faces and UVs are
//    copied and renumbered.
#include "dispex/shapes.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/content_hash.h"
#include "core/first_error.h"

namespace dispex {
namespace {

constexpr std::size_t kFaceGrain = 1 << 14;
constexpr std::size_t kMaxListedNames = 10;
constexpr std::size_t kMaxFileNameBytes = 100;

// A name as messages show it: quoted, control bytes as '?' so that the message stays one line.
std::string Quoted(std::string_view name) {
  std::string out = "'";
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte < 0x20 || byte == 0x7f ? '?' : c;
  }
  out += '\'';
  return out;
}

char AsciiLower(char c) {
  return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
}

std::string AsciiLower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = AsciiLower(c);
  return out;
}

// Which shapes use each element (vertex or texture coordinate) of the parent mesh, and the
// element's id in each: the ids of a shape follow the ascending order of the parent's ids.
class ElementSplit {
 public:
  // `indices`: the parent's face_indices or face_uv_indices (laid out by face_offsets), ids of
  // `num_elements` elements; `what` names one in messages ("vertex").
  static StatusOr<ElementSplit> Build(const Mesh& mesh, std::span<const std::int32_t> indices,
                                      std::size_t num_elements, std::size_t num_shapes,
                                      std::string_view what);

  // The parent's ids of the shape's elements, ascending.
  std::span<const std::int32_t> Elements(std::size_t shape) const {
    return {elements_.data() + shape_start_[shape], elements_.data() + shape_start_[shape + 1]};
  }
  // The id in `shape` of an element that one of its faces uses.
  std::int32_t IdIn(std::int32_t shape, std::int32_t element) const {
    const std::int32_t owner = owner_[static_cast<std::size_t>(element)];
    if (owner >= 0) return local_[static_cast<std::size_t>(element)];
    const std::int32_t id = SharedIdIn(shape, owner);
    DISPEX_CHECK_GE(id, 0);
    return id;
  }
  // The id in `shape` of `element`, or -1 when no face of the shape uses it.
  std::int32_t FindIn(std::int32_t shape, std::int32_t element) const {
    const std::int32_t owner = owner_[static_cast<std::size_t>(element)];
    if (owner >= 0) return owner == shape ? local_[static_cast<std::size_t>(element)] : -1;
    return owner == kUnused ? -1 : SharedIdIn(shape, owner);
  }
  // fn(shape, id) for each shape that uses `element`, in shape order.
  template <class Fn>
  void ForEachShape(std::int32_t element, Fn&& fn) const {
    const std::int32_t owner = owner_[static_cast<std::size_t>(element)];
    if (owner >= 0) {
      fn(owner, local_[static_cast<std::size_t>(element)]);
    } else if (owner != kUnused) {
      const std::size_t s = SharedIndex(owner);
      for (std::size_t e = shared_start_[s]; e < shared_start_[s + 1]; ++e) {
        fn(shared_shape_[e], shared_id_[e]);
      }
    }
  }
  // The lowest element that several shapes use, with its two lowest shapes; nullopt if none.
  struct Shared {
    std::int32_t element, shape0, shape1;
  };
  std::optional<Shared> FirstShared() const {
    if (first_shared_ < 0) return std::nullopt;
    const std::size_t s = SharedIndex(owner_[static_cast<std::size_t>(first_shared_)]);
    return Shared{first_shared_, shared_shape_[shared_start_[s]],
                  shared_shape_[shared_start_[s] + 1]};
  }

 private:
  // The steps of Build, in order.
  Status FindLowestShapes(const Mesh& mesh, std::span<const std::int32_t> indices,
                          std::size_t num_elements, std::string_view what);
  std::size_t EncodeOwners(const Mesh& mesh, std::span<const std::int32_t> indices,
                           bool& any_shared);
  void ListSharedShapes(const Mesh& mesh, std::span<const std::int32_t> indices,
                        std::size_t num_shared);
  void NumberInShapes(std::size_t num_elements, std::size_t num_shapes);

  // owner_: the element's one shape (>= 0), kUnused, or EncodeShared(s) for the s-th shared one;
  // kUnseen while FindLowestShapes runs, for an element no face has used yet.
  static constexpr std::int32_t kUnused = -1;
  static constexpr std::int32_t kUnseen = std::numeric_limits<std::int32_t>::max();
  static std::int32_t EncodeShared(std::size_t s) { return -2 - static_cast<std::int32_t>(s); }
  static std::size_t SharedIndex(std::int32_t owner) {
    return static_cast<std::size_t>(-2 - owner);
  }

  std::int32_t SharedIdIn(std::int32_t shape, std::int32_t owner) const {
    const std::size_t s = SharedIndex(owner);
    for (std::size_t e = shared_start_[s]; e < shared_start_[s + 1]; ++e) {
      if (shared_shape_[e] == shape) return shared_id_[e];
    }
    return -1;
  }

  std::vector<std::int32_t> owner_;
  std::vector<std::int32_t> local_;  // the id in its one shape, where owner_ >= 0
  // The shapes of shared element s, ascending: shared_shape_[shared_start_[s] .. [s + 1]), and
  // its id in each.
  std::vector<std::size_t> shared_start_;
  std::vector<std::int32_t> shared_shape_, shared_id_;
  std::vector<std::size_t> shape_start_;  // num_shapes + 1
  std::vector<std::int32_t> elements_;
  std::int32_t first_shared_ = -1;
};

// Runs fn(face, corner_begin, corner_end, shape) over all faces, in parallel.
template <class Fn>
void ParallelForFaces(const Mesh& mesh, Fn&& fn) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.num_faces(), kFaceGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f < r.end(); ++f) {
                        fn(f, mesh.face_offsets[f], mesh.face_offsets[f + 1], mesh.face_groups[f]);
                      }
                    });
}

StatusOr<ElementSplit> ElementSplit::Build(const Mesh& mesh, std::span<const std::int32_t> indices,
                                           std::size_t num_elements, std::size_t num_shapes,
                                           std::string_view what) {
  ElementSplit split;
  DISPEX_RETURN_IF_ERROR(split.FindLowestShapes(mesh, indices, num_elements, what));
  bool any_shared = false;
  const std::size_t num_shared = split.EncodeOwners(mesh, indices, any_shared);
  if (num_shared > 0) split.ListSharedShapes(mesh, indices, num_shared);
  split.NumberInShapes(num_elements, num_shapes);
  DISPEX_CHECK(!any_shared || split.first_shared_ >= 0);
  return split;
}

// Each element's lowest shape, in owner_ (kUnseen for an element no face uses); fails for the
// lowest face with an index out of range.
Status ElementSplit::FindLowestShapes(const Mesh& mesh, std::span<const std::int32_t> indices,
                                      std::size_t num_elements, std::string_view what) {
  std::vector<std::int32_t>& owner = owner_;
  owner.assign(num_elements, kUnseen);
  const auto n = static_cast<std::int64_t>(num_elements);
  FirstError error;
  ParallelForFaces(mesh, [&](std::size_t f, std::size_t begin, std::size_t end, std::int32_t g) {
    for (std::size_t c = begin; c < end; ++c) {
      const std::int32_t v = indices[c];
      if (v < 0 || v >= n) {
        error.Record(static_cast<std::int64_t>(f),
                     Status::Error(fmt::format("{}: face {} uses {} {} ({} in the mesh)",
                                               mesh.source, f + 1, what, std::int64_t{v} + 1, n)));
        return;
      }
      std::atomic_ref<std::int32_t> slot(owner[static_cast<std::size_t>(v)]);
      std::int32_t current = slot.load(std::memory_order_relaxed);
      while (g < current && !slot.compare_exchange_weak(current, g, std::memory_order_relaxed)) {
      }
    }
  });
  return error.failed() ? error.status() : Status::Ok();
}

// Marks the elements that a face of a higher shape uses too, and encodes owner_: kUnused, the
// one shape, or the shared element's index. Returns the number of shared elements; sets
// `any_shared` when a face found one.
std::size_t ElementSplit::EncodeOwners(const Mesh& mesh, std::span<const std::int32_t> indices,
                                       bool& any_shared) {
  std::vector<std::int32_t>& owner = owner_;
  const std::size_t num_elements = owner.size();
  std::vector<std::uint8_t> shared(num_elements, 0);
  std::atomic<bool> found{false};
  ParallelForFaces(mesh, [&](std::size_t, std::size_t begin, std::size_t end, std::int32_t g) {
    for (std::size_t c = begin; c < end; ++c) {
      const auto v = static_cast<std::size_t>(indices[c]);
      if (owner[v] != g) {
        std::atomic_ref<std::uint8_t>(shared[v]).store(1, std::memory_order_relaxed);
        found.store(true, std::memory_order_relaxed);
      }
    }
  });
  std::size_t num_shared = 0;
  for (std::size_t v = 0; v < num_elements; ++v) {
    if (owner[v] == kUnseen) {
      owner[v] = kUnused;
    } else if (shared[v] != 0) {
      if (first_shared_ < 0) first_shared_ = static_cast<std::int32_t>(v);
      owner[v] = EncodeShared(num_shared++);
    }
  }
  any_shared = found.load();
  return num_shared;
}

// The shapes of each shared element: its corners sorted by element, then deduplicated.
void ElementSplit::ListSharedShapes(const Mesh& mesh, std::span<const std::int32_t> indices,
                                    std::size_t num_shared) {
  const std::vector<std::int32_t>& owner = owner_;
  std::vector<std::size_t>& start = shared_start_;
  start.assign(num_shared + 1, 0);
  ParallelForFaces(mesh, [&](std::size_t, std::size_t begin, std::size_t end, std::int32_t) {
    for (std::size_t c = begin; c < end; ++c) {
      const std::int32_t o = owner[static_cast<std::size_t>(indices[c])];
      if (o <= -2) {
        std::atomic_ref<std::size_t>(start[SharedIndex(o) + 1])
            .fetch_add(1, std::memory_order_relaxed);
      }
    }
  });
  for (std::size_t s = 0; s < num_shared; ++s) start[s + 1] += start[s];
  std::vector<std::size_t> cursor(start.begin(), start.end() - 1);
  std::vector<std::int32_t> shapes(start.back());
  ParallelForFaces(mesh, [&](std::size_t, std::size_t begin, std::size_t end, std::int32_t g) {
    for (std::size_t c = begin; c < end; ++c) {
      const std::int32_t o = owner[static_cast<std::size_t>(indices[c])];
      if (o <= -2) {
        shapes[std::atomic_ref<std::size_t>(cursor[SharedIndex(o)])
                   .fetch_add(1, std::memory_order_relaxed)] = g;
      }
    }
  });
  std::vector<std::size_t>().swap(cursor);
  std::vector<std::size_t> unique(num_shared);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_shared),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t s = r.begin(); s < r.end(); ++s) {
                        const auto first = shapes.begin() + static_cast<std::ptrdiff_t>(start[s]);
                        const auto last =
                            shapes.begin() + static_cast<std::ptrdiff_t>(start[s + 1]);
                        std::sort(first, last);
                        unique[s] = static_cast<std::size_t>(std::unique(first, last) - first);
                      }
                    });
  // Compacted in place: each list moves towards the front.
  std::size_t out = 0;
  for (std::size_t s = 0; s < num_shared; ++s) {
    const std::size_t in = start[s];
    start[s] = out;
    for (std::size_t k = 0; k < unique[s]; ++k) shapes[out++] = shapes[in + k];
  }
  start[num_shared] = out;
  shapes.resize(out);
  shapes.shrink_to_fit();
  shared_shape_ = std::move(shapes);
  shared_id_.resize(out);
}

// Ids in each shape, in ascending order of the parent's ids.
void ElementSplit::NumberInShapes(std::size_t num_elements, std::size_t num_shapes) {
  std::vector<std::size_t>& shape_start = shape_start_;
  shape_start.assign(num_shapes + 1, 0);
  local_.resize(num_elements);  // ForEachShape reads it
  for (std::size_t v = 0; v < num_elements; ++v) {
    ForEachShape(static_cast<std::int32_t>(v), [&](std::int32_t g, std::int32_t) {
      ++shape_start[static_cast<std::size_t>(g) + 1];
    });
  }
  for (std::size_t g = 0; g < num_shapes; ++g) shape_start[g + 1] += shape_start[g];
  elements_.resize(shape_start.back());
  std::vector<std::size_t> next(num_shapes, 0);
  for (std::size_t v = 0; v < num_elements; ++v) {
    const std::int32_t o = owner_[v];
    auto number = [&](std::int32_t g) {
      const std::size_t id = next[static_cast<std::size_t>(g)]++;
      elements_[shape_start[static_cast<std::size_t>(g)] + id] = static_cast<std::int32_t>(v);
      return static_cast<std::int32_t>(id);
    };
    if (o >= 0) {
      local_[v] = number(o);
    } else if (o != kUnused) {
      const std::size_t s = SharedIndex(o);
      for (std::size_t e = shared_start_[s]; e < shared_start_[s + 1]; ++e) {
        shared_id_[e] = number(shared_shape_[e]);
      }
    }
  }
}

// The faces of each shape in file order: faces[start[g] .. start[g + 1]).
struct FacesByShape {
  std::vector<std::size_t> start;
  std::vector<std::int32_t> faces;
  std::span<const std::int32_t> of(std::size_t g) const {
    return {faces.data() + start[g], faces.data() + start[g + 1]};
  }
};

// Checks face_groups and the group names; lists the faces by shape when `list` is set.
StatusOr<FacesByShape> SortFacesByShape(const Mesh& mesh, bool list) {
  const std::size_t num_faces = mesh.num_faces();
  const std::size_t num_groups = mesh.group_names.size();
  if (mesh.face_groups.size() != num_faces) {
    return Status::Error(fmt::format("{}: {} face group ids for {} faces", mesh.source,
                                     mesh.face_groups.size(), num_faces));
  }
  if (num_groups == 0 ||
      num_groups > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return Status::Error(
        fmt::format("{}: {} group names for grouped faces", mesh.source, num_groups));
  }
  std::unordered_set<std::string_view> seen;
  for (const std::string& name : mesh.group_names) {
    if (!seen.insert(name).second) {
      return Status::Error(fmt::format("{}: two groups named {}", mesh.source, Quoted(name)));
    }
  }
  FacesByShape sorted;
  sorted.start.assign(num_groups + 1, 0);
  for (std::size_t f = 0; f < num_faces; ++f) {
    const std::int32_t g = mesh.face_groups[f];
    if (g < 0 || static_cast<std::size_t>(g) >= num_groups) {
      return Status::Error(fmt::format("{}: face {} has group id {} ({} groups)", mesh.source,
                                       f + 1, g, num_groups));
    }
    ++sorted.start[static_cast<std::size_t>(g) + 1];
  }
  for (std::size_t g = 0; g < num_groups; ++g) {
    if (sorted.start[g + 1] == 0) {
      return Status::Error(
          fmt::format("{}: group {} has no faces", mesh.source, Quoted(mesh.group_names[g])));
    }
    sorted.start[g + 1] += sorted.start[g];
  }
  if (!list) return sorted;
  sorted.faces.resize(num_faces);
  std::vector<std::size_t> next(sorted.start.begin(), sorted.start.end() - 1);
  for (std::size_t f = 0; f < num_faces; ++f) {
    sorted.faces[next[static_cast<std::size_t>(mesh.face_groups[f])]++] =
        static_cast<std::int32_t>(f);
  }
  return sorted;
}

Status CheckTagIds(const Mesh& mesh) {
  const auto num_vertices = static_cast<std::int64_t>(mesh.num_vertices());
  const auto num_faces = static_cast<std::int64_t>(mesh.num_faces());
  auto vertex_error = [&](const char* tag, std::int32_t v) {
    return Status::Error(fmt::format("{}: {} tag vertex {} out of range ({} vertices)", mesh.source,
                                     tag, v, num_vertices));
  };
  for (const auto& c : mesh.tags.creases) {
    for (const VertexId v : {c.v0, c.v1}) {
      if (v.value < 0 || v.value >= num_vertices) return vertex_error("crease", v.value);
    }
  }
  for (const auto& c : mesh.tags.corners) {
    if (c.vertex.value < 0 || c.vertex.value >= num_vertices) {
      return vertex_error("corner", c.vertex.value);
    }
  }
  for (const BaseFaceId f : mesh.tags.holes) {
    if (f.value < 0 || f.value >= num_faces) {
      return Status::Error(fmt::format("{}: hole tag face {} out of range ({} faces)", mesh.source,
                                       f.value, num_faces));
    }
  }
  return Status::Ok();
}

// The tags of each shape, renumbered, in tag order.
StatusOr<std::vector<SubdivTags>> SplitTags(const Mesh& mesh, const FacesByShape& sorted,
                                            const ElementSplit& vertices, bool require_disjoint) {
  const SubdivTags& tags = mesh.tags;
  SubdivTags settings;
  settings.boundary = tags.boundary;
  settings.boundary_from_file = tags.boundary_from_file;
  settings.crease_method = tags.crease_method;
  settings.crease_method_from_file = tags.crease_method_from_file;
  settings.triangles = tags.triangles;
  settings.triangles_from_file = tags.triangles_from_file;
  settings.ignored_tag_names = tags.ignored_tag_names;
  std::vector<SubdivTags> out(mesh.group_names.size(), settings);

  for (const SubdivTags::Crease& crease : tags.creases) {
    bool kept = false;
    vertices.ForEachShape(crease.v0.value, [&](std::int32_t g, std::int32_t id0) {
      const std::int32_t id1 = vertices.FindIn(g, crease.v1.value);
      if (id1 >= 0) {
        out[static_cast<std::size_t>(g)].creases.push_back(
            {VertexId(id0), VertexId(id1), crease.sharpness});
        kept = true;
      }
    });
    if (kept || !require_disjoint) continue;
    // Without shared vertices each used vertex has one shape.
    std::int32_t shape0 = -1, shape1 = -1;
    vertices.ForEachShape(crease.v0.value, [&](std::int32_t g, std::int32_t) { shape0 = g; });
    vertices.ForEachShape(crease.v1.value, [&](std::int32_t g, std::int32_t) { shape1 = g; });
    if (shape0 >= 0 && shape1 >= 0) {
      return Status::Error(fmt::format(
          "{}: a crease joins vertex {} of shape {} and vertex {} of shape {}; a crease must lie "
          "within one shape",
          mesh.source, std::int64_t{crease.v0.value} + 1,
          Quoted(mesh.group_names[static_cast<std::size_t>(shape0)]),
          std::int64_t{crease.v1.value} + 1,
          Quoted(mesh.group_names[static_cast<std::size_t>(shape1)])));
    }
  }
  for (const SubdivTags::Corner& corner : tags.corners) {
    vertices.ForEachShape(corner.vertex.value, [&](std::int32_t g, std::int32_t id) {
      out[static_cast<std::size_t>(g)].corners.push_back({VertexId(id), corner.sharpness});
    });
  }
  for (const BaseFaceId hole : tags.holes) {
    const auto g = static_cast<std::size_t>(mesh.face_groups[static_cast<std::size_t>(hole.value)]);
    const std::span<const std::int32_t> faces = sorted.of(g);
    const auto it = std::lower_bound(faces.begin(), faces.end(), hole.value);
    DISPEX_CHECK(it != faces.end() && *it == hole.value);
    out[g].holes.push_back(BaseFaceId(static_cast<std::int32_t>(it - faces.begin())));
  }
  return out;
}

// Copies the shape's faces, positions and UVs out of `parent`.
void BuildShapeMesh(const Mesh& parent, std::int32_t shape, std::span<const std::int32_t> faces,
                    const ElementSplit& vertices, const ElementSplit* uvs, Mesh& mesh) {
  mesh.face_offsets.resize(faces.size() + 1);
  mesh.face_offsets[0] = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    mesh.face_offsets[i + 1] =
        mesh.face_offsets[i] +
        static_cast<std::uint32_t>(parent.face_size(static_cast<std::size_t>(faces[i])));
  }
  mesh.face_indices.resize(mesh.face_offsets.back());
  if (uvs != nullptr) mesh.face_uv_indices.resize(mesh.face_offsets.back());
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, faces.size(), kFaceGrain),
      [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const std::size_t begin = parent.face_offsets[static_cast<std::size_t>(faces[i])];
          const std::size_t out = mesh.face_offsets[i];
          const auto size = static_cast<std::size_t>(mesh.face_offsets[i + 1] - out);
          for (std::size_t c = 0; c < size; ++c) {
            mesh.face_indices[out + c] = vertices.IdIn(shape, parent.face_indices[begin + c]);
          }
          if (uvs == nullptr) continue;
          for (std::size_t c = 0; c < size; ++c) {
            mesh.face_uv_indices[out + c] = uvs->IdIn(shape, parent.face_uv_indices[begin + c]);
          }
        }
      });

  const std::span<const std::int32_t> used = vertices.Elements(static_cast<std::size_t>(shape));
  mesh.positions.reserve(used.size() + 1);  // Embree reads 16 bytes at the last vertex
  mesh.positions.resize(used.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used.size(), kFaceGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) {
                        mesh.positions[i] = parent.positions[static_cast<std::size_t>(used[i])];
                      }
                    });
  if (uvs != nullptr) {
    const std::span<const std::int32_t> used_uvs = uvs->Elements(static_cast<std::size_t>(shape));
    mesh.uvs.resize(2 * used_uvs.size());
    for (std::size_t i = 0; i < used_uvs.size(); ++i) {
      const auto t = static_cast<std::size_t>(used_uvs[i]);
      mesh.uvs[2 * i] = parent.uvs[2 * t];
      mesh.uvs[2 * i + 1] = parent.uvs[2 * t + 1];
    }
  }
  mesh.faces_without_uvs = parent.faces_without_uvs;
  mesh.first_face_without_uvs = parent.first_face_without_uvs;
}

std::string SourceStem(const std::string& source) {
  std::string stem = std::filesystem::path(source).stem().string();
  return stem.empty() ? std::string("mesh") : stem;
}

// The shape of a mesh without groups or with one: the whole mesh (moved from `owned` when
// given, else copied).
MeshShape WholeMesh(const Mesh& mesh, Mesh* owned, std::string name) {
  MeshShape shape;
  shape.file_name = ShapeFileNames(std::span<const std::string>(&name, 1))[0];
  shape.name = std::move(name);
  if (owned != nullptr) {
    shape.mesh = std::move(*owned);
  } else {
    shape.mesh = mesh;
  }
  std::vector<std::int32_t>().swap(shape.mesh.face_groups);
  std::vector<std::string>().swap(shape.mesh.group_names);
  shape.mesh.positions.reserve(shape.mesh.positions.size() + 1);
  return shape;
}

std::string SafeFileName(const std::string& name) {
  if (name.empty()) return "shape";
  std::string safe = name.substr(0, kMaxFileNameBytes);
  for (char& c : safe) {
    const bool keep = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
    if (!keep) c = '_';
  }
  if (safe[0] == '.') safe[0] = '_';
  return safe;
}

// "'a', 'b', 'c'", the first kMaxListedNames names then "...".
std::string NameList(std::span<const MeshShape> shapes) {
  std::string out;
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    if (i > 0) out += ", ";
    if (i == kMaxListedNames) {
      out += "...";
      break;
    }
    out += Quoted(shapes[i].name);
  }
  return out;
}

// Lower case, blanks removed: the key of names that differ only in letter case or blanks.
std::string LooseKey(std::string_view name) {
  std::string key;
  for (const char c : name) {
    if (c != ' ' && c != '\t' && c != '\v' && c != '\f' && c != '\r' && c != '\n') {
      key += AsciiLower(c);
    }
  }
  return key;
}

// "; shape names must match exactly: ..." when one of `shapes` differs from `name` only in
// letter case or blanks; empty otherwise.
std::string NearMatchHint(const std::string& name, std::span<const MeshShape> shapes) {
  const std::string key = LooseKey(name);
  for (const MeshShape& shape : shapes) {
    if (LooseKey(shape.name) == key) {
      return fmt::format(
          "; shape names must match exactly: {} differs from {} only in letter case or blanks",
          Quoted(shape.name), Quoted(name));
    }
  }
  return {};
}

Status CheckDistinctNames(std::span<const MeshShape> shapes, const std::string& source) {
  if (shapes.empty()) return Status::Error(source + ": no shapes");
  std::unordered_set<std::string_view> seen;
  for (const MeshShape& shape : shapes) {
    if (!seen.insert(shape.name).second) {
      return Status::Error(fmt::format("{}: two shapes named {}", source, Quoted(shape.name)));
    }
  }
  return Status::Ok();
}

}  // namespace

namespace {

// SplitShapes; `owned` (== &mesh, or null) lets a single shape take the mesh's arrays.
StatusOr<std::vector<MeshShape>> SplitShapesImpl(const Mesh& mesh, bool require_disjoint,
                                                 Mesh* owned) {
  const bool grouped = !mesh.face_groups.empty() || !mesh.group_names.empty();
  std::vector<MeshShape> shapes;
  if (!grouped) {
    shapes.push_back(WholeMesh(mesh, owned, SourceStem(mesh.source)));
    return shapes;
  }
  const std::size_t num_shapes = mesh.group_names.size();
  DISPEX_ASSIGN_OR_RETURN(const FacesByShape sorted,
                          SortFacesByShape(mesh, /*list=*/num_shapes > 1));
  if (num_shapes == 1) {
    std::string name = mesh.group_names[0];
    shapes.push_back(WholeMesh(mesh, owned, std::move(name)));
    return shapes;
  }

  constexpr auto kMaxId = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  DISPEX_CHECK_LE(mesh.num_faces(), kMaxId);
  DISPEX_CHECK_LE(mesh.num_vertices(), kMaxId);
  DISPEX_CHECK_LE(mesh.num_uvs(), kMaxId);
  DISPEX_CHECK_EQ(mesh.face_offsets.front(), 0u);
  DISPEX_CHECK_EQ(mesh.face_offsets.back(), mesh.face_indices.size());
  DISPEX_CHECK(!mesh.has_uvs() || mesh.face_uv_indices.size() == mesh.face_indices.size());
  DISPEX_ASSIGN_OR_RETURN(
      const ElementSplit vertices,
      ElementSplit::Build(mesh, mesh.face_indices, mesh.num_vertices(), num_shapes, "vertex"));
  if (require_disjoint) {
    if (const auto shared = vertices.FirstShared()) {
      return Status::Error(fmt::format(
          "{}: shapes {} and {} share vertex {}; a shape's faces must not share vertices with "
          "another shape's (give the whole surface one o/g name)",
          mesh.source, Quoted(mesh.group_names[static_cast<std::size_t>(shared->shape0)]),
          Quoted(mesh.group_names[static_cast<std::size_t>(shared->shape1)]),
          std::int64_t{shared->element} + 1));
    }
  }
  std::optional<ElementSplit> uvs;
  if (mesh.has_uvs()) {
    DISPEX_ASSIGN_OR_RETURN(uvs, ElementSplit::Build(mesh, mesh.face_uv_indices, mesh.num_uvs(),
                                                     num_shapes, "texture coordinate"));
  }
  DISPEX_RETURN_IF_ERROR(CheckTagIds(mesh));
  DISPEX_ASSIGN_OR_RETURN(std::vector<SubdivTags> tags,
                          SplitTags(mesh, sorted, vertices, require_disjoint));

  const std::vector<std::string> file_names = ShapeFileNames(mesh.group_names);
  shapes.resize(num_shapes);
  tbb::parallel_for(std::size_t{0}, num_shapes, [&](std::size_t g) {
    MeshShape& shape = shapes[g];
    shape.name = mesh.group_names[g];
    shape.file_name = file_names[g];
    shape.mesh.source = fmt::format("{} shape {}", mesh.source, Quoted(shape.name));
    BuildShapeMesh(mesh, static_cast<std::int32_t>(g), sorted.of(g), vertices,
                   uvs ? &*uvs : nullptr, shape.mesh);
    shape.mesh.tags = std::move(tags[g]);
  });
  return shapes;
}

}  // namespace

StatusOr<std::vector<MeshShape>> SplitShapes(const Mesh& mesh, bool require_disjoint) {
  return SplitShapesImpl(mesh, require_disjoint, nullptr);
}

StatusOr<std::vector<MeshShape>> SplitShapes(Mesh&& mesh, bool require_disjoint) {
  return SplitShapesImpl(mesh, require_disjoint, &mesh);
}

std::vector<std::string> ShapeFileNames(std::span<const std::string> names) {
  const std::size_t n = names.size();
  std::vector<std::string> out(n);
  std::vector<bool> suffixed(n, false);
  auto add_crc = [&](std::size_t i) {
    out[i] += fmt::format("-{:08x}", Crc32(names[i]));
    suffixed[i] = true;
  };
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = SafeFileName(names[i]);
    if (out[i] != names[i]) add_crc(i);
  }
  std::unordered_map<std::string, std::vector<std::size_t>> by_key;
  for (std::size_t i = 0; i < n; ++i) by_key[AsciiLower(out[i])].push_back(i);
  for (const auto& [key, same] : by_key) {
    if (same.size() < 2) continue;
    for (const std::size_t i : same) {
      if (!suffixed[i]) add_crc(i);
    }
  }
  // Still equal: the first keeps its name, the others get a number no name has.
  std::unordered_set<std::string> taken;
  for (std::size_t i = 0; i < n; ++i) taken.insert(AsciiLower(out[i]));
  std::unordered_set<std::string> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (kept.insert(AsciiLower(out[i])).second) continue;
    for (int k = 2;; ++k) {
      std::string candidate = fmt::format("{}-{}", out[i], k);
      if (taken.insert(AsciiLower(candidate)).second) {
        out[i] = std::move(candidate);
        break;
      }
    }
  }
  return out;
}

StatusOr<ShapeMatch> MatchShapes(std::span<const MeshShape> base, std::span<const MeshShape> sculpt,
                                 std::span<const std::string> selected,
                                 const std::string& base_source, const std::string& sculpt_source) {
  DISPEX_RETURN_IF_ERROR(CheckDistinctNames(base, base_source));
  DISPEX_RETURN_IF_ERROR(CheckDistinctNames(sculpt, sculpt_source));
  std::unordered_map<std::string_view, std::size_t> base_by_name, sculpt_by_name;
  for (std::size_t i = 0; i < base.size(); ++i) base_by_name.emplace(base[i].name, i);
  for (std::size_t j = 0; j < sculpt.size(); ++j) sculpt_by_name.emplace(sculpt[j].name, j);

  std::vector<bool> chosen(base.size(), selected.empty());
  for (const std::string& name : selected) {
    const auto it = base_by_name.find(name);
    if (it == base_by_name.end()) {
      return Status::Error(fmt::format("selected shape {} is not in {} (its shapes: {}){}",
                                       Quoted(name), base_source, NameList(base),
                                       NearMatchHint(name, base)));
    }
    if (chosen[it->second]) {
      return Status::Error(fmt::format("shape {} is selected twice", Quoted(name)));
    }
    chosen[it->second] = true;
  }

  ShapeMatch match;
  if (base.size() == 1 && sculpt.size() == 1) {
    match.base_index.push_back(0);
    match.sculpt_index.push_back(0);
    return match;
  }
  for (std::size_t i = 0; i < base.size(); ++i) {
    if (!chosen[i]) continue;
    const auto it = sculpt_by_name.find(base[i].name);
    if (it == sculpt_by_name.end()) {
      return Status::Error(fmt::format("{} has no shape {} (its shapes: {}){}", sculpt_source,
                                       Quoted(base[i].name), NameList(sculpt),
                                       NearMatchHint(base[i].name, sculpt)));
    }
    match.base_index.push_back(i);
    match.sculpt_index.push_back(it->second);
  }
  for (const MeshShape& shape : sculpt) {
    if (!base_by_name.contains(shape.name)) {
      match.warnings.push_back(fmt::format("{}: shape {} has no base shape of that name; not used",
                                           sculpt_source, Quoted(shape.name)));
    }
  }
  return match;
}

}  // namespace dispex
