// dispex verify: how far a displacement map is from the sculpt it was made from.
//
// The base limit surface displaced by the map (read bilinearly per face, as a renderer reads
// it: P + h N for a scalar map, P + D for a vector map, D from its channels in the frame at
// the point) is sampled densely on every Ptex face. Map -> sculpt: each sample's distance to
// the nearest point of the sculpt. Sculpt -> map: each sculpt vertex's distance to the nearest
// point of the displaced surface, tessellated on the same grid. Truth: the map against the
// exact displacement of a generated sculpt at each of its vertices' (face, u, v).
//
// The report as written (JSON, the summary): verify_report.cpp. The steps at face edges:
// edge_steps.cpp.
#include "dispex/verify.h"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>

#include "core/first_error.h"
#include "core/system.h"
#include "core/vec3.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/ptex_sampler.h"
#include "dispex/subdiv.h"
#include "dispex/trace.h"
#include "dispex/uv_charts.h"
#include "dispex/uv_map.h"
#include "dispex/vector_space.h"
#include "verify/edge_steps.h"
#include "verify/verify_stats.h"

namespace dispex {

namespace {

using verify::FrameScratch;
using verify::Summarise;

// What the map holds (DisplacementMapSpace): nullopt for a scalar map.
StatusOr<std::optional<VectorSpace>> MapSpace(const PtexFile& map) {
  const PtexMetaItem* space = map.FindMetaData(kVectorSpaceMetaKey);
  const PtexMetaItem* names = map.FindMetaData(kVectorChannelsMetaKey);
  const std::string space_value = space ? space->AsString() : "";
  const std::string names_value = names ? names->AsString() : "";
  return DisplacementMapSpace(map.name(), map.header().num_channels, map.header().alpha_channel,
                              space ? &space_value : nullptr, names ? &names_value : nullptr);
}

// A vector map's displacement at (u, v) of a face, in object space, the frame there being
// `frame` (the per-face bilinear reader, as for scalar maps).
Float3 MapVector(const PtexFile& map, VectorSpace space, PtexFaceId face, float u, float v,
                 const SurfaceFrame& frame) {
  const float c[3] = {map.Sample(face, u, v, 0), map.Sample(face, u, v, 1),
                      map.Sample(face, u, v, 2)};
  return VectorFromChannels(space, frame, c);
}

// The map under test as the displaced surface reads it: a Ptex map per face, or a UV-space
// map through the cage's UVs (dispex/uv_charts.h), bilinear within its UDIM tile.
struct MapReader {
  std::string name;
  const PtexFile* ptex = nullptr;
  const UvMap* uv = nullptr;
  const PtexUvCharts* charts = nullptr;
  std::optional<VectorSpace> space;  // vector maps only (UV-space ones: object)
  // A scalar Ptex map read by the reference Ptex filter, which blends over face edges as a
  // renderer does (TruthScalar).
  const PtexMapSampler* across = nullptr;
  // A UV-space map: per Ptex face, set where a point of it has no tile (read as 0).
  std::vector<std::atomic<std::uint8_t>>* uv_missing = nullptr;

