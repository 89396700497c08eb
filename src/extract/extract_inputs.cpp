#include "extract/extract_inputs.h"

#include <fmt/format.h>
#include <malloc.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "core/check.h"
#include "core/system.h"
#include "dispex/cancel.h"
#include "extract/incremental/face_keys.h"
#include "extract/incremental/shard_plan.h"
#include "extract/memory_check.h"
#include "extract/parallel_errors.h"

namespace dispex {

std::string MeshFingerprint(const Mesh& mesh) {
  return "xxh3-128:" + extract::MeshContentKey(mesh).Hex();
}

}  // namespace dispex

namespace dispex::extract {

namespace {

struct MeshesRead {
  Mesh base;
  Mesh sculpt;
  LimitSurface surface;
};

// The file at `path`, or a copy of the mesh given in memory (ExtractOptions::base_mesh,
// sculpt_mesh) once it passes the readers' checks.
StatusOr<Mesh> ReadOrCopy(const std::string& path, const std::shared_ptr<const Mesh>& given,
                          const ReadOptions& read_options) {
  if (!given) return ReadMesh(path, read_options);
  Mesh mesh = *given;
  if (mesh.source.empty()) mesh.source = path;
  DISPEX_RETURN_IF_ERROR(CheckMeshArrays(mesh));
  mesh.positions.reserve(mesh.positions.size() + 1);  // Embree reads 16 bytes at the last vertex
  return mesh;
}

// The sculpt is read while the base's topology is built.
StatusOr<MeshesRead> ReadMeshes(const ExtractOptions& options, ExtractReport& report) {
  ReadOptions read_options;
  read_options.threads = options.threads;
  std::optional<StatusOr<Mesh>> sculpt_read;
  std::optional<StatusOr<Mesh>> base_read;
  std::optional<StatusOr<LimitSurface>> surface_built;
  {
    tbb::task_group group;
    group.run([&] {
      Stopwatch clock;
      sculpt_read.emplace(ReadOrCopy(options.sculpt_path, options.sculpt_mesh, read_options));
      report.times.read_sculpt = clock.seconds();
      if (sculpt_read->ok())
        report.inputs.sculpt_fingerprint = MeshFingerprint(sculpt_read->value());
    });
    Stopwatch clock;
    base_read.emplace(ReadOrCopy(options.base_path, options.base_mesh, read_options));
    report.times.read_base = clock.seconds();
    if (base_read->ok()) {
      clock.Reset();
      surface_built.emplace(LimitSurface::Build(base_read->value()));
      report.times.topology = clock.seconds();
    }
    group.wait();
  }
  if (!base_read->ok()) return base_read->status();
  if (!surface_built->ok()) return surface_built->status();
  if (!sculpt_read->ok()) return sculpt_read->status();
  if (CancelRequested()) return Cancelled();
  report.inputs.base_fingerprint = MeshFingerprint(base_read->value());
  return MeshesRead{std::move(*base_read).value(), std::move(*sculpt_read).value(),
                    std::move(*surface_built).value()};
}

void ReportMeshes(const ExtractOptions& options, const MeshesRead& meshes, ExtractReport& report) {
  const LimitSurfaceStats surface_stats = meshes.surface.stats();
  report.inputs.base_vertices = meshes.base.num_vertices();
  report.inputs.base_faces = meshes.base.num_faces();
  report.inputs.ptex_faces = static_cast<std::size_t>(meshes.surface.num_ptex_faces());
  report.inputs.hole_faces = static_cast<std::size_t>(surface_stats.hole_ptex_faces);
  report.inputs.inf_sharp_edges = surface_stats.inf_sharp_edges;
  report.inputs.sculpt_vertices = meshes.sculpt.num_vertices();
  report.inputs.sculpt_faces = meshes.sculpt.num_faces();
  for (std::string& w : IgnoredTagWarnings(meshes.base)) report.warnings.push_back(std::move(w));
  if (surface_stats.inf_sharp_edges > 0) {
    report.warnings.push_back(fmt::format(
        "{}: {} infinitely sharp edges: the limit normal has two values there, so the map "
        "opens a gap or an overlap along them",
        options.base_path, surface_stats.inf_sharp_edges));
  }
  report.inputs.base_diagonal = ComputeBounds(meshes.base).diagonal();
}

MemoryNeed MemoryNeedOf(const ExtractOptions& options, const MeshesRead& meshes) {
  // Texels the output can hold at most: every face at the largest oversampling.
  const std::uint64_t max_texels = static_cast<std::uint64_t>(meshes.surface.num_ptex_faces()) *
                                   static_cast<std::uint64_t>(options.max_oversample) *
                                   static_cast<std::uint64_t>(options.max_oversample);
  const Mesh& sculpt = meshes.sculpt;
  return EstimateMemory(sculpt.num_vertices(), sculpt.num_faces(), sculpt.face_indices.size(),
                        std::min(max_texels, kMaxEstimatedTexels), MatchesSculpt(options));
}

StatusOr<ExtractInputs> FinishInputs(const ExtractOptions& options, MeshesRead meshes,
                                     std::uint64_t memory_limit, ExtractReport& report) {
  ReportMeshes(options, meshes, report);
  const MemoryNeed need = MemoryNeedOf(options, meshes);
  DISPEX_RETURN_IF_ERROR(
      CheckMemoryForSculpt(need, meshes.sculpt.num_faces(), memory_limit, options.max_memory > 0));
  report.plan.memory_limit = memory_limit;
  report.plan.memory_estimate = need.arrays + need.match + need.output;
  std::vector<PtexFaceInfo> faces = PtexFaceTable(meshes.surface);
  return ExtractInputs{.base = std::move(meshes.base),
                       .sculpt = std::move(meshes.sculpt),
                       .surface = std::move(meshes.surface),
                       .faces = std::move(faces),
                       .memory_limit = memory_limit,
                       .memory = need};
}

}  // namespace

StatusOr<ExtractInputs> ReadInputs(const ExtractOptions& options, std::uint64_t memory_limit,
                                   ExtractReport& report) {
  DISPEX_RETURN_IF_ERROR(CheckMemoryBeforeReading(options, memory_limit));
  DISPEX_ASSIGN_OR_RETURN(MeshesRead meshes, ReadMeshes(options, report));
  return FinishInputs(options, std::move(meshes), memory_limit, report);
}

StatusOr<ExtractInputs> InputsFromMeshes(const ExtractOptions& options, Mesh base, Mesh sculpt,
                                         std::uint64_t memory_limit, ExtractReport& report) {
  report.inputs.base_fingerprint = MeshFingerprint(base);
  report.inputs.sculpt_fingerprint = MeshFingerprint(sculpt);
  Stopwatch clock;
  DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(base));
  report.times.topology = clock.seconds();
  return FinishInputs(options, MeshesRead{std::move(base), std::move(sculpt), std::move(surface)},
                      memory_limit, report);
}

