// Ray casting into the sculpt: for each limit point P with unit normal n, where the line
// P + t n meets the sculpt within t in [-d, +d], plus the two other queries later tools need
// (closest points on the sculpt, and arbitrary rays).
//
// The work is done by a Tracer, an abstract backend with one virtual call per BATCH of rays
// (never per ray): MakeEmbreeTracer() builds the CPU backend on Embree 3; a GPU backend can
// implement the same interface. All query functions are const and thread-safe: any number of
// threads (TBB tasks) may query one Tracer at once, each with its own output arrays. A query's
// answer depends only on its own inputs, never on batch boundaries or thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/ids.h"
#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

// ---- Options -------------------------------------------------------------------------------

// Which hit a normal query keeps when both the ray along +n and the ray along -n hit.
enum class HitPolicy : std::uint8_t {
  kNearest,       // the hit with the smallest |t|; on a tie, the +n hit ("nearest", default)
  kOutsideFirst,  // the +n hit whenever there is one ("outside-first")
  kInsideFirst,   // the -n hit whenever there is one ("inside-first")
};

// BVH build quality (Embree's low = Morton builder, medium = binned SAH, high = SAH with
// spatial splits). Measured on 16.8M quads (docs/bench-notes/trace.md): low builds in about
// a third of medium's CPU time and its rays are as fast for these short coherent rays, so it
// is the default; medium with `compact` takes about a third of low's BVH memory for ~8%
// slower rays.
enum class BuildQuality : std::uint8_t { kLow, kMedium, kHigh };

// How a batch is handed to the backend. 8- and 16-wide packets measured fastest (within
// noise of each other, 1.4-1.7x single rays); kPacket8 is the default as it is native on both
// AVX2 and AVX-512. The others exist for measurement (bench/trace).
enum class RayMode : std::uint8_t {
  kSingle,   // one rtcIntersect1 per ray
  kPacket4,  // SoA packets of 4/8/16 rays with valid masks (rtcIntersect4/8/16)
  kPacket8,
  kPacket16,
  kStream,  // rtcIntersect1M over up to 64 rays at a time
};

struct TracerOptions {
  BuildQuality quality = BuildQuality::kLow;
  RayMode ray_mode = RayMode::kPacket8;
  // Watertight intersection (RTC_SCENE_FLAG_ROBUST): rays through shared edges never slip
  // through (at shared vertices, see the vertex guard below). Turning it off is only meant
  // for measurement: then ~10% of rays aimed exactly at edges or vertices slip through.
  bool robust = true;
  // The vertex guard. Embree 3's robust mode still lets a small fraction of the rays that pass
  // exactly through a shared vertex slip through (none at edges). A query that ends as a
  // miss is resolved again from an origin moved sideways by ~2e-6 of the scene's coordinate
  // magnitude, which closes those holes; it costs rays only for misses, and does not move t
  // (t is measured from the query's own origin, see the contract above Tracer).
  bool retry_misses = true;
  // Also catch a ray that slipped through a vertex and went on to hit something farther: one
  // more sideways ray per hit checks the stretch before the hit, and a query that finds a
  // surface there is resolved again from sideways. Exact at vertices, at the cost of one more
  // ray per hit (measured: 24-28% fewer queries per second; docs/bench-notes/trace.md).
  bool verify_hits = false;
  // Build the table the tie rule of normal queries reads (the hit contract below) with the BVH,
  // in parallel. False for a scene that answers only Intersect and ClosestPoints queries; its
  // first normal query, if one comes, builds the table then, on that query's thread.
  bool normal_queries = true;
  // RTC_SCENE_FLAG_COMPACT: a smaller BVH (with medium quality about half the memory), rays
  // ~8% slower.
  bool compact = false;
  // When > 0, an Embree allocation that would take its total above this many bytes fails
  // and MakeEmbreeTracer returns an out-of-memory Status.
  std::int64_t memory_limit_bytes = 0;
  // Embree's kernel set: "sse2", "sse4.2", "avx", "avx2" or "avx512". Empty: the environment
  // variable DISPEX_EMBREE_ISA when set (so a whole test run can be forced to one), else
  // Embree's own choice for this CPU (the widest it supports). An unknown name, or an ISA
  // this CPU lacks, is an error of MakeEmbreeTracer. The contract of the queries below holds
  // under every ISA; hit t values agree to the last bit wherever the same primitive is hit.
  std::string isa;
  // The length the rounding margins and sideways steps of the queries scale with. 0: the
  // largest |coordinate| of the scene's bounds. Extraction gives one taken from the base mesh,
  // so that an edit of the sculpt's outermost parts does not change every face's hits.
  float scale = 0;
};

