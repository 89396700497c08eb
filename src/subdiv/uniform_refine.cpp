// Uniform refinement with limit positions. Topology from Far::TopologyRefiner::RefineUniform
// to level L-1 (on a refiner sharing the cage's base level); the last split, L-1 -> L, is
// written here in OpenSubdiv's own numbering (Vtr::internal::Refinement, uniform, vertices
// not ordered from faces first): child vertices of vertices first (same index), then of
// faces, then of edges; child faces in parent order, child j of a quad keeping the parent's
// orientation (its vertex j is the child of corner j, then the child of edge j, the face
// centre, the child of edge j-1), of an n-gon starting at the child of corner j. Letting
// OpenSubdiv build level L would cost ~140 bytes per level-L face for topology that is only
// read once; generated here it costs nothing, which is what lets 17K-face cages reach
// level 6. The tests compare every face-vertex list with OpenSubdiv's own level L.
//
// Positions and normals come from the limit evaluator, not from Far::PrimvarRefiner::Limit,
// which is not exact at undecayed semi-sharp creases, darts and interior valence-2 vertices.
//
// Where each refined vertex lies on the base limit surface follows from the refinement
// itself: a level-l face is a square of its Ptex face, and its children are the quadrants,
// with child vertices of its corners, edge midpoints and centre at the corresponding (u,v).
// At level 1 an n-gon's child j is exactly Ptex sub-face j (origin at corner j, u towards the
// midpoint of edge j, centre at (1,1)). Walking the refinement hierarchy depth-first per base
// face therefore gives every leaf face's (Ptex face, corner (u,v)) without storing per-level
// charts.
#include <fmt/format.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/check.h"
#include "dispex/subdiv.h"
#include "subdiv/face_sampler.h"
#include "subdiv/osd_messages.h"
#include "subdiv/surface_impl.h"

namespace dispex {
namespace {

namespace Far = OpenSubdiv::Far;

constexpr int kMaxLevels = 8;
constexpr std::int32_t kNoOwner = std::numeric_limits<std::int32_t>::max();

// The last split, from the refiner's deepest level (the parent level) to the output level.
class LastSplit {
 public:
  // `parent` is level 0 (faces of any size) or a refined level (all quads).
  LastSplit(const Far::TopologyLevel& parent, bool all_quads) : parent_(parent) {
    num_vertices_ = parent.GetNumVertices();
    num_faces_ = parent.GetNumFaces();
    num_child_faces_ = 4 * static_cast<std::int64_t>(num_faces_);
    if (!all_quads) {
      first_child_.resize(static_cast<std::size_t>(num_faces_) + 1);
      std::int64_t next = 0;
      for (int f = 0; f < num_faces_; ++f) {
        first_child_[f] = next;
        next += parent.GetFaceVertices(f).size();
      }
      first_child_[num_faces_] = next;
      num_child_faces_ = next;
    }
  }

  std::int64_t num_child_faces() const { return num_child_faces_; }
  std::int64_t num_child_vertices() const {
    return static_cast<std::int64_t>(num_vertices_) + num_faces_ + parent_.GetNumEdges();
  }
  int ChildFace(int parent_face, int j) const {
    return static_cast<int>((first_child_.empty() ? 4 * static_cast<std::int64_t>(parent_face)
                                                  : first_child_[parent_face]) +
                            j);
  }

  // Vertices of child j of `parent_face`, and for each its position in the parent's corner
  // frame: `where[k]` = 0..n-1 the child of corner m, n+m the child of edge m, 2n the centre.
  void ChildVertices(int parent_face, int j, int out[4], int where[4]) const {
    const Far::ConstIndexArray fv = parent_.GetFaceVertices(parent_face);
    const Far::ConstIndexArray fe = parent_.GetFaceEdges(parent_face);
    const int n = fv.size();
    const int jp = (j + n - 1) % n;
    const int vertex = fv[j];
    const int next_edge = num_vertices_ + num_faces_ + fe[j];
    const int centre = num_vertices_ + parent_face;
    const int prev_edge = num_vertices_ + num_faces_ + fe[jp];
    const int base = (n == 4) ? j : 0;  // quads keep the parent's orientation
    out[base % 4] = vertex;
    where[base % 4] = j;
    out[(base + 1) % 4] = next_edge;
    where[(base + 1) % 4] = n + j;
    out[(base + 2) % 4] = centre;
    where[(base + 2) % 4] = 2 * n;
    out[(base + 3) % 4] = prev_edge;
    where[(base + 3) % 4] = n + jp;
  }