  float Scalar(PtexFaceId face, float u, float v) const {
    if (ptex != nullptr) return ptex->Sample(face, u, v);
    float h = 0;
    ReadUv(face, u, v, {&h, 1});
    return h;
  }
  Float3 Vector(PtexFaceId face, float u, float v, const SurfaceFrame& frame) const {
    if (ptex != nullptr) return MapVector(*ptex, *space, face, u, v, frame);
    float c[3] = {0, 0, 0};
    ReadUv(face, u, v, c);
    return VectorFromChannels(*space, frame, c);
  }
  // A scalar map as the truth comparison reads it: as a renderer reads it, across face edges
  // where the map is a Ptex file (a UV map's tiles are read through the cage's UVs, which
  // cross face edges already). Within a face the two reads agree; within half a texel of a
  // face edge the per-face read is clamped to the outermost texel centre, a displacement's
  // slope times that distance off the surface at the edge. Vector maps are read per face, in
  // the frame at the record (tests/verify/vector_truth_test.cpp).
  float TruthScalar(PtexFaceId face, float u, float v) const {
    return across == nullptr ? Scalar(face, u, v)
                             : static_cast<float>(across->SampleAcrossFaces(face, u, v));
  }
  // The UV map's channels at (u, v) of a Ptex face, through the cage's UVs.
  void ReadUv(PtexFaceId face, float u, float v, std::span<float> out) const {
    double at[2];
    charts->Evaluate(face, u, v, at);
    if (!uv->Sample(at[0], at[1], out) && uv_missing != nullptr) {
      (*uv_missing)[static_cast<std::size_t>(face.value)].store(1, std::memory_order_relaxed);
    }
  }
  // Samples per side of a face's displaced grid: twice the Ptex face's resolution within
  // [8, 64]; for a UV map, twice the texels its UV footprint spans within [8, 64].
  int SamplesPerSide(PtexFaceId face) const {
    if (ptex != nullptr) {
      const PtexFaceInfo& info = ptex->face_info(face);
      return std::clamp(2 * std::max(info.ures(), info.vres()), 8, 64);
    }
    const double* c = charts->corners(face);
    double span = 0;
    for (int k = 0; k < 4; ++k) {
      const int l = (k + 1) % 4;
      span = std::max(span, std::hypot(c[2 * l] - c[2 * k], c[2 * l + 1] - c[2 * k + 1]));
    }
    return std::clamp(static_cast<int>(std::ceil(2 * span * uv->resolution())), 8, 64);
  }
};

struct DisplacedSurface {
  Mesh mesh;                    // (k+1)^2 vertices and k^2 quads per face
  std::vector<Float3> samples;  // k^2 points per face at cell centres
  std::vector<std::int32_t> sample_face;
  std::vector<int> k;  // per face, 0 for holes
};

StatusOr<DisplacedSurface> Displace(const LimitSurface& surface, const MapReader& map,
                                    int fixed_k) {
  const std::optional<VectorSpace> space = map.space;
  const int n = surface.num_ptex_faces();
  DisplacedSurface d;
  d.k.assign(static_cast<std::size_t>(n), 0);
  std::vector<std::size_t> vertex_start(static_cast<std::size_t>(n) + 1, 0);
  std::vector<std::size_t> sample_start(static_cast<std::size_t>(n) + 1, 0);
  for (int f = 0; f < n; ++f) {
    PtexFaceId face(f);
    int k = 0;
    if (!surface.is_hole(face)) k = fixed_k > 0 ? fixed_k : map.SamplesPerSide(face);
    d.k[static_cast<std::size_t>(f)] = k;
    vertex_start[f + 1] = vertex_start[f] + (k ? std::size_t(k + 1) * (k + 1) : 0);
    sample_start[f + 1] = sample_start[f] + std::size_t(k) * k;
  }
  d.mesh.source = map.name + " (displaced)";
  d.mesh.positions.reserve(vertex_start[n] + 1);
  d.mesh.positions.resize(vertex_start[n]);
  d.samples.resize(sample_start[n]);
  d.sample_face.resize(sample_start[n]);
  d.mesh.face_offsets.resize(sample_start[n] + 1);
  d.mesh.face_indices.resize(4 * sample_start[n]);
  for (std::size_t q = 0; q <= sample_start[n]; ++q) d.mesh.face_offsets[q] = std::uint32_t(4 * q);

  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<FrameScratch> scratch;
  std::mutex mutex;
  Status error;
  tbb::parallel_for(0, n, [&](int f) {
    const int k = d.k[static_cast<std::size_t>(f)];
    if (k == 0) return;
    PtexFaceId face(f);
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    FrameScratch& s = scratch.local();
    // Corner grid (for the mesh) then cell centres (for the samples), in one evaluation.
    const std::size_t corners = std::size_t(k + 1) * (k + 1), centres = std::size_t(k) * k;
    s.uv.resize(2 * (corners + centres));
    std::size_t i = 0;
    for (int y = 0; y <= k; ++y) {
      for (int x = 0; x <= k; ++x) {
        s.uv[i++] = float(x) / float(k);
        s.uv[i++] = float(y) / float(k);
      }
    }
    for (int y = 0; y < k; ++y) {
      for (int x = 0; x < k; ++x) {
        s.uv[i++] = (float(x) + 0.5f) / float(k);
        s.uv[i++] = (float(y) + 0.5f) / float(k);
      }
    }
    s.Resize(corners + centres);
    Status st = space ? evaluator->EvaluatePointFrames(face, s.uv, s.Frames())
                      : evaluator->EvaluatePoints(face, s.uv, s.p, s.nrm);
    if (!st.ok()) {
      std::lock_guard lock(mutex);
      if (error.ok()) error = st;
      return;
    }
    auto displaced = [&](std::size_t j) {
      const float u = s.uv[2 * j], v = s.uv[2 * j + 1];
      if (space) {
        const Float3 m = map.Vector(face, u, v, s.At(j));
        return Float3{s.p[3 * j] + m.x, s.p[3 * j + 1] + m.y, s.p[3 * j + 2] + m.z};
      }
      const float h = map.Scalar(face, u, v);
      return Float3{s.p[3 * j] + h * s.nrm[3 * j], s.p[3 * j + 1] + h * s.nrm[3 * j + 1],
                    s.p[3 * j + 2] + h * s.nrm[3 * j + 2]};
    };
    Float3* vertices = d.mesh.positions.data() + vertex_start[f];
    for (std::size_t j = 0; j < corners; ++j) vertices[j] = displaced(j);
    for (std::size_t j = 0; j < centres; ++j) {
      d.samples[sample_start[f] + j] = displaced(corners + j);
      d.sample_face[sample_start[f] + j] = f;
    }
    std::int32_t* quads = d.mesh.face_indices.data() + 4 * sample_start[f];
    const auto base = static_cast<std::int32_t>(vertex_start[f]);
    for (int y = 0; y < k; ++y) {
      for (int x = 0; x < k; ++x) {
        std::int32_t v0 = base + y * (k + 1) + x;
        *quads++ = v0;
        *quads++ = v0 + 1;
        *quads++ = v0 + k + 2;
        *quads++ = v0 + k + 1;
      }
    }
  });
  DISPEX_RETURN_IF_ERROR(error);
  for (const Float3& p : d.mesh.positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return Status::Error(map.name + ": the map holds values that are not finite");
    }
  }
  return d;
}

// A tracer for ClosestDistances: no normal queries, so no tie-rule table.
StatusOr<std::unique_ptr<Tracer>> ClosestPointTracer(const Mesh& mesh) {
  TracerOptions options;
  options.normal_queries = false;
  return MakeEmbreeTracer(mesh, options);
}

std::vector<float> ClosestDistances(const Tracer& tracer, std::span<const Float3> points) {
  std::vector<float> distances(points.size());
  constexpr std::size_t kBatch = 4096;
  tbb::enumerable_thread_specific<std::vector<ClosestPoint>> results;
  tbb::parallel_for(std::size_t{0}, (points.size() + kBatch - 1) / kBatch, [&](std::size_t b) {
    std::size_t begin = b * kBatch, end = std::min(points.size(), begin + kBatch);
    auto& out = results.local();
    out.resize(end - begin);
    TraceCounters counters;
    tracer.ClosestPoints(points.subspan(begin, end - begin), std::numeric_limits<float>::infinity(),
                         out, counters);
    for (std::size_t i = begin; i < end; ++i) distances[i] = out[i - begin].distance;
  });
  return distances;
}

const char* TruthQuantity(bool vector_map, bool vector_truth) {
  if (vector_map) return vector_truth ? "|D_map - D|" : "|D_map.N - h|";
  return vector_truth ? "|map N - D|" : "|map - h|";
}

// The map against the truth at every record (VerifyReport::truth_quantity).
struct TruthComparison {
  std::vector<float> errors;         // the error
  std::vector<float> signed_errors;  // the signed error of the normal part
  std::vector<float> map_normal;     // the map's value, or D_map.N
  std::vector<Float3> map_d;         // with D in the truth: the map's D (map N for a scalar map)
};

StatusOr<TruthComparison> CompareTruth(const LimitSurface& surface, const MapReader& map,
                                       const GroundTruth& truth) {
  const std::optional<VectorSpace> space = map.space;
  const std::size_t n = truth.size();
  TruthComparison out;
  out.errors.resize(n);
  out.signed_errors.resize(n);
  out.map_normal.resize(n);
  const bool vector_truth = !truth.d.empty();
  if (!space && !vector_truth) {  // the map's value against h: no frames needed
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
      float value = map.TruthScalar(truth.faces[i], truth.uvs[2 * i], truth.uvs[2 * i + 1]);
      out.map_normal[i] = value;
      out.signed_errors[i] = value - truth.h[i];
      out.errors[i] = std::abs(out.signed_errors[i]);
    });
    return out;
  }
  if (vector_truth) out.map_d.resize(n);
  // The records of each face, evaluated together.
  const std::size_t faces = static_cast<std::size_t>(surface.num_ptex_faces());
  std::vector<std::size_t> start(faces + 1, 0), order(n);
  for (std::size_t i = 0; i < n; ++i) ++start[static_cast<std::size_t>(truth.faces[i].value) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      order[fill[static_cast<std::size_t>(truth.faces[i].value)]++] = i;
    }
  }
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  tbb::enumerable_thread_specific<FrameScratch> scratch;
  FirstError error;
  tbb::parallel_for(std::size_t{0}, faces, [&](std::size_t f) {
    const std::size_t begin = start[f], end = start[f + 1];
    if (begin == end) return;
    const PtexFaceId face(static_cast<std::int32_t>(f));
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    FrameScratch& s = scratch.local();
    s.uv.resize(2 * (end - begin));
    for (std::size_t k = begin; k < end; ++k) {
      s.uv[2 * (k - begin)] = truth.uvs[2 * order[k]];
      s.uv[2 * (k - begin) + 1] = truth.uvs[2 * order[k] + 1];
    }
    s.Resize(end - begin);
    Status st = evaluator->EvaluatePointFrames(face, s.uv, s.Frames());
    if (!st.ok()) return error.Record(static_cast<int>(f), st);
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = order[k], j = k - begin;
      const float u = s.uv[2 * j], v = s.uv[2 * j + 1];
      const SurfaceFrame frame = s.At(j);
      const Vec3d normal = ToVec3d(frame.normal);
      const double h = truth.h[i];
      const Vec3d d =
          vector_truth ? Vec3d{truth.d[3 * i], truth.d[3 * i + 1], truth.d[3 * i + 2]} : Vec3d{};
      double error_value, signed_error, map_normal;
      Vec3d map_d;
      if (space) {
        map_d = ToVec3d(map.Vector(face, u, v, frame));
        map_normal = Dot(map_d, normal);
        signed_error = vector_truth ? Dot(map_d - d, normal) : map_normal - h;
        error_value = vector_truth ? Length(map_d - d) : std::abs(signed_error);
      } else {
        // The normal part from the record's own h, so that a map of a scalar pattern measures
        // as against a scalar truth; the tangential part of D, which h N lacks, on top.
        map_normal = map.TruthScalar(face, u, v);
        map_d = normal * map_normal;
        signed_error = map_normal - h;
        const double tangential = Length(d - normal * h);
        error_value = std::sqrt(signed_error * signed_error + tangential * tangential);
      }
      out.errors[i] = static_cast<float>(error_value);
      out.signed_errors[i] = static_cast<float>(signed_error);
      out.map_normal[i] = static_cast<float>(map_normal);
      if (vector_truth) out.map_d[i] = FromVec3d<Float3>(map_d);
    }
  });
  if (error.failed()) return error.status();
  return out;
}

