// The query loops of the Embree backend, written once over a Caster (ray_casters.h) so that
// every RayMode shares them.
//
// Rays are handled in blocks of 64 queries held on the stack. A normal query casts its first
// ray (+n; -n under inside-first) for the whole block, then a second pass casts the opposite
// ray only for the queries whose answer it can still change, and only up to where it can
// change it: under `nearest` the second ray's tfar is cut to the first hit's t, so Embree
// stops traversing early (the measured win over two independent rays). Queries are packed
// into casters in order, so rays from neighbouring samples of a face share a packet.
//
// Windows and t (the hit contract in include/dispex/trace.h): Embree only finds the
// primitive, over a window WindowMargin() wider than the query's; ExactT() gives t and the
// window is applied to it here, so no Embree ISA's rounding decides.
//
// Vertex guard. Embree 3's robust mode is watertight along shared edges but can still let a
// ray through exactly at a shared vertex (Embree issues #181 and #387; measured here on rays
// aimed exactly at cube-sphere vertices: ~0.3% slip through, none at edges). Such a query is
// re-resolved from an origin moved sideways (Sideways()): far enough, 16 ulps of the
// coordinates' magnitude, to leave the vertex's rounding zone so the rays cross a face or an
// edge; t is still measured from the query's own origin (ExactT), so it does not move.
// Which queries: those that end as misses (TracerOptions::retry_misses: cheap, misses are
// rare), and, with TracerOptions::verify_hits, those where one more sideways ray finds a
// surface between the origin and the kept hit, which the first rays must have slipped past.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <tuple>

#include "core/vec3.h"
#include "dispex/trace.h"
#include "trace/embree_scene.h"
#include "trace/ray_casters.h"

namespace dispex::trace {

inline constexpr int kBlock = 64;

inline bool Finite(const Float3& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}
inline bool NonZero(const Float3& p) {
  return p.x != 0 || p.y != 0 || p.z != 0;
}
inline float Dot(const Float3& a, const Float3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// One ray's hit as the kernels keep it between passes.
struct Candidate {
  float t = 0;
  unsigned geom = RTC_INVALID_GEOMETRY_ID;
  unsigned prim = 0;
  bool back = false;   // the triangle's back side met (ExactHit)
  Float3 ng;           // Embree's unnormalised geometric normal (Intersect reports it)
  float u = 0, v = 0;  // Embree's (u, v) on the primitive (the tie rule's)
  bool hit() const { return geom != RTC_INVALID_GEOMETRY_ID; }
};

// `o` moved sideways (perpendicular to d) by 16 ulps of the larger of the scene's and the
// origin's coordinate magnitude. Deterministic.
inline Float3 Sideways(const Float3& o, const Float3& d, float scene_scale) {
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  // e = d x (the axis of d's smallest component): perpendicular to d, never zero.
  const Float3 e = ax <= ay && ax <= az ? Float3{0, d.z, -d.y}
                   : ay <= az           ? Float3{-d.z, 0, d.x}
                                        : Float3{d.y, -d.x, 0};
  const float scale = std::max({scene_scale, std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)});
  const float step = scale * 0x1p-19f / std::sqrt(Dot(e, e));
  return Float3{o.x + step * e.x, o.y + step * e.y, o.z + step * e.z};
}

// Direction components smaller than 2^-24 of the largest set to exactly zero. Such noise
// (e.g. (-1.7e-20, 4.9e-4, 1) from the limit normals of a flat, creased side) moves a point
// on the ray by less than float rounding, but Embree 3.13.5's coherent packet traversal loses
// up to a third of those rays (none once the component is zero).
[[gnu::always_inline]] inline Float3 FlushTiny(const Float3& d) {
  const float floor = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) * 0x1p-24f;
  return Float3{std::fabs(d.x) < floor ? 0.0f : d.x, std::fabs(d.y) < floor ? 0.0f : d.y,
                std::fabs(d.z) < floor ? 0.0f : d.z};
}

// The window handed to Embree is wider than the query's by this margin at both ends, so that
// Embree's own rounding at the ends (which differs between its SSE, AVX, AVX2 and AVX-512
// kernels) never decides; dispex then decides with ExactT. 2^-18 of the coordinates' scale
// along the ray plus of the window's end: 32 float ulps.
inline float WindowMargin(const Float3& o, const Float3& d, float scene_scale, float end) {
  const float dmax = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  const float scale = std::max({scene_scale, std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)});
  return (scale / dmax + (std::isfinite(end) ? std::fabs(end) : 0.0f)) * 0x1p-18f;
}