float TracerScale(const Mesh& base) {
  const BoundingBox box = ComputeBounds(base);
  float largest = 0;
  for (float c : {box.min.x, box.min.y, box.min.z, box.max.x, box.max.y, box.max.z}) {
    largest = std::max(largest, std::fabs(c));
  }
  return largest > 0 ? std::exp2(std::ceil(std::log2(largest))) : 1.0f;
}

void SetTracerOptions(const ExtractOptions& options, ExtractInputs& inputs) {
  inputs.tracer_options.quality = inputs.compact_bvh ? BuildQuality::kMedium : options.bvh_quality;
  inputs.tracer_options.compact = inputs.compact_bvh;
  inputs.tracer_options.isa = options.embree_isa;
  inputs.tracer_options.scale = TracerScale(inputs.base);
}

Status BuildTracer(const ExtractOptions& options, ExtractInputs& inputs, ExtractReport& report) {
  Stopwatch clock;
  SetTracerOptions(options, inputs);
  inputs.traced.clear();
  DISPEX_ASSIGN_OR_RETURN(inputs.tracer, MakeEmbreeTracer(inputs.sculpt, inputs.tracer_options));
  report.times.bvh += clock.seconds();
  report.tracer = inputs.tracer->stats().backend;
  if (CancelRequested()) return Cancelled();
  return Status::Ok();
}

Status BuildPartTracer(Mesh part, std::vector<std::uint8_t> traced, ExtractInputs& inputs,
                       ExtractReport& report) {
  Stopwatch clock;
  inputs.tracer.reset();
  inputs.traced_part = std::move(part);
  inputs.traced = std::move(traced);
  if (inputs.traced_part.num_faces() == 0) {
    if (std::count(inputs.traced.begin(), inputs.traced.end(), 1) == 0) {
      report.tracer = "none until a face needs one";  // every face copied
      return Status::Ok();
    }
    // Faces with no sculpt within reach: their rays miss whatever the tracer holds.
    inputs.traced.clear();
    inputs.traced_part = Mesh{};
    DISPEX_ASSIGN_OR_RETURN(inputs.tracer, MakeEmbreeTracer(inputs.sculpt, inputs.tracer_options));
    report.times.bvh += clock.seconds();
    report.tracer = inputs.tracer->stats().backend;
    return Status::Ok();
  }
  DISPEX_ASSIGN_OR_RETURN(inputs.tracer,
                          MakeEmbreeTracer(inputs.traced_part, inputs.tracer_options));
  report.times.bvh += clock.seconds();
  report.tracer = inputs.tracer->stats().backend + fmt::format(", {} of {} sculpt faces",
                                                               inputs.traced_part.num_faces(),
                                                               report.inputs.sculpt_faces);
  return Status::Ok();
}