void Threshold(VerifyReport& r, const char* what, const ErrorStats& s, double limit,
               const char* option) {
  if (!r.passed || limit <= 0 || s.max <= limit) return;
  r.passed = false;
  r.failure = fmt::format("{} max error {:.6g} exceeds {} = {:.6g}", what, s.max, option, limit);
}

void RmsThreshold(VerifyReport& r, const char* what, const ErrorStats& s, double limit) {
  if (!r.passed || limit <= 0 || s.rms <= limit) return;
  r.passed = false;
  r.failure = fmt::format("{} RMS error {:.6g} exceeds max_rms = {:.6g}", what, s.rms, limit);
}

void P99Threshold(VerifyReport& r, const char* what, const ErrorStats& s, double limit) {
  if (!r.passed || limit <= 0 || s.p99 <= limit) return;
  r.passed = false;
  r.failure = fmt::format("{} 99th percentile {:.6g} exceeds max_p99 = {:.6g}", what, s.p99, limit);
}

// Sculpt vertices, evenly strided to at most `max_points` (0: all).
std::vector<Float3> SculptPoints(const Mesh& sculpt, std::size_t max_points) {
  std::size_t stride = 1;
  if (max_points > 0 && sculpt.num_vertices() > max_points) {
    stride = (sculpt.num_vertices() + max_points - 1) / max_points;
  }
  std::vector<Float3> points;
  points.reserve(sculpt.num_vertices() / stride + 1);
  for (std::size_t v = 0; v < sculpt.num_vertices(); v += stride) {
    points.push_back(sculpt.positions[v]);
  }
  return points;
}