// Embree's window [lo, hi] from `o`, made non-negative (Embree asserts tnear >= 0) by starting
// the ray -lo earlier; returns that shift, which Embree's t then includes.
template <class Caster>
[[gnu::always_inline]] inline float SetWindow(Caster& caster, int lane, Float3 o, const Float3& d,
                                              float lo, float hi) {
  const float shift = lo < 0 ? -lo : 0.0f;
  if (shift > 0) o = Float3{o.x - shift * d.x, o.y - shift * d.y, o.z - shift * d.z};
  caster.Set(lane, o, d, lo + shift, hi + shift);
  return shift;
}

// The corners of a primitive's triangle, in ExactT's order: a quad's two triangles are
// (v0 v1 v3) and, `second`, (v2 v3 v1), as Embree splits it; a triangle is itself.
struct TriangleCorners {
  std::int32_t ids[3];
};
inline TriangleCorners CornersOf(const GeometryView& g, unsigned prim, bool second) {
  const std::int32_t* c = g.indices + static_cast<std::size_t>(g.corners) * prim;
  if (g.corners == 3) return {{c[0], c[1], c[2]}};
  return second ? TriangleCorners{{c[2], c[3], c[1]}} : TriangleCorners{{c[0], c[1], c[3]}};
}

// The triangle of primitive `prim` that Embree's (u, v) fall in (for a quad, the second when
// u + v > 1: Embree reports (u, v) over the whole quad), and (u, v)'s barycentric weights of
// its corners.
struct HitTriangle {
  std::int32_t ids[3];
  float weights[3];
};
inline HitTriangle TriangleOf(const GeometryView& g, unsigned prim, float u, float v) {
  const bool second = g.corners == 4 && u + v > 1;
  const TriangleCorners c = CornersOf(g, prim, second);
  if (second) return HitTriangle{{c.ids[0], c.ids[1], c.ids[2]}, {u + v - 1, 1 - u, 1 - v}};
  return HitTriangle{{c.ids[0], c.ids[1], c.ids[2]}, {1 - u - v, u, v}};
}

// Where the line o + t d meets the plane of triangle ids[], in double (`exact`) and rounded
// once (NaN when degenerate or parallel), and whether d points along its right-hand normal
// (the back side).
struct PlaneHit {
  float t;
  bool back;
  double exact = 0;
};
inline PlaneHit PlaneOf(const Float3* p, const std::int32_t ids[3], const Float3& o,
                        const Float3& d) {
  const Float3& fa = p[ids[0]];
  const Vec3d a = ToVec3d(fa);
  const Vec3d n = Cross(ToVec3d(p[ids[1]]) - a, ToVec3d(p[ids[2]]) - a);
  const double den = n.x * d.x + n.y * d.y + n.z * d.z;
  const double t =
      (n.x * (double(fa.x) - o.x) + n.y * (double(fa.y) - o.y) + n.z * (double(fa.z) - o.z)) / den;
  const bool finite = std::isfinite(t);
  return PlaneHit{finite ? static_cast<float>(t) : std::numeric_limits<float>::quiet_NaN(), den > 0,
                  finite ? t : std::numeric_limits<double>::quiet_NaN()};
}

// The hit's t as dispex reports it: the line o + t d (the query's own origin, even when Embree
// was given one moved sideways) at the plane of the hit triangle (TriangleOf), and whether
// the back side was met. Identical under every ISA for the same triangle; Embree's own t
// (`fallback`) only for a degenerate one.
inline PlaneHit ExactHit(const EmbreeScene& scene, unsigned geom, unsigned prim, float u, float v,
                         const Float3& o, const Float3& d, float fallback) {
  const PlaneHit hit =
      PlaneOf(scene.positions(), TriangleOf(scene.geometry(geom), prim, u, v).ids, o, d);
  return std::isnan(hit.t) ? PlaneHit{fallback, hit.back, fallback} : hit;
}
inline float ExactT(const EmbreeScene& scene, unsigned geom, unsigned prim, float u, float v,
                    const Float3& o, const Float3& d, float fallback) {
  return ExactHit(scene, geom, prim, u, v, o, d, fallback).t;
}

