// Closest points with rtcPointQuery: Embree walks the BVH nodes that overlap a sphere around
// the query point and calls back per primitive; the callback computes the exact distance to
// the primitive (closest_point.cpp; a quad as the triangles v0,v1,v3 and v2,v3,v1, the split
// Embree's ray queries use) and shrinks the sphere to it, which prunes the rest of the walk.
// This is the approach of Embree's closest_point tutorial.
#include "trace/embree_point_query.h"

#include <cmath>
#include <limits>

#include "trace/closest_point.h"

namespace dispex::trace {
namespace {

struct QueryState {
  const EmbreeScene* scene = nullptr;
  Vec3d p;
  double best_distance2 = std::numeric_limits<double>::infinity();
  Vec3d best_point;
  unsigned geom = RTC_INVALID_GEOMETRY_ID;
  unsigned prim = 0;
};

Vec3d ToVec3d(const Float3& p) {
  return {p.x, p.y, p.z};
}

bool OnPrimitive(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<QueryState*>(args->userPtr);
  const GeometryView& geometry = state->scene->geometry(args->geomID);
  const Float3* positions = state->scene->positions();
  const std::int32_t* corner = geometry.indices + static_cast<std::size_t>(args->primID) *
                                                      static_cast<std::size_t>(geometry.corners);
  const Vec3d v0 = ToVec3d(positions[corner[0]]);
  const Vec3d v1 = ToVec3d(positions[corner[1]]);
  const Vec3d v2 = ToVec3d(positions[corner[2]]);
  Vec3d q;
  if (geometry.corners == 4) {
    const Vec3d v3 = ToVec3d(positions[corner[3]]);
    q = ClosestPointOnTriangle(state->p, v0, v1, v3);
    const Vec3d q2 = ClosestPointOnTriangle(state->p, v2, v3, v1);
    if (Distance2(state->p, q2) < Distance2(state->p, q)) q = q2;
  } else {
    q = ClosestPointOnTriangle(state->p, v0, v1, v2);
  }
  const double d2 = Distance2(state->p, q);
  // Ties keep the lower (geometry, primitive), so the answer does not depend on traversal order.
  const bool better =
      d2 < state->best_distance2 ||
      (d2 == state->best_distance2 &&
       (args->geomID < state->geom || (args->geomID == state->geom && args->primID < state->prim)));
  if (!better) return false;
  state->best_distance2 = d2;
  state->best_point = q;
  state->geom = args->geomID;
  state->prim = args->primID;
  // Shrink the search sphere, rounding up so no primitive at the same distance is culled.
  args->query->radius =
      std::nextafter(static_cast<float>(std::sqrt(d2)), std::numeric_limits<float>::infinity());
  return true;
}

}  // namespace

void ClosestPointsOnScene(const EmbreeScene& scene, std::span<const Float3> points,
                          float max_distance, std::span<ClosestPoint> out,
                          TraceCounters& counters) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  RTCPointQueryContext context;
  std::uint64_t found = 0, invalid = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Float3& p = points[i];
    out[i] = ClosestPoint{inf, Float3{nan, nan, nan}, SculptPrimId()};
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++invalid;
      continue;
    }
    QueryState state;
    state.scene = &scene;
    state.p = ToVec3d(p);
    // The sphere's radius starts at max_distance; results beyond it are dropped below, as
    // Embree may call back for primitives whose bounds, not surface, are within it.
    RTCPointQuery query;
    query.x = p.x;
    query.y = p.y;
    query.z = p.z;
    query.time = 0;
    query.radius = max_distance;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene.scene(), &query, &context, &OnPrimitive, &state);
    if (state.geom == RTC_INVALID_GEOMETRY_ID) continue;
    const double distance = std::sqrt(state.best_distance2);
    if (distance > static_cast<double>(max_distance)) continue;
    out[i] = ClosestPoint{
        static_cast<float>(distance),
        Float3{static_cast<float>(state.best_point.x), static_cast<float>(state.best_point.y),
               static_cast<float>(state.best_point.z)},
        SculptPrimId(scene.FaceOf(state.geom, state.prim))};
    ++found;
  }
  counters.queries += points.size();
  counters.invalid += invalid;
  counters.hits += found;
}

}  // namespace dispex::trace
