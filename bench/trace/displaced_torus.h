// The benchmark's generated assets, made in memory: a torus sculpt displaced by a smooth
// function at any resolution (16.8M quads at 8192 x 2048), and the base samples the
// pipeline would cast from: 64 x 64 texel-centre points with normals per face of a coarse
// base parameterisation of the same torus, on the undisplaced analytic surface.
#pragma once

#include <cstddef>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::bench {

struct TorusShape {
  double major = 1.0;       // ring radius
  double minor = 0.35;      // tube radius
  double amplitude = 0.02;  // of the displacement along the normal
};

// The displacement h(u, v) in object units, u and v in radians.
double Displacement(const TorusShape& shape, double u, double v);

// The sculpt: nu x nv quads, welded (wrapping in u and v), counter-clockwise outward,
// vertex (i, j) at the analytic torus point (2 pi i / nu, 2 pi j / nv) moved by h along the
// normal. Generated in parallel.
Mesh MakeTorusSculpt(const TorusShape& shape, int nu, int nv);

// Base samples: base_u x base_v base faces, `res` x `res` samples each at texel centres,
// face after face (row-major within a face). Points on the undisplaced torus, unit normals.
struct BaseSamples {
  int faces = 0;
  int per_face = 0;
  std::vector<Float3> points, normals;
};
BaseSamples MakeTorusBaseSamples(const TorusShape& shape, int base_u, int base_v, int res);

// Bounding-box diagonal of the undisplaced torus.
double TorusDiagonal(const TorusShape& shape);

}  // namespace dispex::bench