// An intersect context whose filter rejects every candidate with ExactT outside [tnear, tfar]:
// Embree then goes on to the next surface. Used only to re-cast the rare ray whose nearest
// candidate lay in the margin before the window (see WindowMargin).
struct WindowContext {
  RTCIntersectContext context;  // first: Embree hands the filter this pointer
  const EmbreeScene* scene = nullptr;
  Float3 origin, direction;
  float tnear = 0, tfar = 0;

  explicit WindowContext(const EmbreeScene& s) : scene(&s) {
    rtcInitIntersectContext(&context);
    context.filter = &Filter;
  }
  static void Filter(const RTCFilterFunctionNArguments* args) {
    const auto* w = reinterpret_cast<const WindowContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      const float t = ExactT(*w->scene, RTCHitN_geomID(args->hit, args->N, i),
                             RTCHitN_primID(args->hit, args->N, i),
                             RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i),
                             w->origin, w->direction, RTCRayN_tfar(args->ray, args->N, i));
      if (!(t >= w->tnear && t <= w->tfar)) args->valid[i] = 0;
    }
  }
};

// Ties at shared edges and vertices. Where a ray meets the sculpt at an edge or a vertex,
// every face there is hit at (nearly) the same point, and which one Embree reports depends on
// the order its BVH visits them, and on whether the ray was in a packet or alone there (a
// packet goes on as single rays when few lanes remain, which depends on the BVH too). The
// face decides t's last bits (ExactT is measured on its plane) and which side was met, so a
// BVH of part of the sculpt (a farm shard's, an incremental run's) would answer otherwise
// than one of the whole sculpt. It is common: a sample at the centre of a sculpt quad lies on
// its diagonal, one on a sculpt grid line on an edge. The same holds at a fold, where the
// sculpt turns back onto itself: faces around one vertex overlap, and a ray through both
// meets them within rounding of each other, far from any edge.
//
// Hence ResolveTie answers again, in double precision and without Embree, every hit within
// kEdgeBand (of the barycentrics: wide against the kernels' rounding of (u, v)) of an edge or
// a vertex of its triangle, from the triangles around that edge or vertex (the scene's
// VertexPrims), and every hit on a folded primitive (VertexPrims::folded), from the triangles
// around its triangle's corners: of those the line passes through (InsideWeight >= 0) within
// the window margin of the hit's t, the nearest (then the lowest sculpt face, primitive and
// quad half); when it passes through none (rounding let Embree see a hit there), the one it
// passes closest to, if the hit was in the band. That set is the same whichever of them
// Embree reported, so the answer does not depend on the BVH.
inline constexpr float kEdgeBand = 0x1p-12f;

// How far inside triangle ids[] the line o + t d passes: the least barycentric weight of its
// meeting point with the plane (negative outside), in double; NaN when the line runs along it.
inline double InsideWeight(const Float3* p, const std::int32_t ids[3], const Float3& o,
                           const Float3& d) {
  const Vec3d a = ToVec3d(p[ids[0]]);
  const Vec3d e1 = ToVec3d(p[ids[1]]) - a, e2 = ToVec3d(p[ids[2]]) - a;
  const Vec3d dir = ToVec3d(d);
  const Vec3d pv = Cross(dir, e2);
  const double det = Dot(e1, pv);
  const Vec3d tv = ToVec3d(o) - a;
  const double u = Dot(tv, pv) / det;
  const double v = Dot(dir, Cross(tv, e1)) / det;
  return std::min({1 - u - v, u, v});
}