// The sculpt's vertices (at most max_points of them) to `mesh`: the sculpt->map direction.
StatusOr<ErrorStats> SculptToMesh(const Mesh& sculpt, const Mesh& mesh, std::size_t max_points) {
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer, ClosestPointTracer(mesh));
  std::vector<float> d = ClosestDistances(*tracer, SculptPoints(sculpt, max_points));
  return Summarise(d);
}

// The largest allowed distance: max_error, max_error_rel times the diagonal, or the smaller.
double DistanceLimit(const VerifyOptions& options, double diagonal) {
  double limit = options.max_error;
  if (options.max_error_rel > 0) {
    const double rel = options.max_error_rel * diagonal;
    limit = limit > 0 ? std::min(limit, rel) : rel;
  }
  return limit;
}

// VerifyOptions::displaced_path: a displaced mesh against the sculpt, both ways.
StatusOr<VerifyReport> VerifyDisplacedMesh(const VerifyOptions& options) {
  Stopwatch clock;
  if (options.sculpt_path.empty()) {
    return Status::Error(options.displaced_path +
                         ": a displaced mesh is measured against a sculpt");
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh displaced, ReadMesh(options.displaced_path));
  DISPEX_ASSIGN_OR_RETURN(Mesh sculpt, ReadMesh(options.sculpt_path));
  VerifyReport r;
  r.displaced_mesh = true;
  r.diagonal = ComputeBounds(displaced).diagonal();
  {
    DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> sculpt_tracer, ClosestPointTracer(sculpt));
    std::vector<float> d = ClosestDistances(*sculpt_tracer, displaced.positions);
    r.map_to_sculpt = Summarise(d);
  }
  DISPEX_ASSIGN_OR_RETURN(r.sculpt_to_map,
                          SculptToMesh(sculpt, displaced, options.max_sculpt_points));
  r.measured_distances = true;
  const double limit_abs = DistanceLimit(options, r.diagonal);
  const char* option = options.max_error_rel > 0 ? "max_error_rel" : "max_error";
  Threshold(r, "displaced->sculpt", r.map_to_sculpt, limit_abs, option);
  Threshold(r, "sculpt->displaced", r.sculpt_to_map, limit_abs, option);
  P99Threshold(r, "displaced->sculpt", r.map_to_sculpt, options.max_p99);
  P99Threshold(r, "sculpt->displaced", r.sculpt_to_map, options.max_p99);
  RmsThreshold(r, "displaced->sculpt", r.map_to_sculpt, options.max_rms);
  RmsThreshold(r, "sculpt->displaced", r.sculpt_to_map, options.max_rms);
  r.seconds = clock.seconds();
  return r;
}

// The map under test, open: its reader (MapReader) and what it points into, and what the map
// records of the sculpt it was made from. Built in place: `reader` points into it.
struct MapUnderTest {
  MapReader reader;
  std::optional<PtexFile> ptex;
  std::optional<UvMap> uv;
  std::optional<PtexUvCharts> charts;
  std::vector<PtexFaceInfo> faces;                      // a Ptex map's (MeasureEdgeSteps)
  std::vector<std::vector<std::vector<float>>> fields;  // a Ptex map's (MeasureEdgeSteps)
  std::optional<PtexMapSampler> sampler;
  std::string sculpt_fingerprint;
  std::int64_t sculpt_vertices = 0;  // as the map records it (0: not recorded)
  std::vector<std::atomic<std::uint8_t>> uv_missing;
};

