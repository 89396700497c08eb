// The extraction pipeline, top-down: read the meshes, build the limit surface and the BVH,
// resolve the automatic settings, then per Ptex face (in parallel): limit grid -> rays ->
// signed distances -> holes -> DCT resolution -> compressed Ptex block; finally faces that
// missed entirely are filled from their neighbours and the file is committed.
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <optional>

#include "core/cancel.h"
#include "core/content_hash.h"
#include "core/progress.h"
#include "core/system.h"
#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/version.h"
#include "extract/extract_meta.h"
#include "extract/hole_fill.h"
#include "extract/oversampling.h"
#include "extract/ptex_face_table.h"

namespace dispex {

namespace {

// The longer search for samples that missed: this many times the automatic search distance.
constexpr double kRetryFactor = 4.0;

// Per-face outcome, kept for the deterministic reductions after the parallel loop.
struct FaceResult {
  std::int32_t misses = 0;
  std::int32_t recovered = 0;  // misses found by the longer search
  std::int32_t filled = 0;
  std::int32_t hits_negative = 0;
  std::int32_t hits_opposed = 0;
  bool all_missed = false;
  float min = 0, max = 0;
  double sum_squares = 0;
  std::int64_t samples = 0;
  SpectralFaceStats spectral;
  std::int8_t ulog2 = 0, vlog2 = 0;
};

// Per-thread scratch, reused across faces.
struct Worker {
  explicit Worker(const LimitSurface& surface) : evaluator(surface) {}
  LimitEvaluator evaluator;
  SpectralAnalyzer analyzer;
  std::vector<float> positions, normals, t, values;
  std::vector<std::uint8_t> flags, valid;
  std::vector<Float3> retry_origins, retry_normals;  // missed samples, for the longer search
  std::vector<float> retry_t;
  std::vector<std::uint8_t> retry_flags;
  std::vector<std::int32_t> retry_index;
  PullPushScratch pull_push;
  TraceCounters counters;
  double cpu_limit = 0, cpu_trace = 0, cpu_spectral = 0, cpu_write = 0;
};

std::span<const Float3> AsFloat3(const std::vector<float>& v, std::size_t n) {
  return {reinterpret_cast<const Float3*>(v.data()), n};
}

// The first error of a parallel loop, by face id so that the message does not depend on
// scheduling.
class FirstError {
 public:
  void Record(int face, Status status) {
    std::lock_guard lock(mutex_);
    if (!face_ || face < *face_) {
      face_ = face;
      status_ = std::move(status);
    }
    failed_.store(true);
  }
  bool failed() const { return failed_.load(std::memory_order_relaxed); }
  Status status() const { return status_; }

