// The per-face and the cross-face readers of include/dispex/ptex_sampler.h. The cross-face one
// follows the reference library's PtexSeparableFilter / PtexSeparableKernel semantics step by
// step (kernel construction, splitting at edges and corners, rotation into the neighbour,
// sub-face transitions, resolution matching), written anew in double precision.
#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <numeric>

#include "core/check.h"
#include "dispex/ptex_sampler.h"

namespace dispex {

namespace {

enum Edge { kBottom = 0, kRight = 1, kTop = 2, kLeft = 3 };

// A separable kernel over the texels of one face at resolution 2^ulog2 x 2^vlog2: weights
// ku[0..uw) x kv[0..vw) starting at texel (u, v), which may lie outside the face before the
// kernel is split.
struct Kernel {
  static constexpr int kMax = 10;
  int ulog2 = 0, vlog2 = 0;
  int u = 0, v = 0, uw = 0, vw = 0;
  std::array<double, kMax> ku{}, kv{};

  int ures() const { return 1 << ulog2; }
  int vres() const { return 1 << vlog2; }
  static double Sum(const double* k, int n) { return std::accumulate(k, k + n, 0.0); }
  double weight() const { return Sum(ku.data(), uw) * Sum(kv.data(), vw); }

  void DropFrontU(int n) {
    std::copy(ku.begin() + n, ku.begin() + uw, ku.begin());
    uw -= n;
  }
  void DropFrontV(int n) {
    std::copy(kv.begin() + n, kv.begin() + vw, kv.begin());
    vw -= n;
  }
  void StripZeros() {
    int lead = 0;
    while (lead < uw && ku[lead] == 0) ++lead;
    DropFrontU(lead);
    u += lead;
    while (uw > 0 && ku[uw - 1] == 0) --uw;
    lead = 0;
    while (lead < vw && kv[lead] == 0) ++lead;
    DropFrontV(lead);
    v += lead;
    while (vw > 0 && kv[vw - 1] == 0) --vw;
  }

  // Clamp at an edge without neighbour: the weights beyond it join the outermost texel.
  void MergeLeft() {
    const int w = -u;
    ku[w] += Sum(ku.data(), w);
    DropFrontU(w);
    u = 0;
  }
  void MergeRight() {
    const int w = u + uw - ures();
    ku[uw - w - 1] += Sum(ku.data() + uw - w, w);
    uw -= w;
  }
  void MergeBottom() {
    const int w = -v;
    kv[w] += Sum(kv.data(), w);
    DropFrontV(w);
    v = 0;
  }
  void MergeTop() {
    const int w = v + vw - vres();
    kv[vw - w - 1] += Sum(kv.data() + vw - w, w);
    vw -= w;
  }

  // Moves the part beyond an edge into `out` (in the same face's coordinates, shifted by one
  // face width so that it addresses the neighbour's texels before rotation).
  void SplitLeft(Kernel& out) {
    const int w = -u;
    if (w < uw) {
      out = *this;
      out.u = ures() - w;
      out.uw = w;
      u = 0;
      DropFrontU(w);
    } else {
      out = *this;
      out.u += ures();
      u = 0, uw = 0;
    }
  }
  void SplitRight(Kernel& out) {
    const int w = u + uw - ures();
    if (w < uw) {
      out = *this;
      out.u = 0;
      out.uw = w;
      std::copy(ku.begin() + uw - w, ku.begin() + uw, out.ku.begin());
      uw -= w;
    } else {
      out = *this;
      out.u -= ures();
      u = 0, uw = 0;
    }
  }
  void SplitBottom(Kernel& out) {
    const int w = -v;
    if (w < vw) {
      out = *this;
      out.v = vres() - w;
      out.vw = w;
      v = 0;
      DropFrontV(w);
    } else {
      out = *this;
      out.v += vres();
      v = 0, vw = 0;
    }
  }
  void SplitTop(Kernel& out) {
    const int w = v + vw - vres();
    if (w < vw) {
      out = *this;
      out.v = 0;
      out.vw = w;
      std::copy(kv.begin() + vw - w, kv.begin() + vw, out.kv.begin());
      vw -= w;
    } else {
      out = *this;
      out.v -= vres();
      v = 0, vw = 0;
    }
  }

