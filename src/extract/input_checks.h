// Inputs that do not belong together (ExtractOptions::check_inputs): base and sculpt swapped,
// and a sculpt that is not where its base is.
//
// Swapped: the sculpt has fewer faces than its base.
//
// Placement: whether the sculpt sits where its base is. A sculpt exported with another unit, axis
// or pivot, or moved by mistake, is a few percent off its base as a whole: its displacement is
// large and one similarity transform (a move, a turn, a scale about the base's centre)
// explains most of it, where a sculpt's own detail is local and no one transform explains it.
// Measured on probe points of a subset of the Ptex faces (at most kPlacementProbeFaces): the
// sculpt's vertices over their limit points through the correspondence, or the rays' hits
// along the limit normal.
#pragma once

#include <span>
#include <string>

#include "core/vec3.h"
#include "dispex/status.h"
#include "extract/extract_inputs.h"
#include "extract/extract_settings.h"

namespace dispex::extract {

inline constexpr int kPlacementProbeFaces = 4096;

// d ~ t + w x r + s r over the points, r = p - centre (w and s small: a turn of |w| radians,
// a scale of 1 + s), by least squares.
struct PlacementFit {
  Vec3d translation, rotation;
  double scale = 0;      // s
  double explained = 0;  // the fraction of the displacement's sum of squares the fit accounts for
  double largest_move = 0;  // the transform's largest displacement over the points
  std::size_t points = 0;
};

// Each d a whole displacement vector at p.
PlacementFit FitPlacement(std::span<const Vec3d> p, std::span<const Vec3d> d, const Vec3d& centre);
// Each h the displacement's part along the unit normal n at p.
PlacementFit FitPlacementAlongNormals(std::span<const Vec3d> p, std::span<const Vec3d> n,
                                      std::span<const double> h, const Vec3d& centre);

// The fit of the run's inputs: through `grids` where the sculpt is the base refined (may be
// null), else along the normals with the tracer and the settings' query.
StatusOr<PlacementFit> MeasurePlacement(const ExtractInputs& inputs, const GridSource* grids,
                                        const ExtractSettings* settings);

// Fails, naming both files and their face counts, when the sculpt has fewer faces than the
// base.
Status CheckFaceCounts(const Mesh& base, const Mesh& sculpt);

// Fails, naming the sculpt and the transform, when the fit explains at least 90% of the
// displacement and moves some point by 1.5% of `diagonal` or more, or 75% and 3%. A sculpt's own
// low-frequency detail on a small cage is explained up to 88% (a cube refined twice, `detail`:
// a move of 0.7% of the diagonal, a scale by 0.98 and a turn of 2.6 degrees). Measured on Spot
// (level 3, `detail`; through rays on the jittered layout): the sculpt as made 27%, 0.4% (63%,
// 0.9%); moved by 2% of the diagonal 95%, 2.1% (89%, 2.4%), by 3.6% 98% (83%, 4.2%); scaled by 1.05
// 90%, 2.1% (89%, 2.4%); turned by 5 degrees 93%, 2.9% (79%, 2.8%); the bunny scan against its cage
// 16%, 0.3%.
Status CheckPlacement(const PlacementFit& fit, double diagonal, const std::string& sculpt);

}  // namespace dispex::extract