// The tie rule (see kEdgeBand) for `kept`, a hit along d from o: true when it applies
// (`kept` is then the answer, t measured on the chosen triangle's plane).
inline bool ResolveTie(const EmbreeScene& scene, const Float3& o, const Float3& d,
                       Candidate& kept) {
  const GeometryView& kept_geometry = scene.geometry(kept.geom);
  const HitTriangle hit = TriangleOf(kept_geometry, kept.prim, kept.u, kept.v);
  const bool folded = scene.vertex_prims().folded[scene.GlobalOf(kept.geom, kept.prim)] != 0;
  // Near an edge: its two corners; near a vertex: it. Every triangle there holds them.
  std::int32_t feature[3];
  int count = 0;
  for (int k = 0; k < 3; ++k) {
    if (hit.weights[k] >= kEdgeBand) feature[count++] = hit.ids[k];
  }
  const bool in_band = count < 3;
  if (!in_band && !folded) return false;
  const Float3* positions = scene.positions();
  const float margin = WindowMargin(o, d, scene.scale(), kept.t);
  // The ranking: passed through (within the margin of kept.t) before passed beside; then the
  // nearer, or the less beside; then the lowest face, primitive and half.
  struct Rank {
    bool beside;
    double order;  // t through, -InsideWeight beside
    std::int32_t face;
    unsigned prim;
    int second;
    auto key() const { return std::tie(beside, order, face, prim, second); }
  };
  std::optional<Rank> best;
  unsigned best_geom = 0;
  PlaneHit best_plane{};
  const auto consider = [&](unsigned geom, unsigned prim, int second) {
    const TriangleCorners tri = CornersOf(scene.geometry(geom), prim, second != 0);
    if (in_band) {
      for (int k = 0; k < count; ++k) {
        if (tri.ids[0] != feature[k] && tri.ids[1] != feature[k] && tri.ids[2] != feature[k]) {
          return;
        }
      }
    }
    const double weight = InsideWeight(positions, tri.ids, o, d);
    if (std::isnan(weight)) return;
    const PlaneHit plane = PlaneOf(positions, tri.ids, o, d);
    const bool through = weight >= 0 && std::fabs(plane.exact - kept.t) <= margin;
    if (!through && !in_band) return;
    const Rank rank{!through, through ? plane.exact : -weight, scene.FaceOf(geom, prim), prim,
                    second};
    if (best && best->key() <= rank.key()) return;
    best = rank;
    best_geom = geom;
    best_plane = plane;
  };
  const auto consider_around = [&](std::int32_t vertex) {
    for (std::uint32_t global : scene.vertex_prims().around(vertex)) {
      const unsigned geom = scene.GeomOf(global), prim = scene.PrimOf(global);
      for (int second = 0; second < (scene.geometry(geom).corners == 4 ? 2 : 1); ++second) {
        consider(geom, prim, second);
      }
    }
  };
  const bool diagonal = kept_geometry.corners == 4 && count == 2 &&
                        ((feature[0] == hit.ids[1] && feature[1] == hit.ids[2]) ||
                         (feature[0] == hit.ids[2] && feature[1] == hit.ids[1]));
  if (diagonal && !folded) {
    // A quad's own diagonal: its two triangles are all there is.
    consider(kept.geom, kept.prim, 0);
    consider(kept.geom, kept.prim, 1);
  } else if (in_band) {
    consider_around(feature[0]);
  } else {
    for (std::int32_t corner : hit.ids) consider_around(corner);
  }
  if (!best || std::isnan(best_plane.t)) return true;
  kept.t = best_plane.t;
  kept.back = best_plane.back;
  kept.geom = best_geom;
  kept.prim = best->prim;
  return true;
}

// One ray from `cast_origin` whose hit must have ExactT (measured from `origin`) in
// [tnear, tfar]: nothing nearer is returned, whatever Embree's rounding.
inline Candidate CastInWindow(const EmbreeScene& scene, const Float3& cast_origin,
                              const Float3& origin, const Float3& d, float tnear, float tfar) {
  WindowContext w(scene);
  w.origin = origin;
  w.direction = d;
  w.tnear = tnear;
  w.tfar = tfar;
  const float m = WindowMargin(cast_origin, d, scene.scale(), tfar);
  SingleCaster caster;
  const float shift = SetWindow(caster, 0, cast_origin, d, tnear - m, tfar + m);
  caster.Cast(scene.scene(), &w.context, 1);
  if (!caster.Hit(0)) return Candidate{};
  const PlaneHit hit = ExactHit(scene, caster.Geom(0), caster.Prim(0), caster.U(0), caster.V(0),
                                origin, d, caster.T(0) - shift);
  return Candidate{hit.t,        caster.Geom(0), caster.Prim(0), hit.back,
                   caster.Ng(0), caster.U(0),    caster.V(0)};
}

// The normal-query kernel for one block of at most kBlock queries.
template <class Caster>
class NormalBlock {
 public:
  NormalBlock(const EmbreeScene& scene, const NormalQuery& query)
      : scene_(scene),
        query_(query),
        nearest_(query.policy == HitPolicy::kNearest),
        first_sign_(query.policy == HitPolicy::kInsideFirst ? -1.0f : 1.0f) {
    rtcInitIntersectContext(&context_);
    context_.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  }