  void FlipU() {
    u = ures() - u - uw;
    std::reverse(ku.begin(), ku.begin() + uw);
  }
  void FlipV() {
    v = vres() - v - vw;
    std::reverse(kv.begin(), kv.begin() + vw);
  }
  void SwapUV() {
    std::swap(ulog2, vlog2);
    std::swap(u, v);
    std::swap(uw, vw);
    std::swap(ku, kv);
  }
  // `steps` quarter turns counter-clockwise.
  void Rotate(int steps) {
    switch (steps & 3) {
      case 1:
        FlipU();
        SwapUV();
        break;
      case 2:
        FlipU();
        FlipV();
        break;
      case 3:
        FlipV();
        SwapUV();
        break;
      default:
        break;
    }
  }

  // Halves the resolution along u: pairs of weights combine, an odd leading one stays alone.
  void DownresU() {
    int src = 0, dst = 0;
    if (u & 1) {
      ++src, ++dst;
      --uw;
    }
    for (int i = uw / 2; i > 0; --i, src += 2) ku[dst++] = ku[src] + ku[src + 1];
    if (uw & 1) ku[dst++] = ku[src];
    u /= 2;
    uw = dst;
    --ulog2;
  }
  void DownresV() {
    int src = 0, dst = 0;
    if (v & 1) {
      ++src, ++dst;
      --vw;
    }
    for (int i = vw / 2; i > 0; --i, src += 2) kv[dst++] = kv[src] + kv[src + 1];
    if (vw & 1) kv[dst++] = kv[src];
    v /= 2;
    vw = dst;
    --vlog2;
  }
  void UpresU() {
    for (int i = uw - 1; i >= 0; --i) ku[2 * i] = ku[2 * i + 1] = ku[i] / 2;
    uw *= 2, u *= 2;
    ++ulog2;
  }
  void UpresV() {
    for (int i = vw - 1; i >= 0; --i) kv[2 * i] = kv[2 * i + 1] = kv[i] / 2;
    vw *= 2, v *= 2;
    ++vlog2;
  }

  // From a quad into the sub-face across `edge`; true when that is the sub-face the quad
  // names (the first half of the quad's edge).
  bool MainToSubface(int edge) {
    if (ulog2 == 0) UpresU();
    if (vlog2 == 0) UpresV();
    if (ulog2 > 0) --ulog2;
    if (vlog2 > 0) --vlog2;
    bool primary = false;
    const int r_u = ures(), r_v = vres();
    switch (edge & 3) {
      case kBottom:
        primary = u < r_u;
        v -= r_v;
        if (!primary) u -= r_u;
        break;
      case kRight:
        primary = v < r_v;
        if (!primary) v -= r_v;
        break;
      case kTop:
        primary = u >= r_u;
        if (primary) u -= r_u;
        break;
      default:
        primary = v >= r_v;
        u -= r_u;
        if (primary) v -= r_v;
        break;
    }
    return primary;
  }
  void SubfaceToMain(int edge) {
    switch (edge & 3) {
      case kBottom:
        v += vres();
        break;
      case kRight:
        break;
      case kTop:
        u += ures();
        break;
      default:
        u += ures();
        v += vres();
        break;
    }
    ++ulog2, ++vlog2;
  }

  // For a kernel at a vertex of valence 5 or more: the same resolution and width both ways,
  // u and v weights summed, scaled so that the total weight does not grow. Returns the new
  // total weight.
  double MakeSymmetric(double initial_weight) {
    while (ulog2 > vlog2) DownresU();
    while (vlog2 > ulog2) DownresV();
    uw = vw = std::min(uw, vw);
    double total = 0;
    for (int i = 0; i < uw; ++i) {
      ku[i] = kv[i] = ku[i] + kv[i];
      total += ku[i];
    }
    double new_weight = total * total;
    const double scale = new_weight == 0 ? 1.0 : initial_weight / new_weight;
    if (scale < 1) {
      if (scale < -1) {
        for (int i = 0; i < uw; ++i) ku[i] = -ku[i];
        new_weight = -new_weight;
      } else {
        for (int i = 0; i < uw; ++i) ku[i] *= scale;
        new_weight = initial_weight;
      }
    }
    return new_weight;
  }
};

// A face's texels box-averaged to any lower resolution, through a summed-area table.
class BoxReductions {
 public:
  void Build(const PtexFaceInfo& info, const std::vector<float>& texels) {
    ures_ = info.ures();
    vres_ = info.vres();
    sums_.assign(std::size_t(ures_ + 1) * std::size_t(vres_ + 1), 0.0);
    for (int j = 0; j < vres_; ++j) {
      double row = 0;
      for (int i = 0; i < ures_; ++i) {
        row += texels[std::size_t(j) * std::size_t(ures_) + std::size_t(i)];
        At(i + 1, j + 1) = At(i + 1, j) + row;
      }
    }
  }
  // Texel (i, j) of the face reduced to 2^ulog2 x 2^vlog2.
  double Texel(int ulog2, int vlog2, int i, int j) const {
    const int bu = ures_ >> ulog2, bv = vres_ >> vlog2;
    const int i0 = i * bu, j0 = j * bv;
    const double sum = Get(i0 + bu, j0 + bv) - Get(i0, j0 + bv) - Get(i0 + bu, j0) + Get(i0, j0);
    return sum / (double(bu) * double(bv));
  }

