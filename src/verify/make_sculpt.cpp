// Ground-truth sculpts: the cage refined uniformly with OpenSubdiv, every vertex on the limit
// surface and moved along the limit normal by a known pattern h (pattern_field.h), which is
// evaluated at each vertex's (Ptex face, u, v) and limit position.
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <optional>

#include <tbb/enumerable_thread_specific.h>

#include "core/atomic_output.h"
#include "core/system.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/verify.h"
#include "verify/obj_writer.h"
#include "verify/pattern_field.h"

namespace dispex {

namespace {

struct SculptQuality {
  double linear_error = 0;
  std::size_t folded_faces = 0;
};

// See MakeSculptReport::linear_error and folded_faces. `refined.mesh` already holds the
// displaced positions.
StatusOr<SculptQuality> MeasureSculpt(const LimitSurface& surface, const RefinedMesh& refined,
                                      const PatternField& pattern) {
  const Mesh& mesh = refined.mesh;
  const std::size_t faces = mesh.num_faces();
  std::vector<float> errors(faces, 0.0f);
  std::vector<std::uint8_t> folded(faces, 0);
  tbb::enumerable_thread_specific<std::optional<LimitEvaluator>> evaluators;
  std::atomic<bool> failed{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, faces, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
    auto& evaluator = evaluators.local();
    if (!evaluator) evaluator.emplace(surface);
    for (std::size_t f = range.begin(); f < range.end(); ++f) {
      auto face = mesh.face(f);
      if (face.size() != 4) continue;
      const float* c = &refined.face_uvs[8 * f];
      float uv[2] = {0.25f * (c[0] + c[2] + c[4] + c[6]), 0.25f * (c[1] + c[3] + c[5] + c[7])};
      float p[3], n[3];
      if (!evaluator->EvaluatePoints(refined.face_ptex[f], uv, p, n).ok()) {
        failed = true;
        return;
      }
      double h = pattern(refined.face_ptex[f], uv[0], uv[1], p);
      double truth[3] = {p[0] + h * n[0], p[1] + h * n[1], p[2] + h * n[2]};
      auto at = [&](int k) { return mesh.positions[static_cast<std::size_t>(face[k])]; };
      double worst = 0;
      for (int d = 0; d < 2; ++d) {
        Float3 a = at(d), b = at(d + 2);
        double mx = 0.5 * (double(a.x) + b.x) - truth[0], my = 0.5 * (double(a.y) + b.y) - truth[1],
               mz = 0.5 * (double(a.z) + b.z) - truth[2];
        worst = std::max(worst, std::sqrt(mx * mx + my * my + mz * mz));
      }
      errors[f] = static_cast<float>(worst);
      Float3 a = at(0), b = at(1), c2 = at(2), d = at(3);
      double e1[3] = {double(c2.x) - a.x, double(c2.y) - a.y, double(c2.z) - a.z};
      double e2[3] = {double(d.x) - b.x, double(d.y) - b.y, double(d.z) - b.z};
      double fn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                      e1[0] * e2[1] - e1[1] * e2[0]};
      folded[f] = fn[0] * n[0] + fn[1] * n[1] + fn[2] * n[2] < 0;
    }
  });
  if (failed) return Status::Error("evaluating the limit surface at a sculpt face centre failed");
  SculptQuality quality;
  if (faces) quality.linear_error = *std::max_element(errors.begin(), errors.end());
  for (std::uint8_t f : folded) quality.folded_faces += f;
  return quality;
}

}  // namespace

