#include "extract/missed_faces.h"

#include <fmt/format.h>

#include "extract/hole_fill.h"

namespace dispex::extract {

Status FillMissedFaces(const ExtractOptions& options, const ExtractInputs& inputs,
                       ProcessedFaces& faces, PtexWriter& writer, ExtractReport& report) {
  const int num_faces = inputs.surface.num_ptex_faces();
  std::vector<std::uint8_t> has_values(static_cast<std::size_t>(num_faces), 1);
  bool any_hit = false;
  for (int f = 0; f < num_faces; ++f) {
    const FaceStats& r = faces.stats[static_cast<std::size_t>(f)];
    has_values[f] = !r.all_missed && !inputs.surface.is_hole(PtexFaceId(f));
    any_hit |= r.samples > r.misses;
  }
  if (!any_hit) {
    return Status::Error(
        StatusCode::kMismatch,
        fmt::format(
            "no ray from {} hit {} within the search distance {:.6g}: the meshes do not overlap",
            options.base_path, options.sculpt_path, report.settings.search_distance));
  }
  CrossFaceFill cross = FillEmptyFaces(has_values, faces.edge_means, inputs.faces);
  std::int64_t filled = 0;
  for (std::size_t k = 0; k < cross.faces.size(); ++k) {
    const int f = cross.faces[k];
    if (inputs.surface.is_hole(PtexFaceId(f))) continue;  // written as 0 with the first pass
    ++filled;
    DISPEX_RETURN_IF_ERROR(WriteConstantFace(writer, inputs, PtexFaceId(f), cross.values[k]));
    FaceStats& r = faces.stats[static_cast<std::size_t>(f)];
    r.min = r.max = cross.values[k];
    r.sum_squares = double(cross.values[k]) * cross.values[k] * double(r.samples);
  }
  for (int f = 0; f < num_faces; ++f) {
    if (has_values[f] || inputs.surface.is_hole(PtexFaceId(f))) continue;
    DISPEX_RETURN_IF_ERROR(WriteConstantFace(writer, inputs, PtexFaceId(f), 0.0f));
  }
  report.sampling.faces_filled_from_neighbours = filled;
  report.sampling.faces_unreachable = static_cast<std::int64_t>(cross.unreachable);
  if (cross.unreachable > 0) {
    report.warnings.push_back(fmt::format(
        "{} Ptex faces missed the sculpt entirely and have no neighbour with values: written "
        "as 0",
        cross.unreachable));
  }
  return Status::Ok();
}

}  // namespace dispex::extract
