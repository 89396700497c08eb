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

#if defined(__SANITIZE_THREAD__)
// Under ThreadSanitizer: builds and releases of scenes one at a time across threads. Embree's
// allocator hands memory a build on one thread freed to a build on another (two shapes
// extracted side by side), through locks in libembree3 that ThreadSanitizer cannot see.
std::mutex& EmbreeMemoryLock() {
  static std::mutex lock;
  return lock;
}
#endif

// A new scene with the options' flags and build quality (nullptr when Embree fails).
RTCScene NewScene(RTCDevice device, const TracerOptions& options) {
  RTCScene scene = rtcNewScene(device);
  if (scene == nullptr) return nullptr;
  // The context filter is used only by the rare re-cast past a surface before a ray's
  // window (batch_kernels.h, CastInWindow); Embree requires the flag to call it.
  int flags = RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;
  if (options.robust) flags |= RTC_SCENE_FLAG_ROBUST;
  if (options.compact) flags |= RTC_SCENE_FLAG_COMPACT;
  rtcSetSceneFlags(scene, static_cast<RTCSceneFlags>(flags));
  rtcSetSceneBuildQuality(scene, ToRtc(options.quality));
  return scene;
}

// The vertices Embree reads, which may read 16 bytes at the last one: the mesh's own vector
// when its capacity covers that, else one padded copy in `copy`.
const Float3* PaddedPositions(const Mesh& mesh, std::vector<Float3>& copy, TracerStats& stats) {
  const std::size_t num_vertices = mesh.num_vertices();
  if (mesh.positions.capacity() >= num_vertices + 1) {
    stats.shared_vertices = true;
    return mesh.positions.data();
  }
  copy.reserve(num_vertices + 1);
  copy.assign(mesh.positions.begin(), mesh.positions.end());
  stats.copied_bytes += copy.capacity() * sizeof(Float3);
  return copy.data();
}

// A mixed mesh's quads (their 4 indices each) and its other faces fanned from their first
// vertex into triangles, with the sculpt face of each.
void SplitMixedFaces(const Mesh& mesh, const SculptCounts& counts,
                     std::vector<std::int32_t>& quad_indices, std::vector<std::int32_t>& quad_faces,
                     std::vector<std::int32_t>& triangle_indices,
                     std::vector<std::int32_t>& triangle_faces) {
  quad_indices.reserve(4 * counts.quads);
  quad_faces.reserve(counts.quads);
  triangle_indices.reserve(3 * counts.triangles);
  triangle_faces.reserve(counts.triangles);
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) {
    const auto face = mesh.face(f);
    const auto face_id = static_cast<std::int32_t>(f);
    if (face.size() == 4) {
      quad_indices.insert(quad_indices.end(), face.begin(), face.end());
      quad_faces.push_back(face_id);
      continue;
    }
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      triangle_indices.insert(triangle_indices.end(), {face[0], face[k], face[k + 1]});
      triangle_faces.push_back(face_id);
    }
  }
}

// Builds the scene's BVH.
void CommitScene(RTCScene scene) {
#if defined(__SANITIZE_THREAD__)
  // libembree3 is not instrumented: the TBB tasks of its BVH build read a task_group_context
  // on this thread's stack, and ThreadSanitizer cannot see that they finished before the frame
  // is reused (scripts/tsan-extract.sh). Under TSan the build runs on this thread alone, and
  // one build at a time (EmbreeMemoryLock).
  const std::lock_guard<std::mutex> lock(EmbreeMemoryLock());
  tbb::task_arena(1).execute([&] { rtcCommitScene(scene); });
#else
  rtcCommitScene(scene);
#endif
}

// The largest absolute finite coordinate of the scene's bounds (0 when none is finite).
float BoundsScale(RTCScene scene) {
  RTCBounds bounds;
  rtcGetSceneBounds(scene, &bounds);
  float scale = 0;
  for (const float c : {bounds.lower_x, bounds.lower_y, bounds.lower_z, bounds.upper_x,
                        bounds.upper_y, bounds.upper_z}) {
    if (std::isfinite(c)) scale = std::max(scale, std::fabs(c));
  }
  return scale;
}

// What the stats call the backend: the device, the build and the guard's settings.
std::string BackendName(const EmbreeDevice& device, const TracerOptions& options) {
  return fmt::format("{}, {} build{}{}{}{}", device.Describe(), BuildQualityName(options.quality),
                     options.robust ? ", robust" : "", options.compact ? ", compact" : "",
                     options.retry_misses ? ", retry misses" : "",
                     options.verify_hits ? ", verify hits" : "");
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
  scene_ = NewScene(device_->get(), options);
  if (scene_ == nullptr) return device_->TakeError();
  positions_ = PaddedPositions(mesh, vertex_copy_, stats_);

  // All quads or all triangles: Embree reads the mesh's own indices.
  const std::size_t num_faces = mesh.num_faces();
  const std::int32_t* quad_indices = nullptr;
  const std::int32_t* triangle_indices = nullptr;
  if (counts.quads == num_faces) {
    quad_indices = mesh.face_indices.data();
    stats_.shared_indices = true;
  } else if (counts.triangle_faces == num_faces) {
    triangle_indices = mesh.face_indices.data();
    stats_.shared_indices = true;
  } else {
    SplitMixedFaces(mesh, counts, quad_indices_, quad_faces_, triangle_indices_, triangle_faces_);
    quad_indices = quad_indices_.data();
    triangle_indices = triangle_indices_.data();
    stats_.copied_bytes += (quad_indices_.capacity() + quad_faces_.capacity() +
                            triangle_indices_.capacity() + triangle_faces_.capacity()) *
                           sizeof(std::int32_t);
  }

  const std::size_t num_vertices = mesh.num_vertices();
  const RTCBuildQuality quality = ToRtc(options.quality);
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
  CommitScene(scene_);
  stats_.build_seconds = Seconds(build_start);
  DISPEX_RETURN_IF_ERROR(device_->TakeError());

  scale_ = BoundsScale(scene_);
  if (options.scale > 0) scale_ = options.scale;
  retry_misses_ = options.retry_misses;
  verify_hits_ = options.verify_hits;
  stats_.scale = scale_;
  stats_.faces = num_faces;
  stats_.quads = counts.quads;
  stats_.triangles = counts.triangles;
  stats_.backend_bytes = device_->bytes();
  stats_.backend_peak_bytes = device_->peak_bytes();
  stats_.backend = BackendName(*device_, options);
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
