#include "trace/embree_scene.h"

#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <new>

#include "trace/sculpt_check.h"

namespace dispex::trace {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

RTCBuildQuality ToRtc(BuildQuality quality) {
  switch (quality) {
    case BuildQuality::kLow:
      return RTC_BUILD_QUALITY_LOW;
    case BuildQuality::kMedium:
      return RTC_BUILD_QUALITY_MEDIUM;
    case BuildQuality::kHigh:
      return RTC_BUILD_QUALITY_HIGH;
  }
  return RTC_BUILD_QUALITY_MEDIUM;
}

}  // namespace

StatusOr<std::unique_ptr<EmbreeScene>> EmbreeScene::Build(const Mesh& mesh,
                                                          const TracerOptions& options) {
  std::unique_ptr<EmbreeScene> scene(new EmbreeScene());
  // The device first: its errors (an ISA this CPU lacks) are not the sculpt's.
  std::string isa_source;
  const std::string isa = ChosenIsa(options.isa, &isa_source);
  DISPEX_ASSIGN_OR_RETURN(scene->device_,
                          EmbreeDevice::Create(options.memory_limit_bytes, isa, isa_source));
  Status status;
  try {
    status = scene->Setup(mesh, options);
  } catch (const std::bad_alloc&) {
    status = Status::Error("out of memory setting up the sculpt's ray-tracing scene");
  }
  if (!status.ok()) {
    const std::string& source = mesh.source;
    // Validation messages already start with the file name; Embree's do not.
    if (!source.empty() && status.message().rfind(source, 0) != 0) return status.WithPrefix(source);
    return status;
  }
  return scene;
}

#if defined(__SANITIZE_THREAD__)
namespace {
// Under ThreadSanitizer: builds and releases of scenes one at a time across threads. Embree's
// allocator hands memory a build on one thread freed to a build on another (two shapes
// extracted side by side), through locks in libembree3 that ThreadSanitizer cannot see.
std::mutex& EmbreeMemoryLock() {
  static std::mutex lock;
  return lock;
}
}  // namespace
#endif

EmbreeScene::~EmbreeScene() {
#if defined(__SANITIZE_THREAD__)
  const std::lock_guard<std::mutex> lock(EmbreeMemoryLock());
#endif
  if (scene_ != nullptr) rtcReleaseScene(scene_);
  // device_ (declared first) is released after the scene that refers to it.
}

Status EmbreeScene::AddGeometry(unsigned geom_id, RTCGeometryType type, const std::int32_t* indices,
                                std::size_t count, std::size_t num_vertices,
                                RTCBuildQuality quality) {
  RTCGeometry geometry = rtcNewGeometry(device_->get(), type);
  if (geometry == nullptr) return device_->TakeError();
  const bool quads = type == RTC_GEOMETRY_TYPE_QUAD;
  // Embree only reads these buffers; its API takes them as non-const.
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                             const_cast<Float3*>(positions_), 0, sizeof(Float3), num_vertices);
  rtcSetSharedGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, quads ? RTC_FORMAT_UINT4 : RTC_FORMAT_UINT3,
      const_cast<std::int32_t*>(indices), 0, (quads ? 4 : 3) * sizeof(std::int32_t), count);
  rtcSetGeometryBuildQuality(geometry, quality);
  rtcCommitGeometry(geometry);
  rtcAttachGeometryByID(scene_, geometry, geom_id);
  rtcReleaseGeometry(geometry);  // the scene holds its own reference
  geometries_[geom_id] = GeometryView{indices, nullptr, count, quads ? 4 : 3};
  return device_->TakeError();
}