 private:
  const Far::TopologyLevel& parent_;
  int num_vertices_ = 0;
  int num_faces_ = 0;
  std::int64_t num_child_faces_ = 0;
  std::vector<std::int64_t> first_child_;  // empty when every parent face is a quad
};

// Depth-first walk from a base face to its leaf faces at the output level, carrying each
// face's Ptex face and the (u,v) of its corners. Scratch is reused across base faces.
class LeafWalker {
 public:
  LeafWalker(const Far::TopologyRefiner& refiner, const LastSplit* split,
             const LimitSurface::Impl& surface, int levels)
      : refiner_(refiner), split_(split), s_(surface), levels_(levels) {}

  // Calls visit(leaf_face, corners, vertices, corner_ptex, corner_uv) for each leaf face
  // under base face `f`; corner_uv holds 2 floats per corner, in the leaf's vertex order.
  template <class Visit>
  void Walk(int f, Visit&& visit) {
    const Far::TopologyLevel& base = refiner_.GetLevel(0);
    const Far::ConstIndexArray fv = base.GetFaceVertices(f);
    const int n = fv.size();
    const int first = s_.first_ptex[f];
    static constexpr float kQuad[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

    if (levels_ == 0) {
      corner_ptex_.resize(n);
      corner_uv_.resize(2 * static_cast<std::size_t>(n));
      for (int k = 0; k < n; ++k) {
        corner_ptex_[k] = (n == 4) ? first : first + k;
        corner_uv_[2 * k] = (n == 4) ? kQuad[k][0] : 0.0f;
        corner_uv_[2 * k + 1] = (n == 4) ? kQuad[k][1] : 0.0f;
      }
      visit(f, n, fv.begin(), corner_ptex_.data(), corner_uv_.data());
      return;
    }

    stack_.clear();
    if (n == 4) {
      Node root{0, f, first, {}};
      for (int k = 0; k < 4; ++k) {
        root.uv[k][0] = kQuad[k][0];
        root.uv[k][1] = kQuad[k][1];
      }
      stack_.push_back(root);
    } else if (levels_ == 1) {
      // The n sub-faces are the leaves: child j is Ptex sub-face j.
      for (int j = 0; j < n; ++j) {
        int vertices[4], where[4];
        split_->ChildVertices(f, j, vertices, where);
        float uv[8];
        for (int m = 0; m < 4; ++m) {
          const int w = where[m];
          const int corner = (w == j) ? 0 : (w == n + j) ? 1 : (w == 2 * n) ? 2 : 3;
          uv[2 * m] = kQuad[corner][0];
          uv[2 * m + 1] = kQuad[corner][1];
        }
        const int ptex[4] = {first + j, first + j, first + j, first + j};
        visit(split_->ChildFace(f, j), 4, vertices, ptex, uv);
      }
      return;
    } else {
      // Level 1 under an n-gon, from OpenSubdiv: child j is Ptex sub-face j.
      const Far::TopologyLevel& next = refiner_.GetLevel(1);
      const Far::ConstIndexArray fe = base.GetFaceEdges(f);
      const Far::ConstIndexArray children = base.GetFaceChildFaces(f);
      const Far::Index centre = base.GetFaceChildVertex(f);
      for (Far::Index child : children) {
        const Far::ConstIndexArray cv = next.GetFaceVertices(child);
        int corner = -1;
        for (int j = 0; j < n && corner < 0; ++j) {
          const Far::Index vc = base.GetVertexChildVertex(fv[j]);
          for (int m = 0; m < cv.size(); ++m) corner = (cv[m] == vc) ? j : corner;
        }
        DISPEX_CHECK_GE(corner, 0);
        const Far::Index ids[4] = {base.GetVertexChildVertex(fv[corner]),
                                   base.GetEdgeChildVertex(fe[corner]), centre,
                                   base.GetEdgeChildVertex(fe[(corner + n - 1) % n])};
        Node node{1, child, first + corner, {}};
        for (int m = 0; m < 4; ++m) {
          int which = -1;
          for (int c = 0; c < 4; ++c) which = (cv[m] == ids[c]) ? c : which;
          DISPEX_CHECK_GE(which, 0);
          node.uv[m][0] = kQuad[which][0];
          node.uv[m][1] = kQuad[which][1];
        }
        stack_.push_back(node);
      }
    }

    while (!stack_.empty()) {
      const Node node = stack_.back();
      stack_.pop_back();
      if (node.level == levels_ - 1) {
        VisitLeaves(node, visit);
      } else {
        Split(node);
      }
    }
  }

 private:
  struct Node {
    int level;
    int face;
    int ptex;
    float uv[4][2];
  };

  // The (u,v) of a quad node's corners (0..3), edge midpoints (4..7) and centre (8).
  static void ChildUvs(const Node& node, float uv[9][2]) {
    for (int j = 0; j < 4; ++j) {
      const int k = (j + 1) % 4;
      uv[j][0] = node.uv[j][0];
      uv[j][1] = node.uv[j][1];
      uv[4 + j][0] = 0.5f * (node.uv[j][0] + node.uv[k][0]);
      uv[4 + j][1] = 0.5f * (node.uv[j][1] + node.uv[k][1]);
    }
    uv[8][0] = 0.25f * (node.uv[0][0] + node.uv[1][0] + node.uv[2][0] + node.uv[3][0]);
    uv[8][1] = 0.25f * (node.uv[0][1] + node.uv[1][1] + node.uv[2][1] + node.uv[3][1]);
  }

  // The last split of a quad node, in OpenSubdiv's numbering (LastSplit).
  template <class Visit>
  void VisitLeaves(const Node& node, Visit& visit) {
    float uv9[9][2];
    ChildUvs(node, uv9);
    const int ptex[4] = {node.ptex, node.ptex, node.ptex, node.ptex};
    for (int j = 0; j < 4; ++j) {
      int vertices[4], where[4];
      split_->ChildVertices(node.face, j, vertices, where);
      float uv[8];
      for (int m = 0; m < 4; ++m) {
        uv[2 * m] = uv9[where[m]][0];
        uv[2 * m + 1] = uv9[where[m]][1];
      }
      visit(split_->ChildFace(node.face, j), 4, vertices, ptex, uv);
    }
  }

  // Pushes the four children of a quad node from OpenSubdiv's refinement.
  void Split(const Node& node) {
    const Far::TopologyLevel& level = refiner_.GetLevel(node.level);
    const Far::TopologyLevel& next = refiner_.GetLevel(node.level + 1);
    const Far::ConstIndexArray fv = level.GetFaceVertices(node.face);
    const Far::ConstIndexArray fe = level.GetFaceEdges(node.face);
    DISPEX_CHECK_EQ(fv.size(), 4);
    Far::Index ids[9];
    float uv[9][2];
    ChildUvs(node, uv);
    for (int j = 0; j < 4; ++j) {
      ids[j] = level.GetVertexChildVertex(fv[j]);
      ids[4 + j] = level.GetEdgeChildVertex(fe[j]);
    }
    ids[8] = level.GetFaceChildVertex(node.face);
    const Far::ConstIndexArray children = level.GetFaceChildFaces(node.face);
    for (int c = children.size() - 1; c >= 0; --c) {
      const Far::ConstIndexArray cv = next.GetFaceVertices(children[c]);
      Node child{node.level + 1, children[c], node.ptex, {}};
      for (int m = 0; m < 4; ++m) {
        int which = -1;
        for (int q = 0; q < 9; ++q) which = (cv[m] == ids[q]) ? q : which;
        DISPEX_CHECK_GE(which, 0);
        child.uv[m][0] = uv[which][0];
        child.uv[m][1] = uv[which][1];
      }
      stack_.push_back(child);
    }
  }

  const Far::TopologyRefiner& refiner_;
  const LastSplit* split_;
  const LimitSurface::Impl& s_;
  int levels_;
  std::vector<Node> stack_;
  std::vector<int> corner_ptex_;
  std::vector<float> corner_uv_;
};

struct Worker {
  Worker(const Far::TopologyRefiner& refiner, const LastSplit* split, const LimitSurface::Impl& s,
         int levels)
      : walker(refiner, split, s, levels), sampler(s) {}
  LeafWalker walker;
  subdiv::FaceSampler sampler;
};

void AtomicMin(std::int32_t& slot, std::int32_t value) {
  std::atomic_ref<std::int32_t> ref(slot);
  std::int32_t current = ref.load(std::memory_order_relaxed);
  while (value < current && !ref.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
}

// RefineUniform's state, built by its steps in the order RefineUniform calls them.
struct Refinement {
  Refinement(const LimitSurface::Impl& surface, int levels_, const RefineOptions& options_)
      : s(surface),
        levels(levels_),
        options(options_),
        arena(options_.threads > 0 ? options_.threads : tbb::task_arena::automatic) {}

  const LimitSurface::Impl& s;
  const int levels;
  const RefineOptions& options;
  tbb::task_arena arena;
  tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers;

  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<LastSplit> split;
  int num_vertices = 0, num_faces = 0;      // at the output level, holes included
  std::vector<std::int32_t> owner;          // per vertex: the lowest kept leaf face using it
  std::vector<std::uint8_t> keep;           // per leaf face: not part of a hole
  std::vector<std::uint32_t> leaf_offsets;  // only for levels == 0 (faces of any size)
  // Face-vertex lists of all leaves in OpenSubdiv's order (holes included, dropped at the end).
  std::vector<std::int32_t> leaf_vertices;
  std::vector<std::int32_t> new_vertex, new_face;  // compacted ids, -1 for dropped ones
  std::int32_t kept_vertices = 0, kept_faces = 0;
  RefinedMesh out;

  Worker& WorkerForThread() {
    auto& w = workers.local();
    if (!w) w = std::make_unique<Worker>(*refiner, split.get(), s, levels);
    return *w;
  }
  bool HasSurface(int base_face) const { return s.ptex_hole[s.first_ptex[base_face]] == 0; }
  std::size_t LeafOffset(int face) const {
    return levels == 0 ? leaf_offsets[face] : 4 * static_cast<std::size_t>(face);
  }

  // OpenSubdiv refines to the level above the output (full topology: the last split needs
  // its edges).
  Status BuildTopology(std::uint64_t expected_faces) {
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    refiner.reset(Factory::Create(*s.refiner));
    if (levels > 1) {
      subdiv::OsdMessageCapture capture;
      Far::TopologyRefiner::UniformOptions uniform(levels - 1);
      uniform.fullTopologyInLastLevel = true;
      refiner->RefineUniform(uniform);
      if (!capture.empty()) {
        return Status::Error(s.source +
                             ": OpenSubdiv uniform refinement failed: " + capture.messages());
      }
    }
    if (levels == 0) {
      num_vertices = refiner->GetLevel(0).GetNumVertices();
      num_faces = refiner->GetLevel(0).GetNumFaces();
    } else {
      split = std::make_unique<LastSplit>(refiner->GetLevel(levels - 1), levels > 1);
      DISPEX_CHECK_EQ(static_cast<std::uint64_t>(split->num_child_faces()), expected_faces);
      num_vertices = static_cast<int>(split->num_child_vertices());
      num_faces = static_cast<int>(split->num_child_faces());
    }
    out.levels = levels;
    out.refined_vertices = static_cast<std::size_t>(num_vertices);
    out.refined_faces = static_cast<std::size_t>(num_faces);
    out.mesh.source = fmt::format("{} (level {})", s.source, levels);
    return Status::Ok();
  }

  // Pass 1: each vertex's owner is the first (lowest-numbered) kept leaf face using it; the
  // leaf faces' vertex lists are kept for the output.
  void FindOwners() {
    owner.assign(num_vertices, kNoOwner);
    keep.assign(num_faces, 0);
    if (levels == 0) {
      leaf_offsets.resize(static_cast<std::size_t>(num_faces) + 1);
      for (int f = 0; f < num_faces; ++f) {
        leaf_offsets[f + 1] = leaf_offsets[f] + static_cast<std::uint32_t>(
                                                    refiner->GetLevel(0).GetFaceVertices(f).size());
      }
    }
    leaf_vertices.resize(levels == 0 ? leaf_offsets.back()
                                     : 4 * static_cast<std::size_t>(num_faces));
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<int>(0, s.num_base_faces()), [&](const tbb::blocked_range<int>& r) {
            LeafWalker& walker = WorkerForThread().walker;
            for (int f = r.begin(); f != r.end(); ++f) {
              if (!HasSurface(f)) continue;
              walker.Walk(
                  f, [&](int face, int corners, const int* vertices, const int*, const float*) {
                    keep[face] = 1;
                    std::int32_t* dst = &leaf_vertices[LeafOffset(face)];
                    for (int m = 0; m < corners; ++m) {
                      dst[m] = vertices[m];
                      AtomicMin(owner[vertices[m]], face);
                    }
                  });
            }
          });
    });
  }