// The names TracerOptions::isa accepts, narrowest first, and those this CPU can run.
std::span<const std::string_view> EmbreeIsaNames();
std::vector<std::string_view> SupportedEmbreeIsas();

std::string_view HitPolicyName(HitPolicy policy);  // "nearest", "outside-first", "inside-first"
std::string_view BuildQualityName(BuildQuality quality);  // "low", "medium", "high"
std::string_view RayModeName(RayMode mode);  // "single", "packet4", "packet8", "packet16", "stream"
// Inverses of the names. An unknown name is an error that lists the valid names.
StatusOr<HitPolicy> ParseHitPolicy(std::string_view name);
StatusOr<BuildQuality> ParseBuildQuality(std::string_view name);
StatusOr<RayMode> ParseRayMode(std::string_view name);

// ---- Query inputs and outputs --------------------------------------------------------------

struct NormalQuery {
  float distance = 0;  // the search distance d (> 0): each ray has tnear = 0, tfar = d
  HitPolicy policy = HitPolicy::kNearest;
  // TracerOptions::verify_hits for this query even when the tracer was built without it.
  bool verify_hits = false;
};

// Bits of NormalHits::flags. A miss has flags == 0.
struct HitFlags {
  static constexpr std::uint8_t kHit = 1;       // the query hit the sculpt
  static constexpr std::uint8_t kNegative = 2;  // the kept hit came from the ray along -n
  // The ray met the sculpt's back (inner) side: dot(ray direction, outward geometric normal)
  // > 0, the outward normal being the right-hand-rule normal of the face's winding (Embree's
  // Ng for triangles and quads). A grazing hit (dot == 0) counts as front.
  static constexpr std::uint8_t kBackFace = 4;
};

// Caller-owned output arrays, one entry per query; `t` and `flags` must have as many entries
// as there are queries, `prim` as many or none (then primitives are not reported).
struct NormalHits {
  std::span<float> t;             // signed distance along n (t <= 0 for -n hits); NaN on a miss
  std::span<SculptPrimId> prim;   // sculpt face index of the hit; invalid (-1) on a miss
  std::span<std::uint8_t> flags;  // HitFlags bits
};

// Work counters. A batch ADDS to the counters it is given, so a thread can keep one set for
// many batches; sum the per-thread sets at the end.
struct TraceCounters {
  std::uint64_t queries = 0;  // queries (normal queries, rays or points) received
  std::uint64_t invalid = 0;  // of those, skipped as malformed (non-finite values, bad range)
  // Rays handed to the backend (one lane of a packet is one ray). A normal query casts its
  // first ray (+n, or -n under inside-first) and casts the second only when it can change
  // the answer: not after a first hit under outside-/inside-first, and not after a first hit
  // at t = 0 under nearest (its tfar would be 0 and a tie keeps the +n hit); under nearest
  // the second ray's tfar is cut to the first hit's t. Rays not cast are not counted; the
  // vertex guard's rays (TracerOptions::retry_misses, verify_hits) are, and so is a ray cast
  // again past a surface in the margin before its window (see the hit contract above Tracer).
  // Closest-point queries cast no rays.
  std::uint64_t rays_cast = 0;
  std::uint64_t repair_rays = 0;  // of rays_cast, the vertex guard's
  // Hits within the tie band of a sculpt edge or vertex, resolved by the tie rule (the hit
  // contract below; src/trace/batch_kernels.h, kEdgeBand). Which hits count may differ in the
  // last bit of Embree's (u, v) between BVHs (not what they resolve to).
  std::uint64_t tie_hits = 0;
  std::uint64_t hits = 0;  // queries that found something
  TraceCounters& operator+=(const TraceCounters& other);
};

