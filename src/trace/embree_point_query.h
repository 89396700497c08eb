// Closest-point queries on the sculpt scene with Embree's BVH (rtcPointQuery).
#pragma once

#include <span>

#include "dispex/trace.h"
#include "trace/embree_scene.h"

namespace dispex::trace {

// See Tracer::ClosestPoints.
void ClosestPointsOnScene(const EmbreeScene& scene, std::span<const Float3> points,
                          float max_distance, std::span<ClosestPoint> out, TraceCounters& counters);

}  // namespace dispex::trace