  // Compaction: vertices and faces of holes go, the rest keep OpenSubdiv's order.
  void Compact() {
    new_vertex.assign(num_vertices, -1);
    for (int v = 0; v < num_vertices; ++v) {
      if (owner[v] != kNoOwner) new_vertex[v] = kept_vertices++;
    }
    if (options.face_charts) new_face.assign(num_faces, -1);
    for (int f = 0; f < num_faces; ++f) {
      if (!keep[f]) continue;
      if (options.face_charts) new_face[f] = kept_faces;
      ++kept_faces;
    }
    out.mesh.positions.resize(kept_vertices);
    out.normals.resize(3 * static_cast<std::size_t>(kept_vertices));
    out.ptex_faces.resize(kept_vertices);
    out.uvs.resize(2 * static_cast<std::size_t>(kept_vertices));
    if (options.face_charts) {
      out.face_ptex.resize(kept_faces);
      out.face_uvs.resize(8 * static_cast<std::size_t>(kept_faces));
    }
  }

  // Pass 2: locate and evaluate every vertex from its owner face. A face OpenSubdiv fails
  // on stops the work; the lowest such base face is reported, whatever the scheduling.
  Status EvaluateVertices() {
    std::atomic<int> failed_face{std::numeric_limits<int>::max()};
    std::mutex failure_mutex;
    std::string failure;
    Mesh& mesh = out.mesh;
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<int>(0, s.num_base_faces()), [&](const tbb::blocked_range<int>& r) {
            Worker& w = WorkerForThread();
            for (int f = r.begin(); f != r.end(); ++f) {
              if (!HasSurface(f) || f > failed_face.load(std::memory_order_relaxed)) continue;
              bool ok = true;
              w.walker.Walk(f, [&](int face, int corners, const int* vertices, const int* ptex,
                                   const float* uv) {
                for (int m = 0; m < corners && ok; ++m) {
                  if (owner[vertices[m]] != face) continue;
                  const std::int32_t v = new_vertex[vertices[m]];
                  if (w.sampler.Bind(ptex[m]) != subdiv::FaceSampler::BindResult::kOk) {
                    ok = false;
                    std::lock_guard<std::mutex> lock(failure_mutex);
                    if (f < failed_face.load()) {
                      failed_face = f;
                      failure = w.sampler.error();
                    }
                    break;
                  }
                  float p[3];
                  w.sampler.Point(uv[2 * m], uv[2 * m + 1], p,
                                  &out.normals[3 * static_cast<std::size_t>(v)]);
                  mesh.positions[v] = Float3{p[0], p[1], p[2]};
                  out.ptex_faces[v] = PtexFaceId(ptex[m]);
                  out.uvs[2 * static_cast<std::size_t>(v)] = uv[2 * m];
                  out.uvs[2 * static_cast<std::size_t>(v) + 1] = uv[2 * m + 1];
                }
                if (options.face_charts) {
                  const std::size_t nf = static_cast<std::size_t>(new_face[face]);
                  out.face_ptex[nf] = PtexFaceId(ptex[0]);
                  for (int k = 0; k < 8; ++k) out.face_uvs[8 * nf + k] = uv[k];
                }
              });
            }
          });
    });
    if (failed_face.load() != std::numeric_limits<int>::max()) {
      return Status::Error(
          fmt::format("{}: OpenSubdiv could not build the limit surface of base face {}: {}",
                      s.source, failed_face.load(), failure));
    }
    return Status::Ok();
  }

  // Faces, in OpenSubdiv's order, compacted in place.
  void WriteFaces() {
    owner = {};
    workers.clear();  // the walkers read the topology released next
    refiner.reset();  // the topology is all in leaf_vertices now
    split.reset();
    Mesh& mesh = out.mesh;
    std::size_t write = 0;
    mesh.face_offsets.reserve(static_cast<std::size_t>(kept_faces) + 1);
    mesh.face_offsets.push_back(0);
    for (int f = 0; f < num_faces; ++f) {
      if (!keep[f]) continue;
      const std::size_t begin = LeafOffset(f);
      const std::size_t end = levels == 0 ? leaf_offsets[f + 1] : begin + 4;
      for (std::size_t i = begin; i < end; ++i)
        leaf_vertices[write++] = new_vertex[leaf_vertices[i]];
      mesh.face_offsets.push_back(static_cast<std::uint32_t>(write));
    }
    leaf_vertices.resize(write);
    leaf_vertices.shrink_to_fit();
    mesh.face_indices = std::move(leaf_vertices);
  }
};

