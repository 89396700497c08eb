// The regular-face fast path. A regular Catmull-Clark face (Bfr::Surface::IsRegular()) is a
// single bicubic B-spline patch, possibly with boundary or infinitely-sharp-edge rules folded
// into its basis. Whatever the rule, the surface on [0,1]^2 is one bicubic polynomial, so it
// is rebuilt exactly in Bezier form from the position, first derivatives and twist (P, Pu,
// Pv, Puv) at its four corners -- the bicubic Hermite data, converted with the standard
// relations b01 = b00 + Pu/3, b11 = b00 + (Pu + Pv)/3 + Puv/9, ... (Farin, "Curves and
// Surfaces for CAGD", ch. 16-17). Then a grid is a separable evaluation with the cubic
// Bernstein weights of the texel centres, computed once per grid size.
#pragma once

#include <vector>

namespace dispex::subdiv {

// Bicubic Bezier control points b[i][j] (i along u, j along v), xyz.
struct BezierPatch {
  double b[4][4][3];

  // Corner data in the order (u,v) = (0,0), (1,0), (0,1), (1,1); each xyz.
  static BezierPatch FromCornerDerivatives(const double p[4][3], const double du[4][3],
                                           const double dv[4][3], const double duv[4][3]);

  // Position and first derivatives at (u,v).
  void Evaluate(double u, double v, double p[3], double du[3], double dv[3]) const;
};

// Cubic Bernstein weights w[m][i] and derivatives dw[m][i] (m = 0..3) at t_i = (i+0.5)/n,
// one array per weight so that loops over i vectorise.
struct CubicBasisTable {
  int n = 0;
  std::vector<double> w[4], dw[4];

  void Build(int count);
};

// The four cubic Bernstein weights and their derivatives at t.
inline void CubicBernstein(double t, double w[4], double dw[4]) {
  const double s = 1.0 - t;
  w[0] = s * s * s;
  w[1] = 3.0 * t * s * s;
  w[2] = 3.0 * t * t * s;
  w[3] = t * t * t;
  dw[0] = -3.0 * s * s;
  dw[1] = 3.0 * s * (s - 2.0 * t);
  dw[2] = 3.0 * t * (2.0 * s - t);
  dw[3] = 3.0 * t * t;
}

}  // namespace dispex::subdiv
