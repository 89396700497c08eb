#include "subdiv/bezier_patch.h"

namespace dispex::subdiv {

BezierPatch BezierPatch::FromCornerDerivatives(const double p[4][3], const double du[4][3],
                                               const double dv[4][3], const double duv[4][3]) {
  // Corner c at (u,v) = (cu, cv); its Bezier neighbours step inwards, so the signs of the
  // derivative terms flip on the far sides.
  static constexpr int kCu[4] = {0, 1, 0, 1};
  static constexpr int kCv[4] = {0, 0, 1, 1};
  BezierPatch patch;
  for (int c = 0; c < 4; ++c) {
    const int i0 = 3 * kCu[c], j0 = 3 * kCv[c];
    const int i1 = kCu[c] ? 2 : 1, j1 = kCv[c] ? 2 : 1;
    const double su = kCu[c] ? -1.0 : 1.0, sv = kCv[c] ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k) {
      patch.b[i0][j0][k] = p[c][k];
      patch.b[i1][j0][k] = p[c][k] + su * du[c][k] / 3.0;
      patch.b[i0][j1][k] = p[c][k] + sv * dv[c][k] / 3.0;
      patch.b[i1][j1][k] =
          p[c][k] + su * du[c][k] / 3.0 + sv * dv[c][k] / 3.0 + su * sv * duv[c][k] / 9.0;
    }
  }
  return patch;
}

void BezierPatch::Evaluate(double u, double v, double p[3], double du[3], double dv[3]) const {
  double wu[4], dwu[4], wv[4], dwv[4];
  CubicBernstein(u, wu, dwu);
  CubicBernstein(v, wv, dwv);
  for (int k = 0; k < 3; ++k) {
    double sp = 0, su = 0, sv = 0;
    for (int i = 0; i < 4; ++i) {
      double row = 0, row_dv = 0;
      for (int j = 0; j < 4; ++j) {
        row += wv[j] * b[i][j][k];
        row_dv += dwv[j] * b[i][j][k];
      }
      sp += wu[i] * row;
      su += dwu[i] * row;
      sv += wu[i] * row_dv;
    }
    p[k] = sp;
    du[k] = su;
    dv[k] = sv;
  }
}

void CubicBasisTable::Build(int count) {
  n = count;
  for (int m = 0; m < 4; ++m) {
    w[m].resize(static_cast<std::size_t>(count));
    dw[m].resize(static_cast<std::size_t>(count));
  }
  for (int i = 0; i < count; ++i) {
    double wi[4], dwi[4];
    CubicBernstein((i + 0.5) / count, wi, dwi);
    for (int m = 0; m < 4; ++m) {
      w[m][i] = wi[m];
      dw[m][i] = dwi[m];
    }
  }
}

}  // namespace dispex::subdiv
