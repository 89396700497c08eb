// Casters: one fixed-size group of rays handed to Embree in one call, behind one small
// interface so the query loops (batch_kernels.h) are written once for every RayMode:
//
//   Set(lane, origin, direction, tnear, tfar)   fill lane `lane` (0 <= lane < kWidth)
//   Cast(scene, context, count)                 intersect lanes [0, count)
//   Hit(lane), T(lane), Geom(lane), Prim(lane), U(lane), V(lane), Ng(lane)   a lane's result
//
// The packet casters keep the rays in Embree's SoA layout (RTCRayHit4/8/16) and pass a
// valid mask; the stream caster keeps AoS RTCRayHit records for rtcIntersect1M; the single
// caster wraps rtcIntersect1. All are plain stack objects: no allocation, no virtual call.
#pragma once

#include <embree3/rtcore.h>

#include "dispex/mesh.h"

namespace dispex::trace {

template <int W>
struct PacketTraits;
template <>
struct PacketTraits<4> {
  using RayHit = RTCRayHit4;
  static void Intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect4(valid, s, c, r);
  }
};
template <>
struct PacketTraits<8> {
  using RayHit = RTCRayHit8;
  static void Intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect8(valid, s, c, r);
  }
};
template <>
struct PacketTraits<16> {
  using RayHit = RTCRayHit16;
  static void Intersect(const int* valid, RTCScene s, RTCIntersectContext* c, RayHit* r) {
    rtcIntersect16(valid, s, c, r);
  }
};

template <int W>
class PacketCaster {
 public:
  static constexpr int kWidth = W;

  PacketCaster() {
    for (int i = 0; i < W; ++i) {
      Set(i, Float3{}, Float3{0, 0, 1}, 0, 0);
      valid_[i] = 0;
    }
  }

  void Set(int i, const Float3& o, const Float3& d, float tnear, float tfar) {
    auto& ray = rh_.ray;
    ray.org_x[i] = o.x, ray.org_y[i] = o.y, ray.org_z[i] = o.z;
    ray.dir_x[i] = d.x, ray.dir_y[i] = d.y, ray.dir_z[i] = d.z;
    ray.tnear[i] = tnear;
    ray.tfar[i] = tfar;
    ray.time[i] = 0;
    ray.mask[i] = ~0u;
    ray.id[i] = 0;
    ray.flags[i] = 0;
    rh_.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh_.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }

  void Cast(RTCScene scene, RTCIntersectContext* context, int count) {
    for (int i = 0; i < W; ++i) valid_[i] = i < count ? -1 : 0;
    PacketTraits<W>::Intersect(valid_, scene, context, &rh_);
  }

  bool Hit(int i) const { return rh_.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID; }
  float T(int i) const { return rh_.ray.tfar[i]; }
  unsigned Geom(int i) const { return rh_.hit.geomID[i]; }
  unsigned Prim(int i) const { return rh_.hit.primID[i]; }
  float U(int i) const { return rh_.hit.u[i]; }
  float V(int i) const { return rh_.hit.v[i]; }
  Float3 Ng(int i) const { return {rh_.hit.Ng_x[i], rh_.hit.Ng_y[i], rh_.hit.Ng_z[i]}; }

 private:
  typename PacketTraits<W>::RayHit rh_;  // RTC_ALIGN'ed by Embree
  alignas(64) int valid_[W];
};

// AoS records for the scalar and stream calls.
template <int W>
class RecordCaster {
 public:
  static constexpr int kWidth = W;

  void Set(int i, const Float3& o, const Float3& d, float tnear, float tfar) {
    RTCRay& ray = rh_[i].ray;
    ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
    ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
    ray.tnear = tnear;
    ray.tfar = tfar;
    ray.time = 0;
    ray.mask = ~0u;
    ray.id = 0;
    ray.flags = 0;
    rh_[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh_[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }

  void Cast(RTCScene scene, RTCIntersectContext* context, int count) {
    if constexpr (W == 1) {
      if (count == 1) rtcIntersect1(scene, context, &rh_[0]);
    } else {
      if (count > 0) {
        rtcIntersect1M(scene, context, rh_, static_cast<unsigned>(count), sizeof(RTCRayHit));
      }
    }
  }

  bool Hit(int i) const { return rh_[i].hit.geomID != RTC_INVALID_GEOMETRY_ID; }
  float T(int i) const { return rh_[i].ray.tfar; }
  unsigned Geom(int i) const { return rh_[i].hit.geomID; }
  unsigned Prim(int i) const { return rh_[i].hit.primID; }
  float U(int i) const { return rh_[i].hit.u; }
  float V(int i) const { return rh_[i].hit.v; }
  Float3 Ng(int i) const { return {rh_[i].hit.Ng_x, rh_[i].hit.Ng_y, rh_[i].hit.Ng_z}; }

 private:
  RTCRayHit rh_[W];
};

using SingleCaster = RecordCaster<1>;
using StreamCaster = RecordCaster<64>;

}  // namespace dispex::trace
