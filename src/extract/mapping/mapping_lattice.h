// The lattice of cells across Ptex face edges, shared by the mapping's parts (mapping_trace.h):
// points of a face's grid in half-cell units, the rotations and shifts that carry them into a
// neighbour's grid, the states of the slots of a face's neighbourhood, and laying that
// neighbourhood out (mapping_layout.cpp).
#pragma once

#include <cmath>
#include <cstdint>

#include "dispex/ptex_sampler.h"
#include "extract/mapping/mapping_trace.h"

namespace dispex::extract::mapping {

constexpr int kMargin = kMaxRings;  // the apron: cells laid out beyond each edge of the face
constexpr int kMaxHops = 6;         // edge crossings to reach one apron cell

enum SlotState : std::uint8_t {
  kNone = 0,     // no surface there: beyond a boundary, a hole face
  kCell = 1,     // a sculpt quad
  kUnknown = 2,  // not laid out (ambiguous or too far): a sample whose rings reach it is undecided
  kFan = 3,      // the block diagonal to an extraordinary corner: its fan holds the cells
};

// ---- The lattice of cells across Ptex face edges -------------------------------------------
// Points of a face's grid in doubled units: vertex (i, j) at (2i, 2j), cell centres odd.

struct Point {
  int x = 0, y = 0;
  bool operator==(const Point&) const = default;
};

// p' = R_q p + (tx, ty), R_q a rotation by q quarter turns counter-clockwise.
struct Iso {
  int q = 0, tx = 0, ty = 0;
  bool operator==(const Iso&) const = default;
};

inline Point Rotate(int q, Point p) {
  switch (q & 3) {
    case 0:
      return p;
    case 1:
      return {-p.y, p.x};
    case 2:
      return {-p.x, -p.y};
    default:
      return {p.y, -p.x};
  }
}

inline Point Apply(const Iso& s, Point p) {
  const Point r = Rotate(s.q, p);
  return {r.x + s.tx, r.y + s.ty};
}

// `second` after `first`.
inline Iso Then(const Iso& first, const Iso& second) {
  const Point t = Rotate(second.q, {first.tx, first.ty});
  return {(first.q + second.q) & 3, t.x + second.tx, t.y + second.ty};
}

inline Iso Inverse(const Iso& s) {
  const int q = (4 - s.q) & 3;
  const Point t = Rotate(q, {-s.tx, -s.ty});
  return {q, t.x, t.y};
}

inline Point CornerPoint(int m, int corner) {
  switch (corner & 3) {
    case 0:
      return {0, 0};
    case 1:
      return {2 * m, 0};
    case 2:
      return {2 * m, 2 * m};
    default:
      return {0, 2 * m};
  }
}

// Edge e runs from corner e to corner e + 1.
inline Point EdgeDirection(int edge) {
  static constexpr Point kDirections[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  return kDirections[edge & 3];
}

inline Point EdgePoint(int m, int edge, double t) {
  double u = 0, v = 0;
  PtexEdgePoint(edge, t, u, v);
  return {static_cast<int>(std::lround(2 * m * u)), static_cast<int>(std::lround(2 * m * v))};
}

// Lays out the neighbourhood of `face` in `w.apron` (with `margins`: the slots beyond the face,
// kMargin rings of cells) and the fans of its extraordinary corners.
void LayOut(const SculptMapping& mapping, int face, MappingScratch& w, bool margins);
// The apron's vertices, relative to a vertex of the face, for the float filter.
void FillLattice(const Mesh& sculpt, MappingScratch& w);

}  // namespace dispex::extract::mapping