void ReleaseSculpt(ExtractInputs& inputs) {
  Mesh released;
  released.source = inputs.sculpt.source;
  inputs.sculpt = std::move(released);
}

void AddRings(const std::vector<PtexFaceInfo>& faces, int rings, std::vector<int> ring,
              std::vector<std::uint8_t>& traced) {
  for (int step = 0; step < rings && !ring.empty(); ++step) {
    std::vector<int> next;
    for (int f : ring) {
      for (std::int32_t g : faces[static_cast<std::size_t>(f)].adjfaces) {
        if (g >= 0 && !traced[static_cast<std::size_t>(g)]) {
          traced[static_cast<std::size_t>(g)] = 1;
          next.push_back(g);
        }
      }
    }
    ring = std::move(next);
  }
}

namespace {

// The tracer of the sculpt within the whole reach (the retry search's too) of the faces
// `traced` flags; the whole sculpt's when that is more than half the faces.
Status TraceWithinReach(ExtractInputs& inputs, std::vector<std::uint8_t> traced) {
  DISPEX_CHECK(inputs.sculpt.num_faces() > 0);  // not after ReleaseSculpt
  inputs.tracer.reset();                        // before the part it reads
  inputs.traced_part = Mesh{};
  inputs.traced.clear();
  inputs.first_search_only = false;
  const auto count = static_cast<std::size_t>(std::count(traced.begin(), traced.end(), 1));
  if (2 * count > traced.size() || inputs.face_keys == nullptr) {
    DISPEX_ASSIGN_OR_RETURN(inputs.tracer, MakeEmbreeTracer(inputs.sculpt, inputs.tracer_options));
    return Status::Ok();
  }
  inputs.traced_part = SculptWithinReach(inputs, *inputs.face_keys, traced);
  inputs.traced = std::move(traced);
  DISPEX_ASSIGN_OR_RETURN(
      inputs.tracer,
      MakeEmbreeTracer(inputs.traced_part.num_faces() > 0 ? inputs.traced_part : inputs.sculpt,
                       inputs.tracer_options));
  return Status::Ok();
}

}  // namespace

Status EnsureTraced(ExtractInputs& inputs, std::span<const int> faces) {
  if (inputs.traced.empty()) return Status::Ok();
  std::vector<int> beyond;
  for (int f : faces) {
    if (!inputs.traced[static_cast<std::size_t>(f)]) beyond.push_back(f);
  }
  if (beyond.empty()) return Status::Ok();
  std::vector<std::uint8_t> traced = inputs.traced;
  for (int f : beyond) traced[static_cast<std::size_t>(f)] = 1;
  AddRings(inputs.faces, kLocalRings, std::move(beyond), traced);
  inputs.widened = true;
  return TraceWithinReach(inputs, std::move(traced));
}

Status WidenToRetryReach(ExtractInputs& inputs) {
  if (!inputs.first_search_only) return Status::Ok();
  inputs.widened_for_retry = true;
  return TraceWithinReach(inputs, inputs.traced);
}

StatusOr<std::vector<std::vector<int>>> TracedRuns(const ExtractInputs& inputs,
                                                   std::span<const int> faces) {
  if (inputs.sculpt_parts <= 1 || faces.empty()) {
    return std::vector<std::vector<int>>{std::vector<int>(faces.begin(), faces.end())};
  }
  const std::vector<std::int32_t> order = ShardOrder(inputs.base, inputs.surface);
  std::vector<std::int32_t> rank(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    rank[static_cast<std::size_t>(order[i])] = static_cast<std::int32_t>(i);
  }
  std::vector<int> sorted(faces.begin(), faces.end());
  std::sort(sorted.begin(), sorted.end(), [&](int a, int b) {
    return rank[static_cast<std::size_t>(a)] < rank[static_cast<std::size_t>(b)];
  });
  ReachRuns cut =
      RunsWithinReach(inputs, *inputs.face_keys, sorted, kLocalRings, inputs.part_faces);
  // A face whose own reach passes what a part may hold: the limit cannot be kept (a search
  // distance long against the faces), and one BVH per face would not save it.
  if (cut.largest_single > static_cast<std::int64_t>(inputs.part_faces)) {
    return Status::Error(
        StatusCode::kOverBudget,
        fmt::format("{}: the sculpt within reach of Ptex face {} and the faces around it holds "
                    "{} sculpt faces, more than the {} a BVH may hold within the {} memory "
                    "limit; raise the limit (max_memory), or give a shorter search_distance",
                    inputs.sculpt.source, cut.largest_face, cut.largest_single, inputs.part_faces,
                    MemorySize(inputs.memory_limit)));
  }
  return std::move(cut.runs);
}