  // Resolves the queries o[j] +- t d[j], j < m, and writes their outputs at out[base + j].
  void Run(const Float3* o, const Float3* d, int m, const NormalHits& out, std::size_t base,
           TraceCounters& counters) {
    o_ = o;
    int count = 0;
    for (int j = 0; j < m; ++j) {
      kept_[j] = Candidate{};
      if (Finite(o[j]) && Finite(d[j]) && NonZero(d[j])) {
        d_[j] = FlushTiny(d[j]);
        margin_[j] = WindowMargin(o[j], d_[j], scene_.scale(), query_.distance);
        list_[count++] = j;
      } else {
        ++counters.invalid;
      }
    }
    rays_ = 0;
    repair_rays_ = 0;
    ties_ = 0;
    Resolve(list_, count, false);
    if (scene_.retry_misses()) {
      int misses = 0;
      for (int k = 0; k < count; ++k) {
        if (!kept_[list_[k]].hit()) suspects_[misses++] = list_[k];
      }
      Resolve(suspects_, misses, true);
    }
    if (scene_.verify_hits() || query_.verify_hits) Verify(count);
    ResolveTies(count);
    counters.rays_cast += rays_ + repair_rays_;
    counters.repair_rays += repair_rays_;
    counters.tie_hits += ties_;
    Write(m, out, base, counters);
  }

 private:
  // Casts, for each j in ids[0..count), the ray along sign * d[j] with t in [0, tfar_[j]] from
  // o[j] (moved sideways when `sideways`), storing its hit in result[j].
  void Cast(const int* ids, int count, float sign, Candidate* result, bool sideways) {
    constexpr int W = Caster::kWidth;
    int recasts = 0;
    for (int k0 = 0; k0 < count; k0 += W) {
      const int width = std::min(W, count - k0);
      for (int lane = 0; lane < width; ++lane) {
        const int j = ids[k0 + lane];
        const Float3 dir{sign * d_[j].x, sign * d_[j].y, sign * d_[j].z};
        // Both rays of a query move the same way: sideways of d, not of dir.
        const Float3 o = sideways ? Sideways(o_[j], d_[j], scene_.scale()) : o_[j];
        // The window [-m, tfar + m], started m early (Embree asserts tnear >= 0).
        const float m = margin_[j];
        caster_.Set(lane, Float3{o.x - m * dir.x, o.y - m * dir.y, o.z - m * dir.z}, dir, 0.0f,
                    tfar_[j] + 2 * m);
      }
      caster_.Cast(scene_.scene(), &context_, width);
      for (int lane = 0; lane < width; ++lane) {
        if (!caster_.Hit(lane)) continue;
        const int j = ids[k0 + lane];
        const Float3 dir{sign * d_[j].x, sign * d_[j].y, sign * d_[j].z};
        const PlaneHit hit =
            ExactHit(scene_, caster_.Geom(lane), caster_.Prim(lane), caster_.U(lane),
                     caster_.V(lane), o_[j], dir, caster_.T(lane) - margin_[j]);
        if (hit.t < 0) {
          recast_[recasts++] = j;  // a surface in the margin before 0 hid the window's start
        } else if (hit.t <= tfar_[j]) {
          result[j] = Candidate{hit.t,          caster_.Geom(lane), caster_.Prim(lane),
                                hit.back,       caster_.Ng(lane),   caster_.U(lane),
                                caster_.V(lane)};
        }
      }
    }
    for (int k = 0; k < recasts; ++k) {
      const int j = recast_[k];
      const Float3 dir{sign * d_[j].x, sign * d_[j].y, sign * d_[j].z};
      result[j] = CastInWindow(scene_, sideways ? Sideways(o_[j], d_[j], scene_.scale()) : o_[j],
                               o_[j], dir, 0.0f, tfar_[j]);
    }
    (sideways ? repair_rays_ : rays_) += static_cast<std::uint64_t>(count + recasts);
  }