Status EmbreeScene::Setup(const Mesh& mesh, const TracerOptions& options) {
  const auto setup_start = Clock::now();
  SculptCounts counts;
  DISPEX_RETURN_IF_ERROR(CheckSculpt(mesh, &counts));

  scene_ = rtcNewScene(device_->get());
  if (scene_ == nullptr) return device_->TakeError();
  // The context filter is used only by the rare re-cast past a surface before a ray's
  // window (batch_kernels.h, CastInWindow); Embree requires the flag to call it.
  int flags = RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
  if (options.robust) flags |= RTC_SCENE_FLAG_ROBUST;
  if (options.compact) flags |= RTC_SCENE_FLAG_COMPACT;
  rtcSetSceneFlags(scene_, static_cast<RTCSceneFlags>(flags));
  const RTCBuildQuality quality = ToRtc(options.quality);
  rtcSetSceneBuildQuality(scene_, quality);

  // Embree may read 16 bytes at the last vertex: share the mesh's vector when its capacity
  // covers that, else make one padded copy.
  const std::size_t num_vertices = mesh.num_vertices();
  if (mesh.positions.capacity() >= num_vertices + 1) {
    positions_ = mesh.positions.data();
    stats_.shared_vertices = true;
  } else {
    vertex_copy_.reserve(num_vertices + 1);
    vertex_copy_.assign(mesh.positions.begin(), mesh.positions.end());
    positions_ = vertex_copy_.data();
    stats_.copied_bytes += vertex_copy_.capacity() * sizeof(Float3);
  }

  const std::size_t num_faces = mesh.num_faces();
  const bool all_quads = counts.quads == num_faces;
  const bool all_triangles = counts.triangle_faces == num_faces;
  const std::int32_t* quad_indices = nullptr;
  const std::int32_t* triangle_indices = nullptr;
  if (all_quads) {
    quad_indices = mesh.face_indices.data();
    stats_.shared_indices = true;
  } else if (all_triangles) {
    triangle_indices = mesh.face_indices.data();
    stats_.shared_indices = true;
  } else {
    // Mixed: quads keep their 4 indices, other faces are fanned from their first vertex.
    quad_indices_.reserve(4 * counts.quads);
    quad_faces_.reserve(counts.quads);
    triangle_indices_.reserve(3 * counts.triangles);
    triangle_faces_.reserve(counts.triangles);
    for (std::size_t f = 0; f < num_faces; ++f) {
      const auto face = mesh.face(f);
      const auto face_id = static_cast<std::int32_t>(f);
      if (face.size() == 4) {
        quad_indices_.insert(quad_indices_.end(), face.begin(), face.end());
        quad_faces_.push_back(face_id);
        continue;
      }
      for (std::size_t k = 1; k + 1 < face.size(); ++k) {
        triangle_indices_.insert(triangle_indices_.end(), {face[0], face[k], face[k + 1]});
        triangle_faces_.push_back(face_id);
      }
    }
    quad_indices = quad_indices_.data();
    triangle_indices = triangle_indices_.data();
    stats_.copied_bytes += (quad_indices_.capacity() + quad_faces_.capacity() +
                            triangle_indices_.capacity() + triangle_faces_.capacity()) *
                           sizeof(std::int32_t);
  }

  if (counts.quads > 0) {
    DISPEX_RETURN_IF_ERROR(AddGeometry(kQuadGeometry, RTC_GEOMETRY_TYPE_QUAD, quad_indices,
                                       counts.quads, num_vertices, quality));
    if (!quad_faces_.empty()) geometries_[kQuadGeometry].face_of_prim = quad_faces_.data();
  }
  if (counts.triangles > 0) {
    DISPEX_RETURN_IF_ERROR(AddGeometry(kTriangleGeometry, RTC_GEOMETRY_TYPE_TRIANGLE,
                                       triangle_indices, counts.triangles, num_vertices, quality));
    if (!triangle_faces_.empty()) {
      geometries_[kTriangleGeometry].face_of_prim = triangle_faces_.data();
    }
  }
  DISPEX_RETURN_IF_ERROR(CheckVertexPrimsFit(counts.quads, counts.triangles));
  num_quads_ = counts.quads;
  num_vertices_ = num_vertices;
  if (options.normal_queries) vertex_prims();
  stats_.setup_seconds = Seconds(setup_start);

  const auto build_start = Clock::now();
#if defined(__SANITIZE_THREAD__)
  // libembree3 is not instrumented: the TBB tasks of its BVH build read a task_group_context
  // on this thread's stack, and ThreadSanitizer cannot see that they finished before the frame
  // is reused (scripts/tsan-extract.sh). Under TSan the build runs on this thread alone, and
  // one build at a time (EmbreeMemoryLock).
  {
    const std::lock_guard<std::mutex> lock(EmbreeMemoryLock());
    tbb::task_arena(1).execute([&] { rtcCommitScene(scene_); });
  }
#else
  rtcCommitScene(scene_);
#endif
  stats_.build_seconds = Seconds(build_start);
  DISPEX_RETURN_IF_ERROR(device_->TakeError());

  RTCBounds bounds;
  rtcGetSceneBounds(scene_, &bounds);
  for (const float c : {bounds.lower_x, bounds.lower_y, bounds.lower_z, bounds.upper_x,
                        bounds.upper_y, bounds.upper_z}) {
    if (std::isfinite(c)) scale_ = std::max(scale_, std::fabs(c));
  }
  if (options.scale > 0) scale_ = options.scale;
  stats_.scale = scale_;
  retry_misses_ = options.retry_misses;
  verify_hits_ = options.verify_hits;

  stats_.faces = num_faces;
  stats_.quads = counts.quads;
  stats_.triangles = counts.triangles;
  stats_.backend_bytes = device_->bytes();
  stats_.backend_peak_bytes = device_->peak_bytes();
  stats_.backend = fmt::format(
      "{}, {} build{}{}{}{}", device_->Describe(), BuildQualityName(options.quality),
      options.robust ? ", robust" : "", options.compact ? ", compact" : "",
      options.retry_misses ? ", retry misses" : "", options.verify_hits ? ", verify hits" : "");
  return Status::Ok();
}

const VertexPrims& EmbreeScene::vertex_prims() const {
  std::call_once(vertex_prims_once_, [&] {
    // Isolated: a thread waiting in the build's parallel loops must not pick up another batch
    // of queries, which would wait on this very call.
    tbb::this_task_arena::isolate([&] {
      const GeometryView& q = geometries_[kQuadGeometry];
      const GeometryView& t = geometries_[kTriangleGeometry];
      vertex_prims_ =
          BuildVertexPrims(q.indices, q.count, t.indices, t.count, positions_, num_vertices_);
    });
  });
  return vertex_prims_;
}

}  // namespace dispex::trace
