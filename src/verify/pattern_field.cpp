// See pattern_field.h.
#include "verify/pattern_field.h"

namespace dispex::verify {

StatusOr<PatternField> PatternField::Create(Pattern pattern, const std::string& image_path,
                                            const PatternFrame& frame, const Mesh& cage,
                                            const LimitSurface& surface) {
  PatternField field;
  field.pattern_ = pattern;
  field.frame_ = frame;
  if (pattern == Pattern::kImage) {
    DISPEX_ASSIGN_OR_RETURN(field.charts_, PtexUvCharts::Build(cage, surface));
    DISPEX_ASSIGN_OR_RETURN(field.image_, HeightImage::Read(image_path));
  }
  return field;
}

}  // namespace dispex::verify