  // Both rays of the listed queries and the policy's choice, into kept_ and kept_sign_.
  void Resolve(const int* ids, int count, bool sideways) {
    if (count == 0) return;
    for (int k = 0; k < count; ++k) {
      const int j = ids[k];
      first_[j] = second_[j] = Candidate{};
      tfar_[j] = query_.distance;
    }
    Cast(ids, count, first_sign_, first_, sideways);

    // The second ray, where it can change the answer (see TraceCounters::rays_cast).
    int count2 = 0;
    for (int k = 0; k < count; ++k) {
      const int j = ids[k];
      if (!first_[j].hit()) {
        second_ids_[count2++] = j;
      } else if (nearest_ && first_[j].t > 0) {
        tfar_[j] = first_[j].t;
        second_ids_[count2++] = j;
      }
    }
    Cast(second_ids_, count2, -first_sign_, second_, sideways);

    for (int k = 0; k < count; ++k) {
      const int j = ids[k];
      const Candidate& a = first_[j];
      const Candidate& b = second_[j];
      // Under nearest, b was cast with tfar <= a.t: a tie keeps a (the +n hit).
      const bool take_second = b.hit() && (!a.hit() || (nearest_ && b.t < a.t));
      kept_[j] = take_second ? b : a;
      kept_sign_[j] = take_second ? -first_sign_ : first_sign_;
      // Where a surface would have changed the answer, for Verify: under nearest, anything
      // within |t| on either side; otherwise anything before the hit on its side, plus the
      // whole preferred side when the answer came from the other one.
      const float other = nearest_ ? kept_[j].t : (take_second ? query_.distance : 0.0f);
      reach_plus_[j] = kept_sign_[j] > 0 ? kept_[j].t : other;
      reach_minus_[j] = kept_sign_[j] > 0 ? other : kept_[j].t;
    }
  }

  // The tie rule (ResolveTie) for every kept hit.
  void ResolveTies(int count) {
    for (int k = 0; k < count; ++k) {
      const int j = list_[k];
      if (!kept_[j].hit()) continue;
      const float sign = kept_sign_[j];
      ties_ += ResolveTie(scene_, o_[j], Float3{sign * d_[j].x, sign * d_[j].y, sign * d_[j].z},
                          kept_[j]);
    }
  }

  // One sideways ray per hit over the open segment the rays covered, from -reach_minus to
  // +reach_plus along d (ends trimmed by a margin so the kept hit itself is not found): a
  // surface found there was slipped past, so the query is resolved again from sideways.
  void Verify(int count) {
    int segments = 0;
    for (int k = 0; k < count; ++k) {
      const int j = list_[k];
      if (!kept_[j].hit() || kept_[j].t == 0) continue;
      const float length = reach_minus_[j] + reach_plus_[j];
      // The trim covers how far the sideways step can move the kept hit along the ray (up
      // to 64 steps: surfaces within ~1 degree of the ray's direction excepted).
      const float step =
          std::max({scene_.scale(), std::fabs(o_[j].x), std::fabs(o_[j].y), std::fabs(o_[j].z)}) *
          0x1p-19f;
      const float margin = std::max(1e-4f * length, 64 * step);
      segment_start_[j] = reach_minus_[j] - margin;
      tfar_[j] = length - 2 * margin;
      if (tfar_[j] > 0) suspects_[segments++] = j;
    }
    constexpr int W = Caster::kWidth;
    int found = 0;
    for (int k0 = 0; k0 < segments; k0 += W) {
      const int width = std::min(W, segments - k0);
      for (int lane = 0; lane < width; ++lane) {
        const int j = suspects_[k0 + lane];
        const Float3 s = Sideways(o_[j], d_[j], scene_.scale());
        const float back = segment_start_[j];
        caster_.Set(lane, Float3{s.x - back * d_[j].x, s.y - back * d_[j].y, s.z - back * d_[j].z},
                    d_[j], 0.0f, tfar_[j]);
      }
      caster_.Cast(scene_.scene(), &context_, width);
      for (int lane = 0; lane < width; ++lane) {
        if (caster_.Hit(lane)) list2_[found++] = suspects_[k0 + lane];
      }
    }
    repair_rays_ += static_cast<std::uint64_t>(segments);
    // Resolve them again from sideways; keep the first answer where that finds nothing
    // (the nearer surface lay within the trim).
    for (int k = 0; k < found; ++k) {
      saved_[k] = kept_[list2_[k]];
      saved_sign_[k] = kept_sign_[list2_[k]];
    }
    Resolve(list2_, found, true);
    for (int k = 0; k < found; ++k) {
      if (kept_[list2_[k]].hit()) continue;
      kept_[list2_[k]] = saved_[k];
      kept_sign_[list2_[k]] = saved_sign_[k];
    }
  }