 private:
  std::mutex mutex_;
  std::optional<int> face_;
  Status status_;
  std::atomic<bool> failed_{false};
};

Status Cancelled() {
  int sig = CancelSignal();
  return Status::Error(sig ? fmt::format("interrupted by signal {}", sig) : "interrupted");
}

// Limit-surface area of each Ptex face and a sparse set of limit points and normals for the
// automatic search distance, from a 4x4 grid per face.
struct CoarseSampling {
  std::vector<double> face_areas;
  std::vector<Float3> points, normals;
};

StatusOr<CoarseSampling> SampleCoarsely(const LimitSurface& surface) {
  const int n = surface.num_ptex_faces();
  constexpr int kGrid = 4;
  CoarseSampling out;
  out.face_areas.assign(static_cast<std::size_t>(n), 0.0);
  std::vector<float> pos(static_cast<std::size_t>(n) * kGrid * kGrid * 3, 0.0f);
  std::vector<float> nrm(pos.size(), 0.0f);
  std::vector<std::uint8_t> ok(static_cast<std::size_t>(n), 0);
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  FirstError error;
  tbb::parallel_for(0, n, [&](int f) {
    PtexFaceId face(f);
    if (surface.is_hole(face) || error.failed()) return;
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    std::span<float> p(pos.data() + static_cast<std::size_t>(f) * kGrid * kGrid * 3, kGrid * kGrid * 3);
    std::span<float> q(nrm.data() + static_cast<std::size_t>(f) * kGrid * kGrid * 3, kGrid * kGrid * 3);
    Status s = evaluator->EvaluateGrid(face, kGrid, kGrid, p, q);
    if (!s.ok()) return error.Record(f, s);
    // The 3x3 cells between sample centres cover (3/4)^2 of the face's parameter square.
    double area = 0;
    for (int j = 0; j + 1 < kGrid; ++j) {
      for (int i = 0; i + 1 < kGrid; ++i) {
        auto at = [&](int ii, int jj, int c) { return double(p[3 * (jj * kGrid + ii) + c]); };
        double ax = at(i + 1, j + 1, 0) - at(i, j, 0), ay = at(i + 1, j + 1, 1) - at(i, j, 1),
               az = at(i + 1, j + 1, 2) - at(i, j, 2);
        double bx = at(i, j + 1, 0) - at(i + 1, j, 0), by = at(i, j + 1, 1) - at(i + 1, j, 1),
               bz = at(i, j + 1, 2) - at(i + 1, j, 2);
        double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
        area += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
      }
    }
    out.face_areas[static_cast<std::size_t>(f)] = area / (0.75 * 0.75);
    ok[static_cast<std::size_t>(f)] = 1;
  });
  if (error.failed()) return error.status();
  // At most ~64K points for the search-distance estimate, spread over all faces.
  std::size_t total = static_cast<std::size_t>(n) * kGrid * kGrid;
  std::size_t stride = std::max<std::size_t>(1, total / 65536);
  for (std::size_t i = 0; i < total; i += stride) {
    if (!ok[i / (kGrid * kGrid)]) continue;
    out.points.push_back({pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]});
    out.normals.push_back({nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]});
  }
  return out;
}