Status CheckOptions(const VerifyOptions& options) {
  if (options.samples_per_face < 0 || options.samples_per_face > 512) {
    return Status::Error(
        fmt::format("samples_per_face = {}: must be 0..512", options.samples_per_face));
  }
  return Status::Ok();
}

// A UV-space map (UDIM tiles), read through the cage's UVs: 3 channels are an object-space
// vector map; its tolerance from the tiles' attributes.
Status OpenUvMap(const VerifyOptions& options, const Mesh& base, const LimitSurface& surface,
                 MapUnderTest& m, VerifyReport& r) {
  DISPEX_ASSIGN_OR_RETURN(m.uv, UvMap::Open(options.map_path));
  if (m.uv->channels() == 3) {
    const std::string uv_space = m.uv->Attribute("dispex:space");
    if (uv_space.empty()) {
      r.warnings.push_back(options.map_path +
                           ": 3 channels and no dispex:space: read as an object-space vector map");
    } else if (uv_space != "object") {
      return Status::Error(fmt::format(
          "{}: 3 channels in dispex:space '{}': UV-space vector maps are read in object space",
          options.map_path, uv_space));
    }
    m.reader.space = VectorSpace::kObject;
    r.map_vector = true;
    r.map_space = VectorSpace::kObject;
  }
  DISPEX_ASSIGN_OR_RETURN(m.charts, PtexUvCharts::Build(base, surface));
  m.reader.uv = &*m.uv;
  m.uv_missing =
      std::vector<std::atomic<std::uint8_t>>(static_cast<std::size_t>(surface.num_ptex_faces()));
  m.reader.uv_missing = &m.uv_missing;
  m.reader.charts = &*m.charts;
  const std::string tolerance = m.uv->Attribute("dispex:tolerance");
  if (!tolerance.empty()) r.map_tolerance = std::strtod(tolerance.c_str(), nullptr);
  return Status::Ok();
}

// A vector map whose edge filter mode is not its space's: a warning.
void CheckEdgeFilter(const PtexFile& map, VectorSpace space, const std::string& map_path,
                     VerifyReport& r) {
  const PtexEdgeFilterMode expected = space == VectorSpace::kObject
                                          ? PtexEdgeFilterMode::kNone
                                          : PtexEdgeFilterMode::kTangentVector;
  if (map.header().edge_filter != expected) {
    r.warnings.push_back(fmt::format(
        "{}: a {} vector map with edge filter mode {} ({} expected): filters across faces "
        "will not turn its vectors as they should",
        map_path, VectorSpaceName(space), PtexEdgeFilterModeName(map.header().edge_filter),
        PtexEdgeFilterModeName(expected)));
  }
}

// What a Ptex map records of its extraction (dispex:statistics) and of its sculpt (vertices,
// fingerprint).
void ReadMapRecords(const PtexFile& map, MapUnderTest& m, VerifyReport& r) {
  if (const PtexMetaItem* stats = map.FindMetaData("dispex:statistics")) {
    auto j = nlohmann::json::parse(stats->AsString(), nullptr, false);
    if (j.is_object()) {
      r.map_misses = j.value("misses", std::int64_t{-1});
      r.map_holes_filled = j.value("holes_filled", std::int64_t{-1});
      r.map_faces_filled_from_neighbours =
          j.value("faces_filled_from_neighbours", std::int64_t{-1});
      r.map_tolerance = j.value("tolerance", 0.0);
      if (j.contains("sculpt") && j["sculpt"].is_object()) {
        m.sculpt_vertices = j["sculpt"].value("vertices", std::int64_t{0});
      }
    }
  }
  if (const PtexMetaItem* fingerprint = map.FindMetaData("dispex:sculpt_fingerprint")) {
    m.sculpt_fingerprint = fingerprint->AsString();
  }
}

// A Ptex map of this base (one face per Ptex face), scalar or vector (MapSpace).
Status OpenPtexMap(const VerifyOptions& options, const LimitSurface& surface, MapUnderTest& m,
                   VerifyReport& r) {
  DISPEX_ASSIGN_OR_RETURN(m.ptex, PtexFile::Open(options.map_path));
  const PtexFile& map = *m.ptex;
  if (map.num_faces() != surface.num_ptex_faces()) {
    return Status::Error(fmt::format(
        "{}: {} faces, but {} has {} Ptex faces: not a map of this "
        "base mesh",
        options.map_path, map.num_faces(), options.base_path, surface.num_ptex_faces()));
  }
  DISPEX_ASSIGN_OR_RETURN(const std::optional<VectorSpace> space, MapSpace(map));
  r.map_vector = space.has_value();
  if (space) {
    r.map_space = *space;
    CheckEdgeFilter(map, *space, options.map_path, r);
  }
  ReadMapRecords(map, m, r);
  m.reader.ptex = &map;
  m.reader.space = space;
  return Status::Ok();
}

