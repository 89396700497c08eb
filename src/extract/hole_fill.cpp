#include "extract/hole_fill.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace dispex::extract {

namespace {

struct Level {
  std::size_t offset;  // into scratch arrays
  int nx, ny;
};

}  // namespace

int FillHolesPullPush(float* values, const std::uint8_t* valid, int nx, int ny,
                      PullPushScratch& scratch) {
  const std::size_t n = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  std::size_t missing = 0;
  for (std::size_t i = 0; i < n; ++i) missing += valid[i] == 0;
  if (missing == 0) return 0;
  if (missing == n) return -1;

  // Pyramid layout: level 0 is the input, each next level halves each dimension (rounding up)
  // until 1x1.
  Level levels[40];
  int num_levels = 0;
  std::size_t total = 0;
  for (int x = nx, y = ny;; x = (x + 1) / 2, y = (y + 1) / 2) {
    levels[num_levels++] = {total, x, y};
    total += static_cast<std::size_t>(x) * static_cast<std::size_t>(y);
    if (x == 1 && y == 1) break;
  }
  scratch.values.resize(total);
  scratch.weights.resize(total);
  float* v = scratch.values.data();
  float* w = scratch.weights.data();
  for (std::size_t i = 0; i < n; ++i) {
    w[i] = valid[i] ? 1.0f : 0.0f;
    v[i] = valid[i] ? values[i] : 0.0f;
  }

  // Pull: weighted 2x2 averages, weights clamped to 1.
  for (int l = 1; l < num_levels; ++l) {
    const Level& fine = levels[l - 1];
    const Level& coarse = levels[l];
    for (int y = 0; y < coarse.ny; ++y) {
      for (int x = 0; x < coarse.nx; ++x) {
        float sw = 0, swv = 0;
        for (int dy = 0; dy < 2; ++dy) {
          for (int dx = 0; dx < 2; ++dx) {
            int fx = 2 * x + dx, fy = 2 * y + dy;
            if (fx >= fine.nx || fy >= fine.ny) continue;
            std::size_t i = fine.offset + static_cast<std::size_t>(fy) * fine.nx + fx;
            sw += w[i];
            swv += w[i] * v[i];
          }
        }
        std::size_t c = coarse.offset + static_cast<std::size_t>(y) * coarse.nx + x;
        v[c] = sw > 0 ? swv / sw : 0.0f;
        w[c] = std::min(sw, 1.0f);
      }
    }
  }

  // Push: blend each fine cell with the bilinear interpolation of the coarser level.
  for (int l = num_levels - 2; l >= 0; --l) {
    const Level& fine = levels[l];
    const Level& coarse = levels[l + 1];
    for (int y = 0; y < fine.ny; ++y) {
      // Fine cell centre in coarse texel coordinates: (y + 0.5) / 2 - 0.5.
      float cy = (static_cast<float>(y) + 0.5f) * 0.5f - 0.5f;
      int y0 = std::clamp(static_cast<int>(std::floor(cy)), 0, coarse.ny - 1);
      int y1 = std::min(y0 + 1, coarse.ny - 1);
      float ty = std::clamp(cy - static_cast<float>(y0), 0.0f, 1.0f);
      for (int x = 0; x < fine.nx; ++x) {
        std::size_t i = fine.offset + static_cast<std::size_t>(y) * fine.nx + x;
        if (w[i] >= 1.0f) continue;
        float cx = (static_cast<float>(x) + 0.5f) * 0.5f - 0.5f;
        int x0 = std::clamp(static_cast<int>(std::floor(cx)), 0, coarse.nx - 1);
        int x1 = std::min(x0 + 1, coarse.nx - 1);
        float tx = std::clamp(cx - static_cast<float>(x0), 0.0f, 1.0f);
        auto at = [&](int xx, int yy) {
          return v[coarse.offset + static_cast<std::size_t>(yy) * coarse.nx + xx];
        };
        float interp = (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x1, y0)) +
                       ty * ((1 - tx) * at(x0, y1) + tx * at(x1, y1));
        v[i] = w[i] * v[i] + (1 - w[i]) * interp;
      }
    }
  }

  for (std::size_t i = 0; i < n; ++i) {
    if (!valid[i]) values[i] = v[i];
  }
  return static_cast<int>(missing);
}

EdgeMeans ComputeEdgeMeans(const float* values, int nx, int ny) {
  EdgeMeans e;
  double bottom = 0, top = 0, left = 0, right = 0;
  for (int x = 0; x < nx; ++x) {
    bottom += values[x];
    top += values[static_cast<std::size_t>(ny - 1) * nx + x];
  }
  for (int y = 0; y < ny; ++y) {
    left += values[static_cast<std::size_t>(y) * nx];
    right += values[static_cast<std::size_t>(y) * nx + nx - 1];
  }
  e.mean[0] = static_cast<float>(bottom / nx);
  e.mean[1] = static_cast<float>(right / ny);
  e.mean[2] = static_cast<float>(top / nx);
  e.mean[3] = static_cast<float>(left / ny);
  return e;
}

CrossFaceFill FillEmptyFaces(std::vector<std::uint8_t>& filled, std::vector<EdgeMeans>& edges,
                             std::span<const PtexFaceInfo> faces) {
  CrossFaceFill result;
  const std::size_t num_faces = filled.size();
  std::vector<std::int32_t> pending;
  for (std::size_t f = 0; f < num_faces; ++f) {
    if (!filled[f]) pending.push_back(static_cast<std::int32_t>(f));
  }
  // Each round fills the empty faces that touch a face filled before the round, so the result
  // does not depend on the order faces are visited in.
  while (!pending.empty()) {
    std::vector<std::int32_t> next;
    std::vector<std::pair<std::int32_t, float>> round;
    for (std::int32_t f : pending) {
      double sum = 0;
      int count = 0;
      for (int e = 0; e < 4; ++e) {
        const PtexFaceInfo& info = faces[static_cast<std::size_t>(f)];
        std::int32_t g = info.adjfaces[static_cast<std::size_t>(e)];
        if (g < 0 || static_cast<std::size_t>(g) >= num_faces || !filled[g]) continue;
        int ge = info.adjedges[static_cast<std::size_t>(e)] & 3;
        sum += edges[g].mean[ge];
        ++count;
      }
      if (count) {
        round.emplace_back(f, static_cast<float>(sum / count));
      } else {
        next.push_back(f);
      }
    }
    if (round.empty()) break;
    for (auto [f, value] : round) {
      filled[f] = 1;
      for (float& m : edges[f].mean) m = value;
      result.faces.push_back(f);
      result.values.push_back(value);
    }
    pending = std::move(next);
  }
  result.unreachable = pending.size();
  return result;
}

}  // namespace dispex::extract