 private:
  double& At(int i, int j) {
    return sums_[std::size_t(j) * std::size_t(ures_ + 1) + std::size_t(i)];
  }
  double Get(int i, int j) const {
    return sums_[std::size_t(j) * std::size_t(ures_ + 1) + std::size_t(i)];
  }
  int ures_ = 0, vres_ = 0;
  std::vector<double> sums_;
};

}  // namespace

struct PtexMapSampler::Impl {
  std::span<const PtexFaceInfo> faces;
  std::span<const std::vector<float>> texels;
  std::unique_ptr<std::once_flag[]> reductions_built;
  std::vector<BoxReductions> reductions;

  bool constant(int f) const { return texels[std::size_t(f)].size() == 1; }
  float texel(int f, int i, int j) const {
    const auto& t = texels[std::size_t(f)];
    if (t.size() == 1) return t[0];
    return t[std::size_t(j) * std::size_t(faces[std::size_t(f)].ures()) + std::size_t(i)];
  }
  const BoxReductions& Reductions(int f) const {
    std::call_once(reductions_built[std::size_t(f)], [&] {
      const_cast<BoxReductions&>(reductions[std::size_t(f)])
          .Build(faces[std::size_t(f)], texels[std::size_t(f)]);
    });
    return reductions[std::size_t(f)];
  }

  // One evaluation: the running weighted sum and total weight.
  struct Eval {
    double sum = 0, weight = 0;
  };

  void Apply(Eval& e, Kernel& k, int f) const {
    if (k.uw <= 0 || k.vw <= 0) return;
    const PtexFaceInfo& info = faces[std::size_t(f)];
    while (k.ulog2 > info.ulog2) k.DownresU();
    while (k.vlog2 > info.vlog2) k.DownresV();
    DISPEX_CHECK(k.u >= 0 && k.u + k.uw <= k.ures() && k.v >= 0 && k.v + k.vw <= k.vres());
    if (constant(f)) {
      e.sum += k.weight() * texels[std::size_t(f)][0];
      return;
    }
    const bool reduced = k.ulog2 < info.ulog2 || k.vlog2 < info.vlog2;
    const BoxReductions* box = reduced ? &Reductions(f) : nullptr;
    for (int j = 0; j < k.vw; ++j) {
      double row = 0;
      for (int i = 0; i < k.uw; ++i) {
        const double value = box ? box->Texel(k.ulog2, k.vlog2, k.u + i, k.v + j)
                                 : double(texel(f, k.u + i, k.v + j));
        row += k.ku[std::size_t(i)] * value;
      }
      e.sum += k.kv[std::size_t(j)] * row;
    }
  }

