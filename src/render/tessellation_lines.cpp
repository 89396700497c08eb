// The lines of the cage that Ptex faces' sides lie on, and the names of the points on them
// (tessellation_lines.h).
#include "render/tessellation_lines.h"

namespace dispex::render::lines {

namespace {

LineKey EdgeLine(std::int32_t va, std::int32_t vb) {
  return {kBaseEdge, std::min(va, vb), std::max(va, vb)};
}

}  // namespace

PointKey KeyOf(const Mesh& cage, const LineKey& line, Frac t) {
  if (line.kind == kBaseEdge) {
    if (t.num == 0) return {kVertexPoint, line.a, 0, 0, 0};
    if (t.num == 2 * t.den) return {kVertexPoint, line.b, 0, 0, 0};
    return {kEdgePoint, line.a, line.b, t.num, t.den};
  }
  if (t.num == 0) {  // the midpoint of the face's edge q
    const auto verts = cage.face(static_cast<std::size_t>(line.a));
    const int n = static_cast<int>(verts.size());
    const std::int32_t va = verts[static_cast<std::size_t>(line.b)];
    const std::int32_t vb = verts[static_cast<std::size_t>((line.b + 1) % n)];
    return {kEdgePoint, std::min(va, vb), std::max(va, vb), 1, 1};
  }
  if (t.num == 2 * t.den) return {kCentrePoint, line.a, 0, 0, 0};
  return {kSpokePoint, line.a, line.b, t.num, t.den};
}

void FaceSides(const Mesh& cage, const LimitSurface& surface, int f, int kx, int ky,
               SideEntry out[4]) {
  const BaseFaceId base = surface.base_face(PtexFaceId(f));
  const auto verts = cage.face(static_cast<std::size_t>(base.value));
  const int n = static_cast<int>(verts.size());
  for (int s = 0; s < 4; ++s) {
    out[s].face = f;
    out[s].side = s;
    out[s].segs = (s % 2 == 0) ? kx : ky;
  }
  if (n == 4) {
    for (int s = 0; s < 4; ++s) {
      const std::int32_t va = verts[static_cast<std::size_t>(s)];
      const std::int32_t vb = verts[static_cast<std::size_t>((s + 1) % 4)];
      out[s].line = EdgeLine(va, vb);
      out[s].p0 = va < vb ? 0 : 2;
      out[s].p1 = 2 - out[s].p0;
    }
    return;
  }
  const int q = surface.sub_face(PtexFaceId(f));
  const std::int32_t vq = verts[static_cast<std::size_t>(q)];
  const std::int32_t vnext = verts[static_cast<std::size_t>((q + 1) % n)];
  const std::int32_t vprev = verts[static_cast<std::size_t>((q + n - 1) % n)];
  out[0].line = EdgeLine(vq, vnext);  // vertex q to the midpoint of edge q
  out[0].p0 = vq < vnext ? 0 : 2;
  out[0].p1 = 1;
  out[1].line = {kSpoke, base.value, q};  // midpoint of edge q to the centre
  out[1].p0 = 0;
  out[1].p1 = 2;
  out[2].line = {kSpoke, base.value, (q + n - 1) % n};  // centre to the midpoint of edge q-1
  out[2].p0 = 2;
  out[2].p1 = 0;
  out[3].line = EdgeLine(vprev, vq);  // midpoint of edge q-1 to vertex q
  out[3].p0 = 1;
  out[3].p1 = vprev < vq ? 2 : 0;
}

}  // namespace dispex::render::lines