Status TraceRun(ExtractInputs& inputs, std::span<const int> run) {
  if (inputs.sculpt_parts <= 1) return EnsureTraced(inputs, run);
  inputs.tracer.reset();  // before the part it reads
  inputs.traced_part = Mesh{};
  inputs.traced.clear();
  // The freed BVH back to the system: the heap would keep it and the next run's on top of it.
  malloc_trim(0);
  if (run.empty()) return Status::Ok();
  Stopwatch clock;
  // With the rings around the run, every sculpt face beside one its rays can hit is in the
  // part too, so that the tie rule and the vertex guard (dispex/trace.h) find the faces around
  // a hit that the whole sculpt has there.
  std::vector<std::uint8_t> traced(inputs.faces.size(), 0);
  for (int f : run) traced[static_cast<std::size_t>(f)] = 1;
  AddRings(inputs.faces, kLocalRings, std::vector<int>(run.begin(), run.end()), traced);
  Mesh part = SculptWithinReach(inputs, *inputs.face_keys, traced);
  if (part.num_faces() == 0) {
    // No sculpt within reach: the run's rays miss whatever the BVH holds, so one face of it.
    std::vector<std::uint8_t> keep(inputs.sculpt.num_faces(), 0);
    keep[0] = 1;
    part = SculptPart(inputs.sculpt, keep);
  }
  inputs.traced_part = std::move(part);
  inputs.traced = std::move(traced);
  DISPEX_ASSIGN_OR_RETURN(inputs.tracer,
                          MakeEmbreeTracer(inputs.traced_part, inputs.tracer_options));
  inputs.run_bvh_seconds += clock.seconds();
  inputs.run_backend = inputs.tracer->stats().backend;
  return CancelRequested() ? Cancelled() : Status::Ok();
}

StatusOr<std::vector<float>> NearestHitsInParts(const ExtractInputs& inputs, int sculpt_parts,
                                                std::span<const Float3> origins,
                                                std::span<const Float3> normals, float length,
                                                std::span<std::int8_t> side) {
  // Each query's nearest hit over the whole sculpt is the nearest of its parts' when each part
  // is a run of the sculpt's faces (a long ray may reach anywhere) with every face that shares
  // a vertex with them: around a hit on a face of the run the part holds what the whole sculpt
  // does, so the tie rule and the vertex guard (dispex/trace.h) answer as they would there; a
  // hit on one of the faces around is answered as well by the part whose run holds it.
  const Mesh& sculpt = inputs.sculpt;
  const auto parts = static_cast<std::size_t>(std::max(1, sculpt_parts));
  std::vector<float> nearest(origins.size(), std::numeric_limits<float>::infinity());
  if (parts == 1) {  // the whole sculpt, not a copy of it
    DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer,
                            MakeEmbreeTracer(sculpt, inputs.tracer_options));
    LowerNearestHits(*tracer, origins, normals, length, nearest, side);
    DISPEX_RETURN_IF_ERROR(tracer->status());
    return nearest;
  }
  std::vector<std::uint8_t> near_run(sculpt.num_vertices());
  for (std::size_t p = 0; p < parts; ++p) {
    const std::size_t begin = sculpt.num_faces() * p / parts;
    const std::size_t end = sculpt.num_faces() * (p + 1) / parts;
    if (begin == end) continue;
    std::fill(near_run.begin(), near_run.end(), 0);
    for (std::size_t s = begin; s < end; ++s) {
      for (std::int32_t v : sculpt.face(s)) near_run[static_cast<std::size_t>(v)] = 1;
    }
    std::vector<std::uint8_t> keep(sculpt.num_faces(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sculpt.num_faces(), 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t s = range.begin(); s != range.end(); ++s) {
                          for (std::int32_t v : sculpt.face(s)) {
                            if (near_run[static_cast<std::size_t>(v)]) keep[s] = 1;
                          }
                        }
                      });
    const Mesh part = SculptPart(sculpt, keep);
    keep = {};
    DISPEX_ASSIGN_OR_RETURN(std::unique_ptr<Tracer> tracer,
                            MakeEmbreeTracer(part, inputs.tracer_options));
    LowerNearestHits(*tracer, origins, normals, length, nearest, side);
    DISPEX_RETURN_IF_ERROR(tracer->status());
    if (CancelRequested()) return Cancelled();
  }
  return nearest;
}

}  // namespace dispex::extract
