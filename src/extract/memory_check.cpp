// The max_memory admission check: refuse work that will not fit before doing any of it.
#include "extract/memory_check.h"

#include <fmt/format.h>

#include <filesystem>

#include "dispex/extract.h"

namespace dispex::extract {

namespace {

// Measured on OBJ sculpts: the mesh arrays take about half the file's bytes; reading peaks
// at about 1.5 times the arrays.
constexpr double kArraysPerFileByte = 0.5;
constexpr double kReadPeakFactor = 1.5;
// Embree's BVH over quads at medium quality, per primitive (incl. its build scratch).
constexpr double kBvhBytesPerPrimitive = 80;

std::string Gib(std::uint64_t bytes) {
  const double b = double(bytes);
  if (b >= double(1u << 30)) return fmt::format("{:.2f} GiB", b / double(1u << 30));
  if (b >= double(1u << 20)) return fmt::format("{:.1f} MiB", b / double(1u << 20));
  return fmt::format("{:.1f} KiB", b / 1024.0);
}

Status TooBig(std::uint64_t need, std::uint64_t limit, const std::string& what) {
  return Status::Error(
      StatusCode::kOverBudget,
      fmt::format("{} needs an estimated {} but the limit is {} (max_memory); free memory, use a "
                  "machine with more, or raise max_memory if the estimate is too high",
                  what, Gib(need), Gib(limit)));
}

}  // namespace

Status CheckMemoryBeforeReading(const ExtractOptions& options, std::uint64_t limit) {
  if (limit == 0) return Status::Ok();
  std::error_code ec;
  std::uint64_t base = options.base_mesh ? 0 : std::filesystem::file_size(options.base_path, ec);
  if (ec) base = 0;
  std::uint64_t sculpt =
      options.sculpt_mesh ? 0 : std::filesystem::file_size(options.sculpt_path, ec);
  if (ec) sculpt = 0;
  auto need =
      static_cast<std::uint64_t>(double(base + sculpt) * kArraysPerFileByte * kReadPeakFactor);
  if (need > limit) return TooBig(need, limit, "reading " + options.sculpt_path);
  return Status::Ok();
}

Status CheckMemoryForSculpt(std::size_t sculpt_vertices, std::size_t sculpt_faces,
                            std::size_t sculpt_indices, std::uint64_t base_texels,
                            std::uint64_t limit) {
  if (limit == 0) return Status::Ok();
  const double arrays = 12.0 * double(sculpt_vertices) + 4.0 * double(sculpt_faces + 1) +
                        4.0 * double(sculpt_indices);
  const double primitives = double(sculpt_indices) / 4.0 + double(sculpt_faces);  // upper bound
  const double bvh = kBvhBytesPerPrimitive * primitives;
  const double output = 4.0 * double(base_texels);  // compressed blocks, at most raw floats
  auto need = static_cast<std::uint64_t>(arrays + bvh + output);
  if (need > limit) {
    return TooBig(need, limit,
                  fmt::format("a sculpt of {} faces (arrays, BVH and output)", sculpt_faces));
  }
  return Status::Ok();
}

}  // namespace dispex::extract