// An arbitrary ray for Tracer::Intersect. The hit must have t in [tnear, tfar].
struct Ray {
  Float3 origin;
  float tnear = 0;
  Float3 direction;
  float tfar = 0;
};

struct RayHit {
  float t = 0;        // NaN on a miss
  SculptPrimId prim;  // invalid on a miss
  Float3 normal;      // unit outward geometric normal of the hit primitive (0 on a miss)
  bool hit() const { return prim.valid(); }
};

struct ClosestPoint {
  float distance = 0;  // +infinity when nothing lies within the query's max distance
  Float3 point;        // closest point on the sculpt (NaN when nothing was found)
  SculptPrimId prim;   // face holding it; invalid when nothing was found
  bool found() const { return prim.valid(); }
};

// What the backend built, for reports.
struct TracerStats {
  // e.g. "embree 3.13.5 (avx2), low build, robust, retry misses, packet8"; the ISA is the one
  // whose kernels Embree runs, with ", forced" when TracerOptions::isa or DISPEX_EMBREE_ISA
  // chose it.
  std::string backend;
  std::size_t faces = 0;                // sculpt faces
  std::size_t quads = 0;                // primitives in the scene: quads (faces of 4 vertices) ...
  std::size_t triangles = 0;            // ... and triangles (triangles and fan-triangulated n-gons)
  double build_seconds = 0;             // scene commit (BVH build) wall time
  double setup_seconds = 0;             // validation and buffer setup before the build
  std::int64_t backend_bytes = 0;       // bytes the backend holds now (BVH, its buffers)
  std::int64_t backend_peak_bytes = 0;  // peak during the build
  std::size_t copied_bytes = 0;         // bytes dispex copied from the mesh (0 when all shared)
  bool shared_vertices = false;         // Embree reads mesh.positions in place
  bool shared_indices = false;          // Embree reads mesh.face_indices in place
  // TracerOptions::scale as used (the scene's largest |coordinate| when it was 0): the rounding
  // margins and sideways steps of the queries scale with it, so hits depend on it in rare cases.
  float scale = 0;
};

// ---- The tracer ----------------------------------------------------------------------------

// The hit contract, the same under every Embree ISA (TracerOptions::isa) and RayMode:
//  - A hit's t is dispex's, not Embree's: the ray o + t d (its own origin and direction) meets
//    the plane of the hit triangle (for a quad, whichever of its triangles v0 v1 v3 and
//    v2 v3 v1 Embree reports), computed in double and rounded to float once.
//  - Windows are closed: a surface is hit iff that t lies in [tnear, tfar], both ends included,
//    so a zero-length window [a, a] hits a surface exactly at a, and a ray from a point on the
//    surface hits it at t = 0. Embree is asked over a window 2^-18 of the scale wider at both
//    ends and dispex applies the rule; a surface in that margin before tnear is skipped and the
//    next one in the window found (an Embree filter that applies the same rule). Denormal
//    window ends count as 0 (the tracer runs with denormals-are-zero).
//  - Rays through shared edges and vertices hit (robust mode and the vertex guard): the guard
//    re-casts from an origin moved sideways only to find the primitive; t is still measured
//    from the query's own origin, so the guard does not move t.
//  - Direction components smaller than 2^-24 of the largest are taken as exactly zero: they
//    move a point on the ray by less than float rounding (and Embree's coherent 8-wide packets
//    lose rays that carry them).
//  - Ties: a normal query's hit within 2^-12 (of its triangle's barycentrics) of an edge or a
//    vertex, or on a face where the sculpt folds back over itself, is answered again in double
//    precision from the triangles around that edge, vertex or face: of those the line passes
//    through within the window margin of t, the nearest, then the lowest sculpt face (near an
//    edge or vertex with none passed through, the one passed closest). So the answer is the
//    same whichever face Embree reported, under any ISA, ray mode or BVH, even one of part of
//    the sculpt; only sheets that share no vertex and cross within rounding on the line stay
//    Embree's call. The back side flag is that triangle's.
//  - Of two surfaces closer together along the ray than Embree's rounding (~1e-7 of the
//    scale) and not sharing an edge or vertex, which one is nearest is Embree's call (and
//    for Intersect, at shared edges too: then t differs by rounding).