// Checks the arguments; returns the number of faces at the output level, holes included.
StatusOr<std::uint64_t> CountRefinedFaces(const LimitSurface::Impl& s, int levels,
                                          const RefineOptions& options) {
  if (levels < 0 || levels > kMaxLevels) {
    return Status::Error(
        fmt::format("{}: refinement level {} outside 0..{}", s.source, levels, kMaxLevels));
  }
  if (options.threads < 0) {
    return Status::Error(fmt::format("{}: thread count {} is negative", s.source, options.threads));
  }
  if (options.face_charts && levels == 0) {
    return Status::Error(s.source + ": face charts need at least one refinement level");
  }
  std::uint64_t expected_faces = 0;
  for (int f = 0; f < s.num_base_faces(); ++f) {
    const std::uint64_t n = s.face_size(f);
    expected_faces += (levels == 0) ? 1 : ((n == 4 ? 4 : n) << (2 * (levels - 1)));
  }
  if (levels > 0 && 4 * expected_faces > std::numeric_limits<std::int32_t>::max()) {
    return Status::Error(
        fmt::format("{}: {} refinement levels make {} faces, more than 32-bit indices allow",
                    s.source, levels, expected_faces));
  }
  return expected_faces;
}

}  // namespace

StatusOr<RefinedMesh> RefineUniform(const LimitSurface& surface, int levels,
                                    const RefineOptions& options) {
  DISPEX_ASSIGN_OR_RETURN(const std::uint64_t expected_faces,
                          CountRefinedFaces(SurfaceImpl(surface), levels, options));
  Refinement refinement(SurfaceImpl(surface), levels, options);
  DISPEX_RETURN_IF_ERROR(refinement.BuildTopology(expected_faces));
  refinement.FindOwners();
  refinement.Compact();
  DISPEX_RETURN_IF_ERROR(refinement.EvaluateVertices());
  refinement.WriteFaces();
  return std::move(refinement.out);
}

}  // namespace dispex