  void SplitAndApply(Eval& e, Kernel& k, int f) const {
    const PtexFaceInfo& info = faces[std::size_t(f)];
    const bool split_r = k.u + k.uw > k.ures(), split_l = k.u < 0;
    const bool split_t = k.v + k.vw > k.vres(), split_b = k.v < 0;
    const auto& adj = info.adjfaces;
    Kernel ka, kc;
    if (split_r) {
      if (adj[kRight] >= 0) {
        k.SplitRight(ka);
        if (split_t) {
          if (adj[kTop] >= 0) {
            ka.SplitTop(kc);
            ApplyToCorner(e, kc, f, kTop);
          } else {
            ka.MergeTop();
          }
        }
        if (split_b) {
          if (adj[kBottom] >= 0) {
            ka.SplitBottom(kc);
            ApplyToCorner(e, kc, f, kRight);
          } else {
            ka.MergeBottom();
          }
        }
        ApplyAcrossEdge(e, ka, f, kRight);
      } else {
        k.MergeRight();
      }
    }
    if (split_l) {
      if (adj[kLeft] >= 0) {
        k.SplitLeft(ka);
        if (split_t) {
          if (adj[kTop] >= 0) {
            ka.SplitTop(kc);
            ApplyToCorner(e, kc, f, kLeft);
          } else {
            ka.MergeTop();
          }
        }
        if (split_b) {
          if (adj[kBottom] >= 0) {
            ka.SplitBottom(kc);
            ApplyToCorner(e, kc, f, kBottom);
          } else {
            ka.MergeBottom();
          }
        }
        ApplyAcrossEdge(e, ka, f, kLeft);
      } else {
        k.MergeLeft();
      }
    }
    if (split_t) {
      if (adj[kTop] >= 0) {
        k.SplitTop(ka);
        ApplyAcrossEdge(e, ka, f, kTop);
      } else {
        k.MergeTop();
      }
    }
    if (split_b) {
      if (adj[kBottom] >= 0) {
        k.SplitBottom(ka);
        ApplyAcrossEdge(e, ka, f, kBottom);
      } else {
        k.MergeBottom();
      }
    }
    Apply(e, k, f);
  }

  void ApplyAcrossEdge(Eval& e, Kernel& k, int f, int edge) const {
    const PtexFaceInfo& info = faces[std::size_t(f)];
    int af = info.adjfaces[std::size_t(edge)];
    int aedge = info.adjedges[std::size_t(edge)];
    const PtexFaceInfo* a = &faces[std::size_t(af)];
    int rot = edge - aedge + 2;
    if (info.subface != a->subface) {
      if (a->subface) {
        if (!k.MainToSubface(edge)) {  // the second sub-face along the quad's edge
          const int next_edge = (aedge + 3) % 4;
          const int next_face = a->adjfaces[std::size_t(next_edge)];
          aedge = a->adjedges[std::size_t(next_edge)];
          af = next_face;
          a = &faces[std::size_t(af)];
          rot += next_edge - aedge + 2;
        }
      } else {
        const bool primary = a->adjfaces[std::size_t(aedge)] == f;
        k.SubfaceToMain(edge - int(primary));
      }
    }
    k.Rotate(rot);
    if (a->subface) {
      SplitAndApply(e, k, af);
    } else {
      Apply(e, k, af);
    }
  }

  void ApplyToCorner(Eval& e, Kernel& k, int f, int edge) const {
    constexpr int kMaxValence = 10;
    std::array<int, kMaxValence> corner_face{}, corner_edge{};
    int af = f, aedge = edge;
    const PtexFaceInfo* a = &faces[std::size_t(f)];
    bool previous_subface = a->subface;
    int num_corners = 0;
    for (int i = 0; i < kMaxValence; ++i) {
      const int previous_face = af;
      af = a->adjfaces[std::size_t(aedge)];
      if (af < 0) {
        num_corners = i - 2;
        break;
      }
      aedge = (a->adjedges[std::size_t(aedge)] + 1) % 4;
      if (af == f && aedge == edge) {
        num_corners = i - 2;
        break;
      }
      a = &faces[std::size_t(af)];
      corner_face[std::size_t(i)] = af;
      corner_edge[std::size_t(i)] = aedge;
      const bool subface = a->subface;
      if (previous_subface && !subface &&
          a->adjfaces[std::size_t((aedge + 3) % 4)] == previous_face) {
        // A T-junction where a quad meets two sub-faces: continue on the quad.
        const bool primary = i == 1;
        k.SubfaceToMain(edge + int(primary) * 2);
        k.Rotate(edge - aedge + 3 - int(primary));
        SplitAndApply(e, k, af);
        return;
      }
      previous_subface = subface;
    }
    if (num_corners == 1) {
      ApplyToCornerFace(e, k, f, edge, corner_face[1], corner_edge[1]);
    } else if (num_corners > 1) {
      k.Rotate(edge + 2);
      const double initial = k.weight();
      const double symmetric = k.MakeSymmetric(initial);
      for (int i = 1; i <= num_corners; ++i) {
        Kernel kc = k;
        ApplyToCornerFace(e, kc, f, 2, corner_face[std::size_t(i)], corner_edge[std::size_t(i)]);
      }
      e.weight += symmetric * double(num_corners) - initial;
    } else {
      e.weight -= k.weight();
    }
  }