class Tracer {
 public:
  virtual ~Tracer() = default;

  // Normal queries: for each i, the line origins[i] + t normals[i] against the sculpt with
  // t in [-query.distance, +query.distance] (ends included), resolved by query.policy (see
  // HitPolicy); the hit at t = 0 of an origin on the surface is the +n ray's. The
  // result t is the ray parameter, i.e. a distance when the normal is unit length. A query
  // whose origin or normal is not finite, or whose normal is zero, is a miss and counts as
  // invalid. Requires origins.size() == normals.size() == out.t.size() == out.flags.size(),
  // out.prim empty or of that size, and query.distance > 0 and finite (checked: a violation
  // is a programming error and aborts).
  virtual void TraceNormals(std::span<const Float3> origins, std::span<const Float3> normals,
                            const NormalQuery& query, const NormalHits& out,
                            TraceCounters& counters) const = 0;

  // Arbitrary rays: the nearest hit with t in [rays[i].tnear, rays[i].tfar], ends included
  // (see the contract above; tfar may be infinity). A ray with a
  // non-finite or zero direction, a non-finite origin, tnear < 0 or tnear > tfar (NaN
  // included) is a miss and counts as invalid. Requires hits.size() == rays.size().
  virtual void Intersect(std::span<const Ray> rays, std::span<RayHit> hits,
                         TraceCounters& counters) const = 0;

  // Closest points: for each point, the nearest point on the sculpt's surface (quads as
  // the two triangles the ray queries intersect) within max_distance (may be infinity).
  // Distances are exact to float rounding of the result. A non-finite point is not found
  // and counts as invalid. Requires out.size() == points.size() and max_distance >= 0.
  virtual void ClosestPoints(std::span<const Float3> points, float max_distance,
                             std::span<ClosestPoint> out, TraceCounters& counters) const = 0;

  virtual const TracerStats& stats() const = 0;

  // OK unless the backend reported an error after it was built (an Embree device error
  // during a query). Call once after the queries, not per batch.
  virtual Status status() const = 0;
};

// Builds the Embree backend over `sculpt`. The mesh is not copied where Embree can read it
// in place (positions always when mesh.positions has capacity for one more vertex, face
// indices when all faces are quads or all are triangles), so the mesh must outlive the
// tracer and stay unchanged. Quads become Embree quads, triangles and fan-triangulated
// n-gons Embree triangles; primitive ids map back to sculpt face indices (SculptPrimId).
// Errors (Status): empty sculpt (no faces), a face with fewer than 3 vertices, a vertex
// index out of range, a non-finite vertex position (the message names the face or vertex),
// more primitives than 32-bit ids hold, an Embree device error, out of memory. The BVH build
// runs on the calling thread's TBB arena.
StatusOr<std::unique_ptr<Tracer>> MakeEmbreeTracer(const Mesh& sculpt,
                                                   const TracerOptions& options = {});

// ---- Search distance -----------------------------------------------------------------------

// The search distance as the user gives it: "auto", an absolute length ("0.05") or a
// percentage of the base mesh's bounding-box diagonal ("2%").
struct SearchDistanceSpec {
  enum class Kind : std::uint8_t { kAuto, kAbsolute, kRelative };
  Kind kind = Kind::kAuto;
  double value = 0;  // kAbsolute: object units; kRelative: fraction of the diagonal (0.02)
};