// A scalar Ptex map compared with a truth is read across face edges (MapReader::TruthScalar),
// from the texels MeasureEdgeSteps read.
void ReadAcrossFaces(const VerifyOptions& options, MapUnderTest& m) {
  if (!options.truth_path.empty() && !m.reader.space) {
    m.sampler.emplace(m.faces, m.fields[0]);
    m.reader.across = &*m.sampler;
  }
}

// The truth file, checked: one record per vertex of the sculpt the map was made from (where
// the map records their count), each at a point of a Ptex face of the base.
StatusOr<GroundTruth> ReadCheckedTruth(const VerifyOptions& options, const LimitSurface& surface,
                                       std::int64_t map_sculpt_vertices) {
  DISPEX_ASSIGN_OR_RETURN(GroundTruth truth, ReadGroundTruth(options.truth_path));
  // One record per sculpt vertex: another count is another sculpt's truth.
  if (map_sculpt_vertices > 0 && static_cast<std::int64_t>(truth.size()) != map_sculpt_vertices) {
    return Status::Error(fmt::format(
        "{}: {} records, but {} was made from a sculpt of {} vertices: the truth of another "
        "sculpt",
        options.truth_path, truth.size(), options.map_path, map_sculpt_vertices));
  }
  for (std::size_t i = 0; i < truth.size(); ++i) {
    int f = truth.faces[i].value;
    float u = truth.uvs[2 * i], v = truth.uvs[2 * i + 1];
    if (f < 0 || f >= surface.num_ptex_faces() || !(u >= 0 && u <= 1 && v >= 0 && v <= 1)) {
      return Status::Error(fmt::format("{}: record {} names face {} at ({}, {}), outside {}",
                                       options.truth_path, i, f, u, v, options.map_path));
    }
  }
  return truth;
}

// The truth's signed mean and every face's largest error (NaN for a face without records).
void TruthPerFace(const GroundTruth& truth, const TruthComparison& compared, VerifyReport& r) {
  double sum = 0;
  for (float e : compared.signed_errors) sum += e;
  r.truth_signed_mean = truth.size() ? sum / double(truth.size()) : 0;
  r.face_truth_max.assign(r.ptex_faces, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    double& m = r.face_truth_max[static_cast<std::size_t>(truth.faces[i].value)];
    if (!(m >= double(compared.errors[i]))) m = double(compared.errors[i]);
  }
}

// The per-record bound k tau + 2 x the sculpt's local linear error: the records over it, those
// unbounded, the worst record and the local errors' statistics.
void TruthLocalBound(const VerifyOptions& options, const GroundTruth& truth,
                     const TruthComparison& compared, VerifyReport& r) {
  // Sequential, so the worst record is the first of the largest ratio.
  r.truth_local_checked = true;
  r.truth_local_tolerance_factor = options.truth_local_tolerance_factor;
  std::vector<float> local_errors;
  local_errors.reserve(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    double bound = options.truth_local_tolerance_factor * r.truth_tolerance +
                   2.0 * double(truth.local_error[i]);
    if (std::isinf(bound)) {
      ++r.truth_unbounded;
      continue;
    }
    local_errors.push_back(truth.local_error[i]);
    double ratio = double(compared.errors[i]) / bound;
    if (ratio > 1) ++r.truth_over_bound;
    if (ratio > r.truth_worst_ratio || !std::isfinite(ratio)) {
      r.truth_worst_ratio = ratio;
      VerifyReport::TruthRecord& w = r.truth_worst;
      w = {i,          truth.faces[i].value,   truth.uvs[2 * i],    truth.uvs[2 * i + 1],
           truth.h[i], compared.map_normal[i], truth.local_error[i]};
      if (!truth.d.empty()) {
        w.vector = true;
        const Float3& m = compared.map_d[i];
        for (int c = 0; c < 3; ++c) w.d[c] = truth.d[3 * i + static_cast<std::size_t>(c)];
        w.map_d[0] = m.x, w.map_d[1] = m.y, w.map_d[2] = m.z;
      }
    }
  }
  r.truth_local_error = Summarise(local_errors);
}

// The map against the truth file: the errors' statistics, per face, against the per-record
// bound, and the truth's RMS and p99 limits.
Status MeasureTruth(const VerifyOptions& options, const LimitSurface& surface,
                    const MapUnderTest& m, VerifyReport& r) {
  DISPEX_ASSIGN_OR_RETURN(GroundTruth truth, ReadCheckedTruth(options, surface, m.sculpt_vertices));
  r.truth_version = truth.version();
  r.truth_quantity = TruthQuantity(m.reader.space.has_value(), !truth.d.empty());
  DISPEX_ASSIGN_OR_RETURN(TruthComparison compared, CompareTruth(surface, m.reader, truth));
  TruthPerFace(truth, compared, r);
  r.truth_tolerance = options.tolerance > 0 ? options.tolerance : r.map_tolerance;
  if (r.truth_tolerance > 0 && options.truth_local_bound && !truth.local_error.empty()) {
    TruthLocalBound(options, truth, compared, r);
  }
  r.truth = Summarise(compared.errors);  // last: reorders the errors
  r.measured_truth = true;
  if (r.truth.count && !std::isfinite(r.truth.max)) {
    return Status::Error(options.map_path + ": the map holds values that are not finite");
  }
  if (r.truth_tolerance > 0) {
    r.truth_rms_limit = options.truth_rms_factor * r.truth_tolerance;
    r.truth_p99_limit = options.truth_p99_factor * r.truth_tolerance;
  }
  return Status::Ok();
}