  void ApplyToCornerFace(Eval& e, Kernel& k, int f, int edge, int cf, int cedge) const {
    const bool subface = faces[std::size_t(f)].subface;
    const bool corner_subface = faces[std::size_t(cf)].subface;
    if (subface != corner_subface) {
      if (corner_subface) {
        k.MainToSubface(edge + 3);
      } else {
        k.SubfaceToMain(edge + 3);
      }
    }
    k.Rotate(edge - cedge + 2);
    if (corner_subface) {
      SplitAndApply(e, k, cf);
    } else {
      Apply(e, k, cf);
    }
  }
};

PtexMapSampler::PtexMapSampler(std::span<const PtexFaceInfo> faces,
                               std::span<const std::vector<float>> texels)
    : impl_(std::make_unique<Impl>()) {
  DISPEX_CHECK_EQ(faces.size(), texels.size());
  impl_->faces = faces;
  impl_->texels = texels;
  impl_->reductions_built = std::make_unique<std::once_flag[]>(faces.size());
  impl_->reductions.resize(faces.size());
}
PtexMapSampler::~PtexMapSampler() = default;
PtexMapSampler::PtexMapSampler(PtexMapSampler&&) noexcept = default;
PtexMapSampler& PtexMapSampler::operator=(PtexMapSampler&&) noexcept = default;

int PtexMapSampler::num_faces() const {
  return static_cast<int>(impl_->faces.size());
}

double PtexMapSampler::SampleFace(PtexFaceId face, double u, double v) const {
  const int f = face.value;
  const PtexFaceInfo& info = impl_->faces[std::size_t(f)];
  if (impl_->constant(f)) return impl_->texels[std::size_t(f)][0];
  const int ures = info.ures(), vres = info.vres();
  const double x = std::clamp(u, 0.0, 1.0) * ures - 0.5, y = std::clamp(v, 0.0, 1.0) * vres - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const int i0 = std::clamp(int(fx), 0, ures - 1), i1 = std::clamp(int(fx) + 1, 0, ures - 1);
  const int j0 = std::clamp(int(fy), 0, vres - 1), j1 = std::clamp(int(fy) + 1, 0, vres - 1);
  const double bottom = (1 - ax) * impl_->texel(f, i0, j0) + ax * impl_->texel(f, i1, j0);
  const double top = (1 - ax) * impl_->texel(f, i0, j1) + ax * impl_->texel(f, i1, j1);
  return (1 - ay) * bottom + ay * top;
}

double PtexMapSampler::SampleAcrossFaces(PtexFaceId face, double u, double v) const {
  const int f = face.value;
  const PtexFaceInfo& info = impl_->faces[std::size_t(f)];
  Kernel k;
  k.ulog2 = info.ulog2;
  k.vlog2 = info.vlog2;
  const double x = std::clamp(u, 0.0, 1.0) * k.ures() - 0.5;
  const double y = std::clamp(v, 0.0, 1.0) * k.vres() - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  k.u = int(fx), k.v = int(fy);
  k.uw = k.vw = 2;
  k.ku[0] = 1 - (x - fx), k.ku[1] = x - fx;
  k.kv[0] = 1 - (y - fy), k.kv[1] = y - fy;
  k.StripZeros();
  Impl::Eval e;
  e.weight = k.weight();
  impl_->SplitAndApply(e, k, f);
  return e.sum / e.weight;
}

void PtexEdgePoint(int edge, double t, double& u, double& v) {
  switch (edge & 3) {
    case kBottom:
      u = t, v = 0;
      return;
    case kRight:
      u = 1, v = t;
      return;
    case kTop:
      u = 1 - t, v = 1;
      return;
    default:
      u = 0, v = 1 - t;
      return;
  }
}

bool PtexAcrossEdge(std::span<const PtexFaceInfo> faces, PtexFaceId face, int edge, double t,
                    PtexEdgeSide& other) {
  const PtexFaceInfo& info = faces[std::size_t(face.value)];
  const int af = info.adjfaces[std::size_t(edge)];
  if (af < 0) return false;
  const PtexFaceInfo& a = faces[std::size_t(af)];
  other.face = PtexFaceId(af);
  other.edge = info.adjedges[std::size_t(edge)];
  if (info.subface == a.subface) {
    other.t = 1 - t;
    return true;
  }
  if (!info.subface) return false;
  const bool primary = a.adjfaces[std::size_t(other.edge)] == face.value;
  other.t = primary ? (1 - t) / 2 : 1 - t / 2;
  return true;
}

}  // namespace dispex
