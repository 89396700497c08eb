// Per-thread evaluation of one Ptex face of the limit surface at a time: Bfr for every face,
// with the Bezier fast path (bezier_patch.h) for regular ones.
#pragma once

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "dispex/subdiv.h"
#include "subdiv/bezier_patch.h"
#include "subdiv/surface_impl.h"

namespace dispex::subdiv {

// Holds its own Bfr factory (with its own cache of irregular patches), the Surface of the
// last base face, its patch points, and the basis tables of the last grid size: all reused
// across faces, so nothing is allocated per sample. One per thread.
class FaceSampler {
 public:
  explicit FaceSampler(const LimitSurface::Impl& surface);

  enum class BindResult { kOk, kNoSurface, kFailed };
  // Prepares Ptex face `ptex` (a valid id). kNoSurface for holes; kFailed when OpenSubdiv
  // could not build the surface (its messages are in error()).
  BindResult Bind(int ptex);
  const std::string& error() const { return error_; }

  // The rx x ry texel centres of the bound face, texel (i,j) at j*rx+i, xyz interleaved.
  // `normals` may be null; `du` and `dv` (dP/du and dP/dv in the Ptex face's own (u,v)) may
  // be null, and need `normals`.
  void Grid(int rx, int ry, float* positions, float* normals, float* du = nullptr,
            float* dv = nullptr);

  // One point of the bound face at Ptex (u,v). `normal`, `du` and `dv` may be null.
  void Point(double u, double v, float position[3], float normal[3], float du[3] = nullptr,
             float dv[3] = nullptr);

  const LimitEvaluatorStats& stats() const { return stats_; }

 private:
  // Position and derivatives of the bound face at Ptex (u,v); derivatives are with respect
  // to the Ptex face's own (u,v) up to a positive scale (deriv_scale_ undoes it).
  void EvalDerivs(double u, double v, double p[3], double du[3], double dv[3]);
  void GridRegular(int rx, int ry, float* positions, float* normals, float* du, float* dv);
  void GridBfr(int rx, int ry, float* positions, float* normals, float* du, float* dv);
  // du and dv times deriv_scale_ into du_out and dv_out (nothing when du_out is null).
  void StoreDerivs(const double du[3], const double dv[3], float* du_out, float* dv_out) const;
  // Writes the normal for a sample whose derivatives were degenerate (see subdiv.h).
  void FallbackNormal(double u, double v, float normal[3]);

  using Factory = OpenSubdiv::Bfr::RefinerSurfaceFactory<>;

  const LimitSurface::Impl& s_;
  Factory factory_;
  OpenSubdiv::Bfr::Surface<double> surface_;
  OpenSubdiv::Bfr::Parameterization param_;
  int surface_base_face_ = -1;  // base face whose Surface is initialised (-1: none)
  std::vector<double> patch_points_;
  bool has_sub_faces_ = false;
  bool regular_ = false;    // the bound face uses the Bezier fast path
  bool use_table_ = false;  // the bound face is evaluated through s_.patch_table
  int sub_face_ = 0;
  int bound_ptex_ = -1;
  // EvalDerivs' derivatives times this are the Ptex face's: on an n-gon's sub-faces Bfr and
  // Far differentiate in their own sub-face coordinates, half the Ptex sub-face's span.
  double deriv_scale_ = 1.0;
  BezierPatch bezier_{};
  CubicBasisTable basis_u_, basis_v_;
  // One row of the regular fast path, structure of arrays.
  struct RowScratch {
    std::vector<double> p[3], du[3], dv[3];
    std::vector<std::uint8_t> bad;
    void Resize(int n) {
      for (int k = 0; k < 3; ++k) {
        p[k].resize(static_cast<std::size_t>(n));
        du[k].resize(static_cast<std::size_t>(n));
        dv[k].resize(static_cast<std::size_t>(n));
      }
      bad.resize(static_cast<std::size_t>(n));
    }
  } row_;
  LimitEvaluatorStats stats_;
  std::string error_;
};

// A normal is usable when sin(angle(du, dv)) > 1e-12 and the cross product is finite.
inline constexpr double kMinSin2 = 1e-24;
inline constexpr double kMaxLen2 = 1e300;

// Unit normal of cross(du, dv) into n; false (n untouched) if the cross product is
// degenerate relative to |du||dv|, zero, or not finite.
inline bool UnitNormal(const double du[3], const double dv[3], float n[3]) {
  const double cx = du[1] * dv[2] - du[2] * dv[1];
  const double cy = du[2] * dv[0] - du[0] * dv[2];
  const double cz = du[0] * dv[1] - du[1] * dv[0];
  const double len2 = cx * cx + cy * cy + cz * cz;
  const double scale2 = (du[0] * du[0] + du[1] * du[1] + du[2] * du[2]) *
                        (dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
  if (!(len2 > kMinSin2 * scale2) || !(len2 < kMaxLen2)) return false;
  const double inv = 1.0 / std::sqrt(len2);
  n[0] = static_cast<float>(cx * inv);
  n[1] = static_cast<float>(cy * inv);
  n[2] = static_cast<float>(cz * inv);
  return true;
}

}  // namespace dispex::subdiv