StatusOr<ExtractReport> ExtractInArena(const ExtractOptions& options, int threads) {
  Stopwatch total_clock;
  ExtractReport report;
  report.version = DISPEX_VERSION_STRING;
  report.options = options;
  report.base_path = options.base_path;
  report.sculpt_path = options.sculpt_path;
  report.output_path = options.output_path;
  report.threads = threads;

  const std::uint64_t memory_limit =
      options.max_memory > 0 ? options.max_memory : AvailableMemoryBytes();
  DISPEX_RETURN_IF_ERROR(CheckMemoryBeforeReading(options, memory_limit));

  // 1. Inputs: the sculpt is read while the base's topology is built.
  ReadOptions read_options;
  read_options.threads = options.threads;
  std::optional<StatusOr<Mesh>> sculpt_read;
  StatusOr<std::string> sculpt_fingerprint = Status::Error("not computed");
  std::optional<StatusOr<Mesh>> base_read;
  std::optional<StatusOr<LimitSurface>> surface_built;
  {
    tbb::task_group group;
    group.run([&] {
      Stopwatch clock;
      sculpt_read.emplace(ReadMesh(options.sculpt_path, read_options));
      report.t_read_sculpt = clock.seconds();
      if (sculpt_read->ok()) sculpt_fingerprint = FileFingerprint(options.sculpt_path);
    });
    Stopwatch clock;
    base_read.emplace(ReadMesh(options.base_path, read_options));
    report.t_read_base = clock.seconds();
    if (base_read->ok()) {
      clock.Reset();
      surface_built.emplace(LimitSurface::Build(base_read->value()));
      report.t_topology = clock.seconds();
    }
    group.wait();
  }
  if (!base_read->ok()) return base_read->status();
  if (!surface_built->ok()) return surface_built->status();
  if (!sculpt_read->ok()) return sculpt_read->status();
  if (CancelRequested()) return Cancelled();
  const Mesh& base = base_read->value();
  const Mesh& sculpt = sculpt_read->value();
  const LimitSurface& surface = surface_built->value();
  DISPEX_ASSIGN_OR_RETURN(report.base_fingerprint, FileFingerprint(options.base_path));
  DISPEX_ASSIGN_OR_RETURN(report.sculpt_fingerprint, std::move(sculpt_fingerprint));
  const std::vector<PtexFaceInfo> ptex_faces = PtexFaceTable(surface);
  const int num_faces = surface.num_ptex_faces();
  LimitSurfaceStats surface_stats = surface.stats();
  report.base_vertices = base.num_vertices();
  report.base_faces = base.num_faces();
  report.ptex_faces = static_cast<std::size_t>(num_faces);
  report.hole_faces = static_cast<std::size_t>(surface_stats.hole_ptex_faces);
  report.inf_sharp_edges = surface_stats.inf_sharp_edges;
  report.sculpt_vertices = sculpt.num_vertices();
  report.sculpt_faces = sculpt.num_faces();
  for (std::string& w : IgnoredTagWarnings(base)) report.warnings.push_back(std::move(w));
  if (surface_stats.inf_sharp_edges > 0) {
    report.warnings.push_back(fmt::format(
        "{}: {} infinitely sharp edges: the limit normal has two values there, so the map "
        "opens a gap or an overlap along them", options.base_path, surface_stats.inf_sharp_edges));
  }
  BoundingBox base_box = ComputeBounds(base);
  report.base_diagonal = base_box.diagonal();

  // Texels the output can hold at most: every face at the largest oversampling.
  const std::uint64_t max_texels = static_cast<std::uint64_t>(num_faces) *
                                   static_cast<std::uint64_t>(options.max_oversample) *
                                   static_cast<std::uint64_t>(options.max_oversample);
  DISPEX_RETURN_IF_ERROR(CheckMemoryForSculpt(sculpt.num_vertices(), sculpt.num_faces(),
                                              sculpt.face_indices.size(),
                                              std::min<std::uint64_t>(max_texels, 1ull << 31),
                                              memory_limit));

  // 2. The sculpt's BVH.
  Stopwatch clock;
  TracerOptions tracer_options;
  tracer_options.quality = options.bvh_quality;
  tracer_options.isa = options.embree_isa;
  DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer, MakeEmbreeTracer(sculpt, tracer_options));
  report.t_bvh = clock.seconds();
  report.tracer = tracer->stats().backend;
  if (CancelRequested()) return Cancelled();

  // 3. Automatic settings: tolerance, search distance, oversampling.
  clock.Reset();
  report.sculpt_median_edge = MedianEdgeLength(sculpt);
  report.tolerance_auto = options.tolerance <= 0;
  report.tolerance = report.tolerance_auto
                         ? options.tolerance_fraction * report.sculpt_median_edge
                         : options.tolerance;
  if (!(report.tolerance > 0)) {
    return Status::Error(fmt::format("{}: cannot derive a tolerance (median edge length {}); "
                                     "set tolerance", options.sculpt_path,
                                     report.sculpt_median_edge));
  }
  DISPEX_ASSIGN_OR_RETURN(CoarseSampling coarse, SampleCoarsely(surface));
  report.search_distance_auto = options.search_distance.kind == SearchDistanceSpec::Kind::kAuto;
  if (report.search_distance_auto) {
    auto estimate = EstimateSearchDistance(*tracer, coarse.points, coarse.normals,
                                           report.base_diagonal);
    if (!estimate.ok()) {
      return Status::Error(fmt::format("{} and {} do not overlap: {}", options.base_path,
                                       options.sculpt_path, estimate.status().message()));
    }
    report.search_estimate = *estimate;
    report.search_distance = estimate->distance;
  } else {
    DISPEX_ASSIGN_OR_RETURN(report.search_distance,
                            ResolveSearchDistance(options.search_distance, report.base_diagonal));
  }
  OversamplingPlan plan = PlanOversampling(surface, sculpt, coarse.face_areas, options.oversample,
                                           options.min_oversample, options.max_oversample);
  report.oversample_subdivision_level = plan.subdivision_level;
  coarse = {};
  report.t_search = clock.seconds();

  // 4. The output file (a temporary until Finish).
  PtexWriterOptions writer_options;
  writer_options.data_type = options.data_type;
  writer_options.compression_level = options.compression_level;
  DISPEX_ASSIGN_OR_RETURN(PtexWriter writer,
                          PtexWriter::Create(options.output_path, writer_options, num_faces));

  SpectralOptions spectral;
  spectral.rule = options.resolution_rule;
  spectral.tolerance = report.tolerance;
  spectral.nonzero_threshold = options.nonzero_threshold;
  spectral.fixed_ulog2 = options.fixed_ulog2;
  spectral.fixed_vlog2 = options.fixed_vlog2;
  NormalQuery query;
  query.distance = static_cast<float>(report.search_distance);
  query.policy = options.ray_policy;
  NormalQuery retry_query = query;
  const double retry_distance =
      report.search_distance_auto
          ? std::max(report.search_distance,
                     std::min(kRetryFactor * report.search_distance, report.search_estimate.ray_length))
          : 0.0;
  retry_query.distance = static_cast<float>(retry_distance);
  report.retry_search_distance = retry_distance;

  // 5. Per face, in parallel.
  clock.Reset();
  std::vector<FaceResult> results(static_cast<std::size_t>(num_faces));
  std::vector<EdgeMeans> edge_means(static_cast<std::size_t>(num_faces));
  tbb::enumerable_thread_specific<Worker> workers([&] { return Worker(surface); });
  FirstError error;
  Progress progress("extract", static_cast<std::uint64_t>(num_faces), "faces", options.progress);

  auto face_info = [&](int f, int ulog2, int vlog2) {
    PtexFaceInfo info = ptex_faces[static_cast<std::size_t>(f)];
    info.ulog2 = static_cast<std::int8_t>(ulog2);
    info.vlog2 = static_cast<std::int8_t>(vlog2);
    return info;
  };
  auto process_face = [&](int f, Worker& w) -> Status {
    PtexFaceId face(f);
    FaceResult& r = results[static_cast<std::size_t>(f)];
    if (surface.is_hole(face)) {
      const float zero = 0.0f;
      return writer.SetConstantFace(face, face_info(f, 0, 0), {&zero, 1});
    }
    const int n = 1 << plan.log2[static_cast<std::size_t>(f)];
    const std::size_t count = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    w.positions.resize(3 * count);
    w.normals.resize(3 * count);
    w.t.resize(count);
    w.flags.resize(count);
    w.values.resize(count);
    w.valid.resize(count);

    ThreadCpuStopwatch step;
    DISPEX_RETURN_IF_ERROR(w.evaluator.EvaluateGrid(face, n, n, w.positions, w.normals));
    w.cpu_limit += step.seconds();
    step.Reset();
    tracer->TraceNormals(AsFloat3(w.positions, count), AsFloat3(w.normals, count), query,
                         NormalHits{w.t, {}, w.flags}, w.counters);
    // With an automatic search distance, samples that missed get a second, longer search:
    // the sparse estimate can miss thin or strongly curved parts where the sculpt is
    // farther from the limit surface than almost everywhere else.
    if (retry_distance > 0) {
      w.retry_origins.clear();
      w.retry_normals.clear();
      w.retry_index.clear();
      for (std::size_t i = 0; i < count; ++i) {
        if (w.flags[i] & HitFlags::kHit) continue;
        w.retry_index.push_back(static_cast<std::int32_t>(i));
        w.retry_origins.push_back(AsFloat3(w.positions, count)[i]);
        w.retry_normals.push_back(AsFloat3(w.normals, count)[i]);
      }
      if (!w.retry_index.empty()) {
        const std::size_t m = w.retry_index.size();
        w.retry_t.resize(m);
        w.retry_flags.resize(m);
        tracer->TraceNormals(w.retry_origins, w.retry_normals, retry_query,
                             NormalHits{w.retry_t, {}, w.retry_flags}, w.counters);
        for (std::size_t k = 0; k < m; ++k) {
          if (!(w.retry_flags[k] & HitFlags::kHit)) continue;
          const auto i = static_cast<std::size_t>(w.retry_index[k]);
          w.t[i] = w.retry_t[k];
          w.flags[i] = w.retry_flags[k];
          ++r.recovered;
        }
      }
    }
    w.cpu_trace += step.seconds();

    r.samples = static_cast<std::int64_t>(count);
    for (std::size_t i = 0; i < count; ++i) {
      const std::uint8_t fl = w.flags[i];
      const bool hit = fl & HitFlags::kHit;
      w.valid[i] = hit;
      w.values[i] = hit ? w.t[i] : 0.0f;
      r.misses += !hit;
      r.hits_negative += hit && (fl & HitFlags::kNegative);
      // The sculpt faces the limit normal's way where it is met from behind along +n or from
      // the front along -n; the other way round it faces against it: a fold or another sheet.
      const bool negative = fl & HitFlags::kNegative, back = fl & HitFlags::kBackFace;
      r.hits_opposed += hit && (negative == back);
    }
    if (r.misses > 0) {
      if (options.holes == HolePolicy::kFail) {
        return Status::Error(fmt::format(
            "Ptex face {}: {} of {} rays missed the sculpt within the search distance {:.6g} "
            "(holes = fail)", f, r.misses, count, report.search_distance));
      }
      if (r.misses == static_cast<std::int32_t>(count) && options.holes == HolePolicy::kFill) {
        r.all_missed = true;  // filled from the neighbours once every face is done
        return Status::Ok();
      }
      if (options.holes == HolePolicy::kFill) {
        r.filled = FillHolesPullPush(w.values.data(), w.valid.data(), n, n, w.pull_push);
      }
    }
    r.min = *std::min_element(w.values.begin(), w.values.end());
    r.max = *std::max_element(w.values.begin(), w.values.end());
    for (float v : w.values) r.sum_squares += double(v) * double(v);
    edge_means[static_cast<std::size_t>(f)] = ComputeEdgeMeans(w.values.data(), n, n);

    step.Reset();
    DISPEX_ASSIGN_OR_RETURN(SpectralFace analysed, w.analyzer.Analyze(w.values, n, n, spectral));
    w.cpu_spectral += step.seconds();
    r.spectral = analysed.stats;
    r.ulog2 = static_cast<std::int8_t>(analysed.ulog2);
    r.vlog2 = static_cast<std::int8_t>(analysed.vlog2);
    step.Reset();
    PtexFaceInfo info = face_info(f, analysed.ulog2, analysed.vlog2);
    Status written = analysed.constant
                         ? writer.SetConstantFace(face, info, {&analysed.constant_value, 1})
                         : writer.SetFace(face, info, analysed.texels);
    w.cpu_write += step.seconds();
    return written;
  };

  tbb::parallel_for(tbb::blocked_range<int>(0, num_faces, 1), [&](const tbb::blocked_range<int>& range) {
    Worker& w = workers.local();
    for (int f = range.begin(); f != range.end(); ++f) {
      if (error.failed()) return;
      if (CancelRequested()) return error.Record(-1, Cancelled());
      Status s = process_face(f, w);
      if (!s.ok()) return error.Record(f, s);
      progress.Advance();
    }
  });
  progress.Finish();
  if (error.failed()) return error.status();

  // 6. Faces whose rays all missed: from their neighbours' shared edges.
  std::vector<std::uint8_t> has_values(static_cast<std::size_t>(num_faces), 1);
  bool any_hit = false;
  for (int f = 0; f < num_faces; ++f) {
    const FaceResult& r = results[static_cast<std::size_t>(f)];
    has_values[f] = !r.all_missed && !surface.is_hole(PtexFaceId(f));
    any_hit |= r.samples > r.misses;
  }
  if (!any_hit) {
    return Status::Error(fmt::format(
        "no ray from {} hit {} within the search distance {:.6g}: the meshes do not overlap",
        options.base_path, options.sculpt_path, report.search_distance));
  }
  CrossFaceFill cross = FillEmptyFaces(has_values, edge_means, ptex_faces);
  for (std::size_t k = 0; k < cross.faces.size(); ++k) {
    int f = cross.faces[k];
    DISPEX_RETURN_IF_ERROR(writer.SetConstantFace(PtexFaceId(f), face_info(f, 0, 0),
                                                  {&cross.values[k], 1}));
    FaceResult& r = results[static_cast<std::size_t>(f)];
    r.min = r.max = cross.values[k];
    r.sum_squares = double(cross.values[k]) * cross.values[k] * double(r.samples);
  }
  for (int f = 0; f < num_faces; ++f) {
    if (has_values[f] || surface.is_hole(PtexFaceId(f))) continue;
    const float zero = 0.0f;
    DISPEX_RETURN_IF_ERROR(writer.SetConstantFace(PtexFaceId(f), face_info(f, 0, 0), {&zero, 1}));
  }
  report.faces_filled_from_neighbours = static_cast<std::int64_t>(cross.faces.size());
  report.faces_unreachable = static_cast<std::int64_t>(cross.unreachable);
  if (cross.unreachable > 0) {
    report.warnings.push_back(fmt::format(
        "{} Ptex faces missed the sculpt entirely and have no neighbour with values: written "
        "as 0", cross.unreachable));
  }
  report.t_sample_trace = clock.seconds();

  // 7. Totals, in face order so that they do not depend on scheduling.
  double sum_squares = 0;
  bool first = true;
  for (int f = 0; f < num_faces; ++f) {
    const FaceResult& r = results[static_cast<std::size_t>(f)];
    if (surface.is_hole(PtexFaceId(f))) continue;
    report.oversample_faces[plan.log2[static_cast<std::size_t>(f)]]++;
    report.samples += r.samples;
    report.misses += r.misses;
    report.misses_recovered += r.recovered;
    report.holes_filled += r.filled;
    report.faces_with_misses += r.misses > 0;
    report.hits_negative += r.hits_negative;
    report.hits_positive += r.samples - r.misses - r.hits_negative;
    report.hits_opposed += r.hits_opposed;
    if (r.all_missed) {
      SpectralFaceStats constant;
      constant.texels_before = r.samples;
      constant.texels_after = 1;
      constant.constant = true;
      report.spectral.Add(constant, 0, 0);
    } else {
      report.spectral.Add(r.spectral, r.ulog2, r.vlog2);
    }
    sum_squares += r.sum_squares;
    report.displacement_min = first ? r.min : std::min<double>(report.displacement_min, r.min);
    report.displacement_max = first ? r.max : std::max<double>(report.displacement_max, r.max);
    first = false;
  }
  report.displacement_rms = report.samples ? std::sqrt(sum_squares / double(report.samples)) : 0;
  report.miss_fraction = report.samples ? double(report.misses) / double(report.samples) : 0;
  if (report.miss_fraction > options.max_miss_fraction) {
    return Status::Error(fmt::format(
        "{:.1f}% of the samples ({} of {}) found no surface of {} within the search distance "
        "{:.6g}{}, more than the limit of {:.4g}%: the sculpt covers only part of {} or is not "
        "aligned with it; align the meshes, give a longer search distance, or raise the limit "
        "of missed samples",
        100 * report.miss_fraction, report.misses, report.samples, options.sculpt_path,
        report.search_distance,
        retry_distance > report.search_distance
            ? fmt::format(" (and {:.6g} on the second search)", retry_distance)
            : "",
        100 * options.max_miss_fraction, options.base_path));
  }
  for (const Worker& w : workers) {
    report.rays_cast += w.counters.rays_cast;
    report.cpu_limit += w.cpu_limit;
    report.cpu_trace += w.cpu_trace;
    report.cpu_spectral += w.cpu_spectral;
    report.cpu_compress += w.cpu_write;
    report.fallback_normals += w.evaluator.stats().fallback_normals;
  }
  DISPEX_RETURN_IF_ERROR(tracer->status());

  // 8. Meta data and the file.
  clock.Reset();
  DISPEX_RETURN_IF_ERROR(AddExtractMetaData(writer, base, report));
  if (CancelRequested()) return Cancelled();
  DISPEX_RETURN_IF_ERROR(writer.Finish());
  report.t_write = clock.seconds();
  std::error_code ec;
  report.bytes_written = std::filesystem::file_size(options.output_path, ec);
  report.peak_rss_bytes = PeakResidentBytes();
  report.t_total = total_clock.seconds();
  return report;
}

}  // namespace

StatusOr<ExtractReport> Extract(const ExtractOptions& options) {
  DISPEX_RETURN_IF_ERROR(ValidateExtractOptions(options));
  // --threads N runs every parallel loop (Embree's BVH build included) in an arena of N
  // threads, more than the machine's cores if asked: the map is the same at any count.
  std::optional<tbb::global_control> thread_limit;
  if (options.threads > 0) {
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                         static_cast<std::size_t>(options.threads));
  }
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.initialize();
  const int threads = std::min(
      arena.max_concurrency(),
      static_cast<int>(
          tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
  return arena.execute([&] { return ExtractInArena(options, threads); });
}

}  // namespace dispex
