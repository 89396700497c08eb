#include "displaced_torus.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>

namespace dispex::bench {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

struct Frame {
  double px, py, pz, nx, ny, nz;
};

Frame Torus(const TorusShape& shape, double u, double v) {
  const double cu = std::cos(u), su = std::sin(u), cv = std::cos(v), sv = std::sin(v);
  const double ring = shape.major + shape.minor * cv;
  return {ring * cu, ring * su, shape.minor * sv, cv * cu, cv * su, sv};
}

}  // namespace

double Displacement(const TorusShape& shape, double u, double v) {
  // Smooth: a few low harmonics and one finer ripple, all periodic in u and v.
  return shape.amplitude * (0.5 * std::sin(5 * u) * std::cos(3 * v) +
                            0.3 * std::sin(17 * u + 2 * v) + 0.2 * std::cos(29 * v - 7 * u));
}

Mesh MakeTorusSculpt(const TorusShape& shape, int nu, int nv) {
  Mesh mesh;
  mesh.source = "generated torus sculpt";
  const std::size_t num = static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv);
  mesh.positions.reserve(num + 1);  // the readers' padding, so Embree can share the buffer
  mesh.positions.resize(num);
  mesh.face_indices.resize(4 * num);
  mesh.face_offsets.resize(num + 1);
  tbb::parallel_for(tbb::blocked_range<int>(0, nv), [&](const tbb::blocked_range<int>& rows) {
    for (int j = rows.begin(); j != rows.end(); ++j) {
      const double v = kTwoPi * j / nv;
      for (int i = 0; i < nu; ++i) {
        const double u = kTwoPi * i / nu;
        const Frame f = Torus(shape, u, v);
        const double h = Displacement(shape, u, v);
        const std::size_t k = static_cast<std::size_t>(j) * static_cast<std::size_t>(nu) +
                              static_cast<std::size_t>(i);
        mesh.positions[k] = {static_cast<float>(f.px + h * f.nx),
                             static_cast<float>(f.py + h * f.ny),
                             static_cast<float>(f.pz + h * f.nz)};
        auto id = [&](int a, int b) { return static_cast<std::int32_t>((b % nv) * nu + (a % nu)); };
        std::int32_t* q = mesh.face_indices.data() + 4 * k;
        q[0] = id(i, j);
        q[1] = id(i + 1, j);
        q[2] = id(i + 1, j + 1);
        q[3] = id(i, j + 1);
        mesh.face_offsets[k + 1] = static_cast<std::uint32_t>(4 * (k + 1));
      }
    }
  });
  mesh.face_offsets[0] = 0;
  return mesh;
}

BaseSamples MakeTorusBaseSamples(const TorusShape& shape, int base_u, int base_v, int res) {
  BaseSamples s;
  s.faces = base_u * base_v;
  s.per_face = res * res;
  const std::size_t total =
      static_cast<std::size_t>(s.faces) * static_cast<std::size_t>(s.per_face);
  s.points.resize(total);
  s.normals.resize(total);
  tbb::parallel_for(0, s.faces, [&](int face) {
    const int fu = face % base_u, fv = face / base_u;
    std::size_t k = static_cast<std::size_t>(face) * static_cast<std::size_t>(s.per_face);
    for (int b = 0; b < res; ++b) {
      for (int a = 0; a < res; ++a, ++k) {
        const double u = kTwoPi * (fu + (a + 0.5) / res) / base_u;
        const double v = kTwoPi * (fv + (b + 0.5) / res) / base_v;
        const Frame f = Torus(shape, u, v);
        s.points[k] = {static_cast<float>(f.px), static_cast<float>(f.py),
                       static_cast<float>(f.pz)};
        s.normals[k] = {static_cast<float>(f.nx), static_cast<float>(f.ny),
                        static_cast<float>(f.nz)};
      }
    }
  });
  return s;
}

double TorusDiagonal(const TorusShape& shape) {
  const double xy = 2 * (shape.major + shape.minor), z = 2 * shape.minor;
  return std::sqrt(2 * xy * xy + z * z);
}

}  // namespace dispex::bench
