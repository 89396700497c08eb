// The max_memory admission check: refuse work that will not fit before doing any of it.
#include "extract/memory_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "dispex/extract.h"
#include "dispex/mesh.h"

namespace dispex::extract {

namespace {

// Measured on OBJ sculpts: the mesh arrays take about half the file's bytes; reading peaks
// at about 1.5 times the arrays.
constexpr double kArraysPerFileByte = 0.5;
constexpr double kReadPeakFactor = 1.5;
// Embree's BVH over quads at medium quality, per primitive (incl. its build scratch).
constexpr double kBvhBytesPerPrimitive = 80;
// The same built compact (RTC_SCENE_FLAG_COMPACT, medium quality). Measured through rays with
// the whole sculpt's BVH (bench/film-scale's sculpts, peak less the sculpt's arrays): 74 bytes
// a quad on the body (16.9M quads), 72 on 135.3M quads, against 143 at low quality without
// compact; per primitive as counted here (2 a quad), 37 and 36 against 72.
constexpr double kCompactBvhBytesPerPrimitive = 40;
// MatchRefinedSculpt's peak per sculpt face, its half-edge adjacency (dispex/correspondence.h).
constexpr std::uint64_t kMatchBytesPerFace = 40;
// The parts a sculpt is planned in against how many faces one holds: the search distance's
// margin around each, and uneven runs.
constexpr double kPartShareFactor = 2;

// `given`: the limit is max_memory's, else what the machine has available.
Status TooBig(std::uint64_t need, std::uint64_t limit, bool given, const std::string& what) {
  if (given) {
    return Status::Error(
        StatusCode::kOverBudget,
        fmt::format("{} needs an estimated {} but the limit is {} (max_memory); free memory, use "
                    "a machine with more, or raise max_memory if the estimate is too high",
                    what, MemorySize(need), MemorySize(limit)));
  }
  return Status::Error(
      StatusCode::kOverBudget,
      fmt::format("{} needs an estimated {} but only {} is available (free memory, within the "
                  "process's cgroup and address-space limits); free memory or use a machine with "
                  "more (max_memory sets the limit instead)",
                  what, MemorySize(need), MemorySize(limit)));
}

}  // namespace

std::uint64_t ReadPeakBytes(const ExtractOptions& options) {
  std::error_code ec;
  std::uint64_t base = options.base_mesh ? 0 : std::filesystem::file_size(options.base_path, ec);
  if (ec) base = 0;
  std::uint64_t sculpt =
      options.sculpt_mesh ? 0 : std::filesystem::file_size(options.sculpt_path, ec);
  if (ec) sculpt = 0;
  return static_cast<std::uint64_t>(double(base + sculpt) * kArraysPerFileByte * kReadPeakFactor);
}

Status CheckMemoryBeforeReading(const ExtractOptions& options, std::uint64_t limit) {
  if (limit == 0) return Status::Ok();
  const std::uint64_t need = ReadPeakBytes(options);
  if (need > limit) {
    return TooBig(need, limit, options.max_memory > 0, "reading " + options.sculpt_path);
  }
  // A PLY sculpt's header gives its counts: what every plan needs of them at least (arrays of
  // 3 corners a face, the correspondence), before seconds of reading. Only a regular file is
  // opened here (a FIFO would block); the reader says what is wrong with anything else.
  std::error_code ec;
  if (options.sculpt_mesh || !std::filesystem::is_regular_file(options.sculpt_path, ec) ||
      DetectMeshFormat(options.sculpt_path) != MeshFormat::kPly) {
    return Status::Ok();
  }
  const StatusOr<MeshSize> size = CountMeshElements(options.sculpt_path);
  if (!size.ok()) return Status::Ok();  // the reader says what is wrong
  const MemoryNeed least =
      EstimateMemory(size->vertices, size->faces, 3 * size->faces, 0, MatchesSculpt(options));
  if (least.arrays + least.match > limit) {
    return TooBig(
        least.arrays + least.match, limit, options.max_memory > 0,
        fmt::format("{}: a sculpt of {} faces ({}arrays, from its header)", options.sculpt_path,
                    size->faces, least.match > 0 ? "its correspondence, " : ""));
  }
  return Status::Ok();
}

bool MatchesSculpt(const ExtractOptions& options) {
  return options.vector.has_value() || options.method != ExtractMethod::kRays;
}

MemoryNeed EstimateMemory(std::size_t sculpt_vertices, std::size_t sculpt_faces,
                          std::size_t sculpt_indices, std::uint64_t max_texels, bool matches) {
  MemoryNeed need;
  need.arrays = 12 * std::uint64_t{sculpt_vertices} + 4 * std::uint64_t{sculpt_faces + 1} +
                4 * std::uint64_t{sculpt_indices};
  need.vertex_map = 5 * std::uint64_t{sculpt_vertices} + std::uint64_t{sculpt_faces};
  // MatchRefinedSculpt's peak (dispex/correspondence.h), then the mapping it leaves.
  if (matches) need.match = kMatchBytesPerFace * std::uint64_t{sculpt_faces};
  const double primitives = double(sculpt_indices) / 4.0 + double(sculpt_faces);  // upper bound
  need.bvh = static_cast<std::uint64_t>(kBvhBytesPerPrimitive * primitives);
  need.compact_bvh = static_cast<std::uint64_t>(kCompactBvhBytesPerPrimitive * primitives);
  // The map's texels as floats (kept for the edges, then compressed): the oversampling reads
  // a sculpt's detail at about 4 samples per sculpt face, up to every face at the largest.
  need.output = 4 * std::min<std::uint64_t>(max_texels, 4 * std::uint64_t{sculpt_faces});
  return need;
}

Status CheckMemoryForSculpt(const MemoryNeed& need, std::size_t sculpt_faces, std::uint64_t limit,
                            bool given) {
  const std::uint64_t floor = need.arrays + need.match + need.output;
  if (limit == 0 || floor <= limit) return Status::Ok();
  return TooBig(floor, limit, given,
                fmt::format("a sculpt of {} faces ({}arrays and output)", sculpt_faces,
                            need.match > 0 ? "its correspondence, " : ""));
}

StatusOr<SculptParts> SculptPartsWithin(const MemoryNeed& need, std::size_t sculpt_faces,
                                        std::uint64_t limit, bool given, std::uint64_t* estimate) {
  const std::uint64_t whole = need.arrays + need.bvh + need.output;
  *estimate = whole;
  if (limit == 0 || whole <= limit || sculpt_faces == 0) return SculptParts{1, sculpt_faces};
  const std::uint64_t compact = need.arrays + need.compact_bvh + need.output;
  if (compact <= limit) {
    *estimate = compact;
    return SculptParts{1, sculpt_faces, true};
  }
  // A part: sculpt faces with their arrays and BVH, besides the whole sculpt's arrays.
  const std::uint64_t floor = need.arrays + need.vertex_map + need.output;
  const double per_face = double(need.arrays + need.bvh) / double(sculpt_faces);
  SculptParts parts;
  if (limit > floor) {
    parts.part_faces = static_cast<std::size_t>(double(limit - floor) / per_face);
    parts.parts = static_cast<int>(std::ceil(kPartShareFactor * double(sculpt_faces) /
                                             double(std::max<std::size_t>(1, parts.part_faces))));
  }
  if (limit > floor && parts.parts <= kMaxSculptParts) {
    *estimate = floor + static_cast<std::uint64_t>(per_face * double(parts.part_faces));
    return parts;
  }
  *estimate = floor + static_cast<std::uint64_t>(kPartShareFactor * per_face *
                                                 double(sculpt_faces) / kMaxSculptParts);
  return TooBig(*estimate, limit, given,
                fmt::format("tracing a sculpt of {} faces in {} parts (arrays, a part's BVH and "
                            "output)",
                            sculpt_faces, kMaxSculptParts));
}

}  // namespace dispex::extract

namespace dispex {

std::string MemorySize(std::uint64_t bytes) {
  const double b = double(bytes);
  if (b >= double(1u << 30)) return fmt::format("{:.2f} GiB", b / double(1u << 30));
  if (b >= double(1u << 20)) return fmt::format("{:.1f} MiB", b / double(1u << 20));
  return fmt::format("{:.1f} KiB", b / 1024.0);
}

}  // namespace dispex