// The samples per side of the displaced surface's faces, smallest and largest (holes aside).
void SamplesPerFaceRange(const DisplacedSurface& displaced, VerifyReport& r) {
  r.samples_per_face_min = 1 << 30;
  for (int k : displaced.k) {
    if (k == 0) continue;
    r.samples_per_face_min = std::min(r.samples_per_face_min, k);
    r.samples_per_face_max = std::max(r.samples_per_face_max, k);
  }
}

// Map -> sculpt: each sample's distance to the sculpt, every face's largest (NaN for holes)
// and the 10 worst faces.
Status MapToSculpt(const Mesh& sculpt, const DisplacedSurface& displaced, VerifyReport& r) {
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> sculpt_tracer, ClosestPointTracer(sculpt));
  std::vector<float> d = ClosestDistances(*sculpt_tracer, displaced.samples);
  std::vector<double> face_max(r.ptex_faces, 0.0);
  for (std::size_t i = 0; i < d.size(); ++i) {
    double& m = face_max[static_cast<std::size_t>(displaced.sample_face[i])];
    m = std::max(m, double(d[i]));
  }
  std::vector<int> order(r.ptex_faces);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return face_max[a] > face_max[b]; });
  for (std::size_t i = 0; i < std::min<std::size_t>(10, order.size()); ++i) {
    if (face_max[order[i]] > 0) r.worst_faces.push_back({order[i], face_max[order[i]]});
  }
  r.map_to_sculpt = Summarise(d);
  r.face_map_to_sculpt_max = std::move(face_max);
  for (std::size_t f = 0; f < r.ptex_faces; ++f) {
    if (displaced.k[f] == 0) r.face_map_to_sculpt_max[f] = std::numeric_limits<double>::quiet_NaN();
  }
  return Status::Ok();
}

// The sculpt against the displaced surface, both ways (map -> sculpt, sculpt -> map).
Status MeasureDistances(const VerifyOptions& options, const LimitSurface& surface,
                        const MapUnderTest& m, VerifyReport& r) {
  DISPEX_ASSIGN_OR_RETURN(Mesh sculpt, ReadMesh(options.sculpt_path));
  if (!m.sculpt_fingerprint.empty() && MeshFingerprint(sculpt) != m.sculpt_fingerprint) {
    r.warnings.push_back(fmt::format(
        "{}: not the sculpt {} was made from (its fingerprint differs): an edited sculpt, or "
        "another one",
        options.sculpt_path, options.map_path));
  }
  DISPEX_ASSIGN_OR_RETURN(DisplacedSurface displaced,
                          Displace(surface, m.reader, options.samples_per_face));
  SamplesPerFaceRange(displaced, r);
  if (displaced.samples.empty()) return Status::Error(options.base_path + ": no surface");
  DISPEX_RETURN_IF_ERROR(MapToSculpt(sculpt, displaced, r));
  DISPEX_ASSIGN_OR_RETURN(r.sculpt_to_map,
                          SculptToMesh(sculpt, displaced.mesh, options.max_sculpt_points));
  r.measured_distances = true;
  return Status::Ok();
}

// A UV-space map's Ptex faces with points that no tile holds: listed, and a warning.
void UvFacesWithoutTile(const MapUnderTest& m, const std::string& map_path, VerifyReport& r) {
  for (std::size_t f = 0; f < m.uv_missing.size(); ++f) {
    if (m.uv_missing[f].load()) r.uv_faces_without_tile.push_back(static_cast<int>(f));
  }
  if (r.uv_faces_without_tile.empty()) return;
  std::string list;
  for (std::size_t i = 0; i < r.uv_faces_without_tile.size() && i < 10; ++i) {
    list += fmt::format("{}{}", i ? ", " : "", r.uv_faces_without_tile[i]);
  }
  if (r.uv_faces_without_tile.size() > 10) list += ", ...";
  r.warnings.push_back(
      fmt::format("{}: {} Ptex faces have points whose UVs no tile holds (read as 0): {}", map_path,
                  r.uv_faces_without_tile.size(), list));
}

// The sculpt's points' mean distance to the displaced surface, in tolerances: over
// max_mean_tolerances, not the sculpt the map was made from.
void MeanDistanceBound(const VerifyOptions& options, VerifyReport& r) {
  r.distance_tolerance = options.tolerance > 0 ? options.tolerance : r.map_tolerance;
  if (!r.measured_distances || !(options.max_mean_tolerances > 0) || !(r.distance_tolerance > 0)) {
    return;
  }
  // The sculpt's own points: the displaced surface's points also carry the sagging of the
  // sculpt's facets between its vertices, many tolerances on a coarse sculpt.
  const ErrorStats& s = r.sculpt_to_map;
  if (r.passed && s.mean > options.max_mean_tolerances * r.distance_tolerance) {
    r.passed = false;
    r.failure = fmt::format(
        "sculpt->map mean distance {:.4g} is {:.3g} tolerances, over max_mean_tolerances {} x "
        "{:.4g}: is this the sculpt the map was made from?",
        s.mean, s.mean / r.distance_tolerance, options.max_mean_tolerances, r.distance_tolerance);
  }
}

