// The Embree backend of dispex::Tracer: an EmbreeScene plus the batch kernels, dispatched
// once per batch on the configured RayMode.
#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "core/check.h"
#include "dispex/trace.h"
#include "trace/batch_kernels.h"
#include "trace/embree_point_query.h"
#include "trace/embree_scene.h"
#include "trace/flush_denormals.h"
#include "trace/ray_casters.h"

namespace dispex {
namespace {

using trace::EmbreeScene;

class EmbreeTracer final : public Tracer {
 public:
  EmbreeTracer(std::unique_ptr<EmbreeScene> scene, RayMode mode)
      : scene_(std::move(scene)), mode_(mode), stats_(scene_->stats()) {
    stats_.backend += fmt::format(", {}", RayModeName(mode));
  }

  void TraceNormals(std::span<const Float3> origins, std::span<const Float3> normals,
                    const NormalQuery& query, const NormalHits& out,
                    TraceCounters& counters) const override {
    DISPEX_CHECK_EQ(origins.size(), normals.size());
    DISPEX_CHECK_EQ(out.t.size(), origins.size());
    DISPEX_CHECK_EQ(out.flags.size(), origins.size());
    DISPEX_CHECK(out.prim.empty() || out.prim.size() == origins.size());
    DISPEX_CHECK(std::isfinite(query.distance) && query.distance > 0);
    trace::ScopedFlushDenormals flush;
    switch (mode_) {
      case RayMode::kSingle:
        return trace::TraceNormalsWith<trace::SingleCaster>(*scene_, origins, normals, query, out,
                                                            counters);
      case RayMode::kPacket4:
        return trace::TraceNormalsWith<trace::PacketCaster<4>>(*scene_, origins, normals, query,
                                                               out, counters);
      case RayMode::kPacket8:
        return trace::TraceNormalsWith<trace::PacketCaster<8>>(*scene_, origins, normals, query,
                                                               out, counters);
      case RayMode::kPacket16:
        return trace::TraceNormalsWith<trace::PacketCaster<16>>(*scene_, origins, normals, query,
                                                                out, counters);
      case RayMode::kStream:
        return trace::TraceNormalsWith<trace::StreamCaster>(*scene_, origins, normals, query, out,
                                                            counters);
    }
  }

  void Intersect(std::span<const Ray> rays, std::span<RayHit> hits,
                 TraceCounters& counters) const override {
    DISPEX_CHECK_EQ(hits.size(), rays.size());
    trace::ScopedFlushDenormals flush;
    switch (mode_) {
      case RayMode::kSingle:
        return trace::IntersectWith<trace::SingleCaster>(*scene_, rays, hits, counters);
      case RayMode::kPacket4:
        return trace::IntersectWith<trace::PacketCaster<4>>(*scene_, rays, hits, counters);
      case RayMode::kPacket8:
        return trace::IntersectWith<trace::PacketCaster<8>>(*scene_, rays, hits, counters);
      case RayMode::kPacket16:
        return trace::IntersectWith<trace::PacketCaster<16>>(*scene_, rays, hits, counters);
      case RayMode::kStream:
        return trace::IntersectWith<trace::StreamCaster>(*scene_, rays, hits, counters);
    }
  }

  void ClosestPoints(std::span<const Float3> points, float max_distance,
                     std::span<ClosestPoint> out, TraceCounters& counters) const override {
    DISPEX_CHECK_EQ(out.size(), points.size());
    DISPEX_CHECK(max_distance >= 0);  // NaN fails too
    trace::ScopedFlushDenormals flush;
    trace::ClosestPointsOnScene(*scene_, points, max_distance, out, counters);
  }

  const TracerStats& stats() const override { return stats_; }

  Status status() const override { return scene_->device().PeekError(); }

 private:
  std::unique_ptr<EmbreeScene> scene_;
  RayMode mode_;
  TracerStats stats_;
};

}  // namespace

StatusOr<std::unique_ptr<Tracer>> MakeEmbreeTracer(const Mesh& sculpt,
                                                   const TracerOptions& options) {
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<EmbreeScene> scene, EmbreeScene::Build(sculpt, options));
  return std::unique_ptr<Tracer>(new EmbreeTracer(std::move(scene), options.ray_mode));
}

}  // namespace dispex