  void Write(int m, const NormalHits& out, std::size_t base, TraceCounters& counters) const {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const bool with_prims = !out.prim.empty();
    for (int j = 0; j < m; ++j) {
      const std::size_t i = base + static_cast<std::size_t>(j);
      const Candidate& pick = kept_[j];
      if (!pick.hit()) {
        out.t[i] = nan;
        out.flags[i] = 0;
        if (with_prims) out.prim[i] = SculptPrimId();
        continue;
      }
      const float sign = kept_sign_[j];
      out.t[i] = sign * pick.t;
      out.flags[i] =
          static_cast<std::uint8_t>(HitFlags::kHit | (sign < 0 ? HitFlags::kNegative : 0) |
                                    (pick.back ? HitFlags::kBackFace : 0));
      if (with_prims) out.prim[i] = SculptPrimId(scene_.FaceOf(pick.geom, pick.prim));
      ++counters.hits;
    }
  }

  const EmbreeScene& scene_;
  const NormalQuery& query_;
  const bool nearest_;
  const float first_sign_;
  RTCIntersectContext context_;
  Caster caster_;
  const Float3* o_ = nullptr;
  Float3 d_[kBlock];      // the queries' normals, FlushTiny'd
  float margin_[kBlock];  // WindowMargin of each query at its longest window
  std::uint64_t rays_ = 0, repair_rays_ = 0, ties_ = 0;
  int list_[kBlock], list2_[kBlock], second_ids_[kBlock], suspects_[kBlock], recast_[kBlock];
  float tfar_[kBlock];
  float reach_plus_[kBlock], reach_minus_[kBlock], segment_start_[kBlock];
  float kept_sign_[kBlock], saved_sign_[kBlock];
  Candidate first_[kBlock], second_[kBlock], kept_[kBlock], saved_[kBlock];
};

template <class Caster>
void TraceNormalsWith(const EmbreeScene& scene, std::span<const Float3> origins,
                      std::span<const Float3> normals, const NormalQuery& query,
                      const NormalHits& out, TraceCounters& counters) {
  static_assert(kBlock % Caster::kWidth == 0);
  NormalBlock<Caster> block(scene, query);
  const std::size_t n = origins.size();
  for (std::size_t base = 0; base < n; base += kBlock) {
    const int m = static_cast<int>(std::min<std::size_t>(kBlock, n - base));
    block.Run(origins.data() + base, normals.data() + base, m, out, base, counters);
  }
  counters.queries += n;
}