// Parses "auto", "<number>" or "<number>%". The number must be finite and > 0.
StatusOr<SearchDistanceSpec> ParseSearchDistance(std::string_view text);

struct SearchDistanceOptions {
  double ray_fraction = 0.15;  // the long rays: this fraction of the base diagonal
  double percentile = 0.999;   // of |t| over the hits
  double safety_factor = 1.5;  // applied to that percentile
  double min_fraction = 1e-4;  // floor, as a fraction of the base diagonal
};

// What EstimateSearchDistance found; every field is meant for the report.
struct SearchDistanceEstimate {
  double distance = 0;  // the search distance to use
  double base_diagonal = 0;
  double ray_length = 0;        // length of the long rays cast
  std::size_t samples = 0;      // queries cast
  std::size_t hits = 0;         // of those, hits
  double percentile = 0;        // the percentile used (0..1) ...
  double percentile_abs_t = 0;  // ... and |t| at it
  double median_abs_t = 0;
  double max_abs_t = 0;
  bool floored = false;  // distance was raised to min_fraction * base_diagonal
  bool capped = false;   // distance was lowered to ray_length
};

// The automatic search distance: casts `origins[i] ± t normals[i]` rays of length
// ray_fraction * base_diagonal (nearest policy) from a sparse sample of the base limit
// surface that the caller provides, takes the `percentile` of |t| over the hits and
// multiplies it by `safety_factor`; the result is clamped to [min_fraction * base_diagonal,
// ray_length]. Runs in parallel (TBB) and is deterministic. Errors: sizes differ, no
// samples, base_diagonal not finite and > 0, options out of range, or no sample hit the
// sculpt (the sculpt is probably not aligned with the base mesh).
StatusOr<SearchDistanceEstimate> EstimateSearchDistance(const Tracer& tracer,
                                                        std::span<const Float3> origins,
                                                        std::span<const Float3> normals,
                                                        double base_diagonal,
                                                        const SearchDistanceOptions& options = {});

// EstimateSearchDistance's long rays, `length` long, against `tracer`: lowers
// nearest_abs_t[i] to |t| of query i's hit where it hits nearer (nearest policy, hits
// verified: a long ray that slipped through a vertex would find the far side of the model).
// Parallel (TBB), deterministic. Over parts of a sculpt, one tracer each, from infinity: |t| of
// each query's hit on the whole sculpt, when every face that shares a vertex with a face of a
// part is in a part with it (so that a hit's neighbourhood is whole in some part). `side`, when
// given: which side of the origin that nearest hit lies on (+1, -1; 0 where equally near hits
// lie on both, or none).
// LowerNearestHits's rule for one query's hit (|t| and side): lowered to another's when that is
// nearer; equally near on the other side, side 0.
inline void KeepNearerHit(float& abs_t, std::int8_t& side, float other_abs_t,
                          std::int8_t other_side) {
  if (other_abs_t < abs_t) {
    abs_t = other_abs_t;
    side = other_side;
  } else if (other_abs_t == abs_t && side != other_side) {
    side = 0;
  }
}
void LowerNearestHits(const Tracer& tracer, std::span<const Float3> origins,
                      std::span<const Float3> normals, float length, std::span<float> nearest_abs_t,
                      std::span<std::int8_t> side = {});

// EstimateSearchDistance's rule over hits found another way (the same long rays answered
// without this tracer): `abs_t`, |t| of the hits among `samples` queries. Same errors.
StatusOr<SearchDistanceEstimate> SearchDistanceFromHits(std::vector<double> abs_t,
                                                        std::size_t samples, double base_diagonal,
                                                        const SearchDistanceOptions& options = {});

// The search distance for an absolute or relative spec: value, or value * base_diagonal.
// Error for kAuto (use EstimateSearchDistance) or a base_diagonal that is not finite and > 0.
StatusOr<double> ResolveSearchDistance(const SearchDistanceSpec& spec, double base_diagonal);

}  // namespace dispex