StatusOr<MakeSculptReport> MakeSculpt(const MakeSculptOptions& options) {
  Stopwatch clock;
  if (options.levels < 1 || options.levels > 8) {
    return Status::Error(fmt::format("--levels {}: must be 1..8", options.levels));
  }
  if (!(std::isfinite(options.amplitude) && options.amplitude >= 0)) {
    return Status::Error(fmt::format("--amplitude {}: must be >= 0", options.amplitude));
  }
  if (options.output_path.empty()) return Status::Error("no output file given (-o SCULPT.obj)");
  if (options.output_path == options.cage_path) {
    return Status::Error("the output must differ from the cage");
  }
  if (options.pattern == Pattern::kImage && options.image_path.empty()) {
    return Status::Error("the image pattern needs a height image (image:FILE.png)");
  }
  std::optional<tbb::global_control> limit;
  if (options.threads > 0) {
    limit.emplace(tbb::global_control::max_allowed_parallelism,
                  static_cast<std::size_t>(options.threads));
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh cage, ReadMesh(options.cage_path));
  DISPEX_ASSIGN_OR_RETURN(LimitSurface surface, LimitSurface::Build(cage));

  BoundingBox box = ComputeBounds(cage);
  PatternFrame frame;
  frame.center[0] = 0.5f * (box.min.x + box.max.x);
  frame.center[1] = 0.5f * (box.min.y + box.max.y);
  frame.center[2] = 0.5f * (box.min.z + box.max.z);
  frame.diagonal = box.diagonal();
  frame.edge = MedianEdgeLength(cage) / double(1 << options.levels);
  frame.amplitude = options.amplitude > 0 ? options.amplitude : 0.01 * frame.diagonal;
  frame.seed = options.seed;
  // Before the refinement, so that a bad image or a cage without UVs fails at once.
  DISPEX_ASSIGN_OR_RETURN(
      PatternField pattern,
      PatternField::Create(options.pattern, options.image_path, frame, cage, surface));

  RefineOptions refine_options;
  refine_options.face_charts = true;
  DISPEX_ASSIGN_OR_RETURN(RefinedMesh refined,
                          RefineUniform(surface, options.levels, refine_options));

  Mesh& sculpt = refined.mesh;
  const std::size_t n = sculpt.num_vertices();
  GroundTruth truth;
  truth.faces = std::move(refined.ptex_faces);
  truth.uvs = std::move(refined.uvs);
  truth.h.resize(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t v = range.begin(); v < range.end(); ++v) {
                        Float3& p = sculpt.positions[v];
                        const float xyz[3] = {p.x, p.y, p.z};
                        double h = pattern(truth.faces[v], truth.uvs[2 * v],
                                           truth.uvs[2 * v + 1], xyz);
                        truth.h[v] = static_cast<float>(h);
                        p.x = static_cast<float>(p.x + h * refined.normals[3 * v]);
                        p.y = static_cast<float>(p.y + h * refined.normals[3 * v + 1]);
                        p.z = static_cast<float>(p.z + h * refined.normals[3 * v + 2]);
                      }
                    });
  DISPEX_ASSIGN_OR_RETURN(SculptQuality quality, MeasureSculpt(surface, refined, pattern));
  const std::string pattern_name =
      options.pattern == Pattern::kImage ? "image:" + options.image_path
                                         : std::string(PatternName(options.pattern));
  std::string header = fmt::format(
      "# dispex make-sculpt: {} refined {} times, pattern {}, amplitude {}, seed {}\n",
      options.cage_path, options.levels, pattern_name, frame.amplitude, options.seed);
  DISPEX_RETURN_IF_ERROR(WriteObj(options.output_path, sculpt, header));
  std::string truth_path =
      options.truth_path.empty() ? options.output_path + ".truth" : options.truth_path;
  DISPEX_RETURN_IF_ERROR(WriteGroundTruth(truth_path, truth));

  MakeSculptReport report;
  report.vertices = n;
  report.faces = sculpt.num_faces();
  report.amplitude = frame.amplitude;
  report.diagonal = frame.diagonal;
  report.edge = frame.edge;
  if (n) {
    auto [lo, hi] = std::minmax_element(truth.h.begin(), truth.h.end());
    report.h_min = *lo;
    report.h_max = *hi;
  }
  report.linear_error = quality.linear_error;
  report.folded_faces = quality.folded_faces;
  report.warnings = IgnoredTagWarnings(cage);
  report.seconds = clock.seconds();
  return report;
}

}  // namespace dispex