template <class Caster>
void IntersectWith(const EmbreeScene& scene, std::span<const Ray> rays, std::span<RayHit> hits,
                   TraceCounters& counters) {
  static_assert(kBlock % Caster::kWidth == 0);
  constexpr int W = Caster::kWidth;
  Caster caster;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float scale = scene.scale();

  int list[kBlock], repair[kBlock], recast[kBlock];
  float tfar[kBlock];
  Float3 dir[kBlock];  // the rays' directions, FlushTiny'd
  float shift[W];
  std::uint64_t cast = 0, repairs = 0, found = 0, invalid = 0;
  const std::size_t n = rays.size();
  for (std::size_t base = 0; base < n; base += kBlock) {
    const int m = static_cast<int>(std::min<std::size_t>(kBlock, n - base));
    const Ray* block = rays.data() + base;
    RayHit* out = hits.data() + base;

    // Casts rays ids[0..count) over [tnear, tfar[j]] from their origin (moved sideways when
    // `sideways`) and stores the hits; `count` and `recasts` rays in all.
    auto store = [&](int j, const Candidate& c) {
      const float length = std::sqrt(Dot(c.ng, c.ng));
      const float inv = length > 0 ? 1.0f / length : 0.0f;
      out[j].t = c.t;
      out[j].prim = SculptPrimId(scene.FaceOf(c.geom, c.prim));
      out[j].normal = Float3{c.ng.x * inv, c.ng.y * inv, c.ng.z * inv};
    };
    auto cast_rays = [&](const int* ids, int count, bool sideways) {
      int recasts = 0;
      for (int k0 = 0; k0 < count; k0 += W) {
        const int width = std::min(W, count - k0);
        for (int lane = 0; lane < width; ++lane) {
          const int j = ids[k0 + lane];
          const Ray& ray = block[j];
          Float3 o = ray.origin;
          if (sideways) o = Sideways(o, dir[j], scale);
          const float margin = WindowMargin(o, dir[j], scale, tfar[j]);
          shift[lane] = SetWindow(caster, lane, o, dir[j], ray.tnear - margin, tfar[j] + margin);
        }
        caster.Cast(scene.scene(), &context, width);
        for (int lane = 0; lane < width; ++lane) {
          if (!caster.Hit(lane)) continue;
          const int j = ids[k0 + lane];
          const float t =
              ExactT(scene, caster.Geom(lane), caster.Prim(lane), caster.U(lane), caster.V(lane),
                     block[j].origin, dir[j], caster.T(lane) - shift[lane]);
          if (t < block[j].tnear) {
            recast[recasts++] = j;  // a surface in the margin before tnear hid the window
          } else if (t <= tfar[j]) {
            store(j, Candidate{t, caster.Geom(lane), caster.Prim(lane), false, caster.Ng(lane)});
          }
        }
      }
      for (int k = 0; k < recasts; ++k) {
        const int j = recast[k];
        const Ray& ray = block[j];
        const Candidate c =
            CastInWindow(scene, sideways ? Sideways(ray.origin, dir[j], scale) : ray.origin,
                         ray.origin, dir[j], ray.tnear, tfar[j]);
        if (c.hit()) store(j, c);
      }
      (sideways ? repairs : cast) += static_cast<std::uint64_t>(count + recasts);
    };

    int count = 0;
    for (int j = 0; j < m; ++j) {
      const Ray& ray = block[j];
      out[j] = RayHit{nan, SculptPrimId(), Float3{}};
      tfar[j] = ray.tfar;
      const bool valid = Finite(ray.origin) && Finite(ray.direction) && NonZero(ray.direction) &&
                         std::isfinite(ray.tnear) && ray.tnear >= 0 && ray.tnear <= ray.tfar;
      if (valid) {
        dir[j] = FlushTiny(ray.direction);
        list[count++] = j;
      } else {
        ++invalid;
      }
    }
    cast_rays(list, count, false);

    // The vertex guard (see the file comment): misses, and hits with a surface before them
    // that a sideways ray over [tnear, t) finds, are cast again from sideways.
    int suspects = 0;
    if (scene.retry_misses()) {
      for (int k = 0; k < count; ++k) {
        if (!out[list[k]].hit()) repair[suspects++] = list[k];
      }
    }
    if (scene.verify_hits()) {
      int segments = 0;
      int segment_ids[kBlock];
      for (int k = 0; k < count; ++k) {
        const int j = list[k];
        const float t = out[j].t;
        if (!out[j].hit() || !(t > block[j].tnear)) continue;
        const Float3& o = block[j].origin;
        const float step = std::max({scale, std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)}) *
                           0x1p-19f / std::sqrt(Dot(dir[j], dir[j]));
        tfar[j] = t - std::max(1e-4f * (t - block[j].tnear), 64 * step);
        if (tfar[j] > block[j].tnear) segment_ids[segments++] = j;
      }
      // Segments start at tnear: move the origin there, sideways, and cast over [0, length).
      for (int k = 0; k < segments; ++k) {
        const int j = segment_ids[k];
        tfar[j] -= block[j].tnear;
      }
      for (int k0 = 0; k0 < segments; k0 += W) {
        const int width = std::min(W, segments - k0);
        for (int lane = 0; lane < width; ++lane) {
          const int j = segment_ids[k0 + lane];
          const Ray& ray = block[j];
          const Float3 s = Sideways(ray.origin, dir[j], scale);
          const float a = ray.tnear;
          caster.Set(lane, Float3{s.x + a * dir[j].x, s.y + a * dir[j].y, s.z + a * dir[j].z},
                     dir[j], 0.0f, tfar[j]);
        }
        caster.Cast(scene.scene(), &context, width);
        for (int lane = 0; lane < width; ++lane) {
          if (caster.Hit(lane)) repair[suspects++] = segment_ids[k0 + lane];
        }
      }
      repairs += static_cast<std::uint64_t>(segments);
    }
    for (int k = 0; k < suspects; ++k) tfar[repair[k]] = block[repair[k]].tfar;
    cast_rays(repair, suspects, true);

    for (int k = 0; k < count; ++k) found += out[list[k]].hit() ? 1 : 0;
  }
  counters.queries += n;
  counters.invalid += invalid;
  counters.rays_cast += cast + repairs;
  counters.repair_rays += repairs;
  counters.hits += found;
}

}  // namespace dispex::trace