// The truth's bounds in tolerances: per record (a failure there is the report's failure), then
// RMS and p99.
void TruthBounds(const VerifyOptions& options, VerifyReport& r) {
  if (!r.measured_truth) return;
  if (r.truth_over_bound > 0) {
    const auto& w = r.truth_worst;
    r.passed = false;
    const std::string values =
        w.vector ? fmt::format("map D ({:.4g}, {:.4g}, {:.4g}), D ({:.4g}, {:.4g}, {:.4g})",
                               w.map_d[0], w.map_d[1], w.map_d[2], w.d[0], w.d[1], w.d[2])
                 : fmt::format("map {:.6g}, h {:.6g}", w.map, w.h);
    r.failure = fmt::format(
        "truth: {} of {} records exceed {} x tolerance + 2 x local linear error in {} (worst "
        "{:.3g} x, record {}: face {} at ({:.4g}, {:.4g}), {}, bound {:.4g})",
        r.truth_over_bound, r.truth.count, r.truth_local_tolerance_factor, r.truth_quantity,
        r.truth_worst_ratio, w.index, w.face, w.u, w.v, values,
        r.truth_local_tolerance_factor * r.truth_tolerance + 2.0 * w.local_error);
  }
  if (r.passed && r.truth_rms_limit > 0 && r.truth.rms > r.truth_rms_limit) {
    r.passed = false;
    r.failure =
        fmt::format("truth RMS error {:.4g} ({}) exceeds truth_rms_factor {} x tolerance {:.4g}",
                    r.truth.rms, r.truth_quantity, options.truth_rms_factor, r.truth_tolerance);
  }
  if (r.passed && r.truth_p99_limit > 0 && r.truth.p99 > r.truth_p99_limit) {
    r.passed = false;
    r.failure =
        fmt::format("truth p99 error {:.4g} ({}) exceeds truth_p99_factor {} x tolerance {:.4g}",
                    r.truth.p99, r.truth_quantity, options.truth_p99_factor, r.truth_tolerance);
  }
}

// The bounds and the verdict: the first bound failed is the report's failure (a truth record
// over its bound overrides the mean distance's).
void ApplyBounds(const VerifyOptions& options, VerifyReport& r) {
  const double limit_abs = DistanceLimit(options, r.diagonal);
  const char* option = options.max_error_rel > 0 ? "max_error_rel" : "max_error";
  MeanDistanceBound(options, r);
  TruthBounds(options, r);
  if (r.measured_truth) Threshold(r, "truth", r.truth, limit_abs, option);
  if (r.measured_distances) {
    Threshold(r, "map->sculpt", r.map_to_sculpt, limit_abs, option);
    Threshold(r, "sculpt->map", r.sculpt_to_map, limit_abs, option);
  }
  verify::EdgeThresholds(r, options);
  if (r.measured_truth) RmsThreshold(r, "truth", r.truth, options.max_rms);
  if (r.measured_distances) {
    RmsThreshold(r, "map->sculpt", r.map_to_sculpt, options.max_rms);
    RmsThreshold(r, "sculpt->map", r.sculpt_to_map, options.max_rms);
    P99Threshold(r, "map->sculpt", r.map_to_sculpt, options.max_p99);
    P99Threshold(r, "sculpt->map", r.sculpt_to_map, options.max_p99);
  }
}

}  // namespace

StatusOr<VerifyReport> Verify(const VerifyOptions& options) {
  if (!options.displaced_path.empty()) return VerifyDisplacedMesh(options);
  Stopwatch clock;
  DISPEX_RETURN_IF_ERROR(CheckOptions(options));
  std::optional<tbb::global_control> limit;
  if (options.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism, std::size_t(options.threads));
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh base, ReadMesh(options.base_path));
  DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(base));
  VerifyReport r;
  r.ptex_faces = static_cast<std::size_t>(surface.num_ptex_faces());
  r.diagonal = ComputeBounds(base).diagonal();
  r.warnings = IgnoredTagWarnings(base);
  MapUnderTest m;
  m.reader.name = options.map_path;
  if (IsUvMapPath(options.map_path)) {
    DISPEX_RETURN_IF_ERROR(OpenUvMap(options, base, surface, m, r));
  } else {
    DISPEX_RETURN_IF_ERROR(OpenPtexMap(options, surface, m, r));
    DISPEX_RETURN_IF_ERROR(verify::MeasureEdgeSteps(options, base, surface, *m.ptex, m.reader.space,
                                                    m.faces, m.fields, r));
    ReadAcrossFaces(options, m);
  }
  if (!options.truth_path.empty()) DISPEX_RETURN_IF_ERROR(MeasureTruth(options, surface, m, r));
  if (!options.sculpt_path.empty()) {
    DISPEX_RETURN_IF_ERROR(MeasureDistances(options, surface, m, r));
  }
  UvFacesWithoutTile(m, options.map_path, r);
  ApplyBounds(options, r);
  r.seconds = clock.seconds();
  return r;
}

}  // namespace dispex
