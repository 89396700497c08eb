// Limit evaluation of one Ptex face, following OpenSubdiv's Bfr tutorials (bfr_tutorial_1_1:
// one Surface per face, patch points prepared once, then Evaluate per (u,v)), with n-gon
// sub-faces mapped through Bfr::Parameterization::ConvertNormalizedSubFaceToCoord -- the
// normalized sub-face coordinates are the Ptex coordinates of Far::PtexIndices' sub-faces.
#include "subdiv/face_sampler.h"

#include <cmath>

#include "core/check.h"
#include "subdiv/osd_messages.h"

namespace dispex::subdiv {
namespace {

namespace Bfr = OpenSubdiv::Bfr;
using PointDescriptor = Bfr::Surface<double>::PointDescriptor;

Bfr::SurfaceFactory::Options FactoryOptions(const SubdivOptions& options) {
  Bfr::SurfaceFactory::Options factory_options;
  factory_options.SetApproxLevelSmooth(options.approx_level_smooth);
  factory_options.SetApproxLevelSharp(options.approx_level_sharp);
  return factory_options;
}

}  // namespace

FaceSampler::FaceSampler(const LimitSurface::Impl& surface)
    : s_(surface), factory_(*surface.refiner, FactoryOptions(surface.options)) {}

FaceSampler::BindResult FaceSampler::Bind(int ptex) {
  if (ptex == bound_ptex_) return BindResult::kOk;
  bound_ptex_ = -1;
  if (s_.ptex_hole[ptex]) return BindResult::kNoSurface;
  const int base = s_.ptex_base[ptex];
  use_table_ = s_.use_patch_table[base] != 0;
  if (use_table_) {
    regular_ = false;
    surface_base_face_ = -1;
  } else if (base != surface_base_face_) {
    surface_base_face_ = -1;
    OsdMessageCapture capture;
    const bool ok = factory_.InitVertexSurface(base, &surface_);
    if (!ok || !capture.empty()) {
      error_ = capture.empty() ? std::string("no surface") : capture.messages();
      return BindResult::kFailed;
    }
    patch_points_.resize(3 * static_cast<std::size_t>(surface_.GetNumPatchPoints()));
    surface_.PreparePatchPoints(s_.positions.data(), PointDescriptor(3), patch_points_.data(),
                                PointDescriptor(3));
    param_ = surface_.GetParameterization();
    has_sub_faces_ = param_.HasSubFaces();
    regular_ = false;
    if (s_.options.regular_fast_path && surface_.IsRegular()) {
      double p[4][3], du[4][3], dv[4][3], duu[3], duv[4][3], dvv[3];
      static constexpr double kCorner[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
      for (int c = 0; c < 4; ++c) {
        surface_.Evaluate(kCorner[c], patch_points_.data(), PointDescriptor(3), p[c], du[c], dv[c],
                          duu, duv[c], dvv);
      }
      bezier_ = BezierPatch::FromCornerDerivatives(p, du, dv, duv);
      regular_ = true;
    }
    surface_base_face_ = base;
  }
  sub_face_ = s_.ptex_sub[ptex];
  deriv_scale_ = s_.face_size(base) == 4 ? 1.0 : 0.5;
  bound_ptex_ = ptex;
  ++stats_.faces;
  stats_.regular_faces += regular_ ? 1 : 0;
  return BindResult::kOk;
}

void FaceSampler::EvalDerivs(double u, double v, double p[3], double du[3], double dv[3]) {
  if (use_table_) {
    DISPEX_CHECK(s_.patch_table->Evaluate(bound_ptex_, u, v, p, du, dv));
    return;
  }
  if (regular_) {
    bezier_.Evaluate(u, v, p, du, dv);
    return;
  }
  double uv[2] = {u, v};
  if (has_sub_faces_) {
    const double st[2] = {u, v};
    param_.ConvertNormalizedSubFaceToCoord(sub_face_, st, uv);
  }
  surface_.Evaluate(uv, patch_points_.data(), PointDescriptor(3), p, du, dv);
}

void FaceSampler::Point(double u, double v, float position[3], float normal[3], float du_out[3],
                        float dv_out[3]) {
  double p[3], du[3], dv[3];
  EvalDerivs(u, v, p, du, dv);
  for (int k = 0; k < 3; ++k) position[k] = static_cast<float>(p[k]);
  if (normal != nullptr && !UnitNormal(du, dv, normal)) FallbackNormal(u, v, normal);
  StoreDerivs(du, dv, du_out, dv_out);
  ++stats_.samples;
}

void FaceSampler::StoreDerivs(const double du[3], const double dv[3], float* du_out,
                              float* dv_out) const {
  if (du_out == nullptr) return;
  for (int k = 0; k < 3; ++k) {
    du_out[k] = static_cast<float>(du[k] * deriv_scale_);
    dv_out[k] = static_cast<float>(dv[k] * deriv_scale_);
  }
}

void FaceSampler::Grid(int rx, int ry, float* positions, float* normals, float* du, float* dv) {
  if (regular_) {
    GridRegular(rx, ry, positions, normals, du, dv);
  } else {
    GridBfr(rx, ry, positions, normals, du, dv);
  }
  stats_.samples += static_cast<std::int64_t>(rx) * ry;
}

void FaceSampler::GridBfr(int rx, int ry, float* positions, float* normals, float* du_out,
                          float* dv_out) {
  if (use_table_) {
    for (int j = 0; j < ry; ++j) {
      for (int i = 0; i < rx; ++i) {
        const std::size_t k = 3 * (static_cast<std::size_t>(j) * rx + i);
        Point((i + 0.5) / rx, (j + 0.5) / ry, positions + k,
              normals == nullptr ? nullptr : normals + k, du_out == nullptr ? nullptr : du_out + k,
              dv_out == nullptr ? nullptr : dv_out + k);
      }
    }
    stats_.samples -= static_cast<std::int64_t>(rx) * ry;  // Point() counted them
    return;
  }
  const double* points = patch_points_.data();
  for (int j = 0; j < ry; ++j) {
    const double v = (j + 0.5) / ry;
    for (int i = 0; i < rx; ++i) {
      const double u = (i + 0.5) / rx;
      double uv[2] = {u, v};
      if (has_sub_faces_) {
        const double st[2] = {u, v};
        param_.ConvertNormalizedSubFaceToCoord(sub_face_, st, uv);
      }
      double p[3], du[3], dv[3];
      float* out_p = positions + 3 * (static_cast<std::size_t>(j) * rx + i);
      if (normals == nullptr) {
        surface_.Evaluate(uv, points, PointDescriptor(3), p);
      } else {
        surface_.Evaluate(uv, points, PointDescriptor(3), p, du, dv);
        const std::size_t k = 3 * (static_cast<std::size_t>(j) * rx + i);
        if (!UnitNormal(du, dv, normals + k)) FallbackNormal(u, v, normals + k);
        if (du_out != nullptr) StoreDerivs(du, dv, du_out + k, dv_out + k);
      }
      out_p[0] = static_cast<float>(p[0]);
      out_p[1] = static_cast<float>(p[1]);
      out_p[2] = static_cast<float>(p[2]);
    }
  }
}

void FaceSampler::GridRegular(int rx, int ry, float* positions, float* normals, float* du_out,
                              float* dv_out) {
  if (basis_u_.n != rx) basis_u_.Build(rx);
  if (basis_v_.n != ry) basis_v_.Build(ry);
  row_.Resize(rx);
  const auto& b = bezier_.b;
  const double *w0 = basis_u_.w[0].data(), *w1 = basis_u_.w[1].data(), *w2 = basis_u_.w[2].data(),
               *w3 = basis_u_.w[3].data();
  const double *d0 = basis_u_.dw[0].data(), *d1 = basis_u_.dw[1].data(),
               *d2 = basis_u_.dw[2].data(), *d3 = basis_u_.dw[3].data();
  double* p[3] = {row_.p[0].data(), row_.p[1].data(), row_.p[2].data()};
  double* du[3] = {row_.du[0].data(), row_.du[1].data(), row_.du[2].data()};
  double* dv[3] = {row_.dv[0].data(), row_.dv[1].data(), row_.dv[2].data()};
  for (int j = 0; j < ry; ++j) {
    double wv[4], dwv[4];
    for (int m = 0; m < 4; ++m) {
      wv[m] = basis_v_.w[m][j];
      dwv[m] = basis_v_.dw[m][j];
    }
    // The row's cubic in u: Bezier points q and their v-derivatives qv.
    double q[4][3], qv[4][3];
    for (int i = 0; i < 4; ++i) {
      for (int k = 0; k < 3; ++k) {
        q[i][k] = wv[0] * b[i][0][k] + wv[1] * b[i][1][k] + wv[2] * b[i][2][k] + wv[3] * b[i][3][k];
        qv[i][k] =
            dwv[0] * b[i][0][k] + dwv[1] * b[i][1][k] + dwv[2] * b[i][2][k] + dwv[3] * b[i][3][k];
      }
    }
    // Structure-of-arrays passes over the row, so that they vectorise.
    for (int k = 0; k < 3; ++k) {
      const double q0 = q[0][k], q1 = q[1][k], q2 = q[2][k], q3 = q[3][k];
      double* pk = p[k];
      for (int i = 0; i < rx; ++i) pk[i] = w0[i] * q0 + w1[i] * q1 + w2[i] * q2 + w3[i] * q3;
    }
    float* out_p = positions + 3 * static_cast<std::size_t>(j) * rx;
    for (int i = 0; i < rx; ++i) {
      out_p[3 * i + 0] = static_cast<float>(p[0][i]);
      out_p[3 * i + 1] = static_cast<float>(p[1][i]);
      out_p[3 * i + 2] = static_cast<float>(p[2][i]);
    }
    if (normals == nullptr) continue;
    for (int k = 0; k < 3; ++k) {
      const double q0 = q[0][k], q1 = q[1][k], q2 = q[2][k], q3 = q[3][k];
      const double v0 = qv[0][k], v1 = qv[1][k], v2 = qv[2][k], v3 = qv[3][k];
      double* uk = du[k];
      double* vk = dv[k];
      for (int i = 0; i < rx; ++i) {
        uk[i] = d0[i] * q0 + d1[i] * q1 + d2[i] * q2 + d3[i] * q3;
        vk[i] = w0[i] * v0 + w1[i] * v1 + w2[i] * v2 + w3[i] * v3;
      }
    }
    float* out_n = normals + 3 * static_cast<std::size_t>(j) * rx;
    std::uint8_t* bad = row_.bad.data();
    for (int i = 0; i < rx; ++i) {
      const double cx = du[1][i] * dv[2][i] - du[2][i] * dv[1][i];
      const double cy = du[2][i] * dv[0][i] - du[0][i] * dv[2][i];
      const double cz = du[0][i] * dv[1][i] - du[1][i] * dv[0][i];
      const double len2 = cx * cx + cy * cy + cz * cz;
      const double scale2 = (du[0][i] * du[0][i] + du[1][i] * du[1][i] + du[2][i] * du[2][i]) *
                            (dv[0][i] * dv[0][i] + dv[1][i] * dv[1][i] + dv[2][i] * dv[2][i]);
      // Same test as UnitNormal(); degenerate samples are redone below.
      const bool ok = len2 > kMinSin2 * scale2 && len2 < kMaxLen2;
      const double inv = ok ? 1.0 / std::sqrt(ok ? len2 : 1.0) : 0.0;
      out_n[3 * i + 0] = static_cast<float>(cx * inv);
      out_n[3 * i + 1] = static_cast<float>(cy * inv);
      out_n[3 * i + 2] = static_cast<float>(cz * inv);
      bad[i] = ok ? 0 : 1;
    }
    for (int i = 0; i < rx; ++i) {
      if (bad[i]) FallbackNormal((i + 0.5) / rx, (j + 0.5) / ry, out_n + 3 * i);
    }
    if (du_out == nullptr) continue;
    float* out_du = du_out + 3 * static_cast<std::size_t>(j) * rx;
    float* out_dv = dv_out + 3 * static_cast<std::size_t>(j) * rx;
    for (int i = 0; i < rx; ++i) {
      for (int k = 0; k < 3; ++k) {
        out_du[3 * i + k] = static_cast<float>(du[k][i]);
        out_dv[3 * i + k] = static_cast<float>(dv[k][i]);
      }
    }
  }
}

void FaceSampler::FallbackNormal(double u, double v, float normal[3]) {
  ++stats_.fallback_normals;
  double p[3], du[3], dv[3];
  for (double t : {1e-6, 1e-4, 1e-2, 0.1}) {
    EvalDerivs(u + t * (0.5 - u), v + t * (0.5 - v), p, du, dv);
    if (UnitNormal(du, dv, normal)) return;
  }
  // Newell's normal of the base face's cage polygon.
  const auto verts = s_.refiner->GetLevel(0).GetFaceVertices(s_.ptex_base[bound_ptex_]);
  double n[3] = {0, 0, 0};
  for (int k = 0; k < verts.size(); ++k) {
    const double* a = &s_.positions[3 * static_cast<std::size_t>(verts[k])];
    const double* c = &s_.positions[3 * static_cast<std::size_t>(verts[(k + 1) % verts.size()])];
    n[0] += (a[1] - c[1]) * (a[2] + c[2]);
    n[1] += (a[2] - c[2]) * (a[0] + c[0]);
    n[2] += (a[0] - c[0]) * (a[1] + c[1]);
  }
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (len > 0 && std::isfinite(len)) {
    for (int k = 0; k < 3; ++k) normal[k] = static_cast<float>(n[k] / len);
  } else {
    normal[0] = 0;
    normal[1] = 0;
    normal[2] = 1;
  }
}

}  // namespace dispex::subdiv
