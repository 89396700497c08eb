#include "extract/extract_inputs.h"

#include <fmt/format.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "core/check.h"
#include "core/system.h"
#include "dispex/cancel.h"
#include "extract/incremental/face_keys.h"
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

Status CheckMemoryForInputs(const ExtractOptions& options, const MeshesRead& meshes,
                            std::uint64_t memory_limit) {
  // Texels the output can hold at most: every face at the largest oversampling.
  const std::uint64_t max_texels = static_cast<std::uint64_t>(meshes.surface.num_ptex_faces()) *
                                   static_cast<std::uint64_t>(options.max_oversample) *
                                   static_cast<std::uint64_t>(options.max_oversample);
  const Mesh& sculpt = meshes.sculpt;
  return CheckMemoryForSculpt(sculpt.num_vertices(), sculpt.num_faces(), sculpt.face_indices.size(),
                              std::min<std::uint64_t>(max_texels, 1ull << 31), memory_limit);
}

StatusOr<ExtractInputs> FinishInputs(const ExtractOptions& options, MeshesRead meshes,
                                     std::uint64_t memory_limit, ExtractReport& report) {
  ReportMeshes(options, meshes, report);
  DISPEX_RETURN_IF_ERROR(CheckMemoryForInputs(options, meshes, memory_limit));
  std::vector<PtexFaceInfo> faces = PtexFaceTable(meshes.surface);
  return ExtractInputs{std::move(meshes.base),
                       std::move(meshes.sculpt),
                       std::move(meshes.surface),
                       std::move(faces),
                       nullptr,
                       {},
                       {},
                       false,
                       {},
                       nullptr,
                       false,
                       nullptr,
                       0};
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
  inputs.tracer_options.quality = options.bvh_quality;
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

Status EnsureTraced(ExtractInputs& inputs, std::span<const int> faces) {
  if (inputs.traced.empty()) return Status::Ok();
  DISPEX_CHECK(inputs.sculpt.num_faces() > 0);  // not after ReleaseSculpt
  std::vector<int> beyond;
  for (int f : faces) {
    if (!inputs.traced[static_cast<std::size_t>(f)]) beyond.push_back(f);
  }
  if (beyond.empty()) return Status::Ok();
  std::vector<std::uint8_t> traced = std::move(inputs.traced);
  for (int f : beyond) traced[static_cast<std::size_t>(f)] = 1;
  AddRings(inputs.faces, kLocalRings, std::move(beyond), traced);
  inputs.widened = true;
  inputs.tracer.reset();  // before the part it reads
  inputs.traced_part = Mesh{};
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

}  // namespace dispex::extract
