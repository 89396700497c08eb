#include "extract/incremental/shard_plan.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/check.h"

namespace dispex::extract {
namespace {

// x's low 21 bits spread to every third bit.
std::uint64_t Spread(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

}  // namespace

std::vector<std::int32_t> ShardOrder(const Mesh& base, const LimitSurface& surface) {
  DISPEX_CHECK(static_cast<std::size_t>(surface.num_base_faces()) == base.num_faces());
  const auto n = static_cast<std::size_t>(surface.num_ptex_faces());
  // A quad's centroid; for the sub-face k of an n-gon, the middle of its corner k and its
  // centroid.
  std::vector<std::array<double, 3>> centres(n);
  std::array<double, 3> lower{INFINITY, INFINITY, INFINITY}, upper{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t f = 0; f < n; ++f) {
    const PtexFaceId face(static_cast<int>(f));
    const auto corners = base.face(static_cast<std::size_t>(surface.base_face(face).value));
    std::array<double, 3> c{0, 0, 0};
    for (std::int32_t v : corners) {
      const Float3& p = base.positions[static_cast<std::size_t>(v)];
      c = {c[0] + p.x, c[1] + p.y, c[2] + p.z};
    }
    for (double& x : c) x /= static_cast<double>(corners.size());
    if (corners.size() != 4) {
      const Float3& p = base.positions[static_cast<std::size_t>(
          corners[static_cast<std::size_t>(surface.sub_face(face))])];
      c = {(c[0] + p.x) / 2, (c[1] + p.y) / 2, (c[2] + p.z) / 2};
    }
    centres[f] = c;
    for (int k = 0; k < 3; ++k) {
      lower[k] = std::min(lower[k], c[k]);
      upper[k] = std::max(upper[k], c[k]);
    }
  }
  std::vector<std::uint64_t> code(n);
  for (std::size_t f = 0; f < n; ++f) {
    std::uint64_t c = 0;
    for (int k = 0; k < 3; ++k) {
      const double span = upper[k] - lower[k];
      const double unit = span > 0 ? (centres[f][k] - lower[k]) / span : 0;
      c |= Spread(static_cast<std::uint64_t>(std::clamp(unit, 0.0, 1.0) * 0x1fffff)) << k;
    }
    code[f] = c;
  }
  std::vector<std::int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    return code[ua] != code[ub] ? code[ua] < code[ub] : a < b;
  });
  return order;
}

ShardRange PlanShard(const LimitSurface& surface, const OversamplingPlan& plan,
                     const FaceKeys& keys, std::span<const std::int32_t> order, int index,
                     int count) {
  const auto n = static_cast<std::size_t>(surface.num_ptex_faces());
  // cumulative[i]: the cost of the faces before order[i].
  std::vector<std::int64_t> cumulative(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto f = static_cast<std::size_t>(order[i]);
    std::int64_t cost = 0;
    if (!surface.is_hole(PtexFaceId(static_cast<int>(f)))) {
      const std::int64_t side = std::int64_t{1} << plan.log2[f];
      cost = side * side + keys.reach_faces[f];
    }
    cumulative[i + 1] = cumulative[i] + cost;
  }
  const std::int64_t total = cumulative[n];
  // The first face boundary whose running cost reaches k/count of the total (exact integers).
  auto boundary = [&](int k) -> std::int64_t {
    if (k <= 0) return 0;
    if (k >= count) return static_cast<std::int64_t>(n);
    // At most about 10^14 (a million faces, each reaching 10^8 sculpt faces) times the count.
    const std::int64_t target = total * k;
    std::size_t lo = 0, hi = n;
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      if (cumulative[mid] * count >= target) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    return static_cast<std::int64_t>(lo);
  };
  ShardRange range;
  range.begin = boundary(index - 1);
  range.end = boundary(index);
  if (total > 0) {
    range.cost_fraction = static_cast<double>(cumulative[static_cast<std::size_t>(range.end)] -
                                              cumulative[static_cast<std::size_t>(range.begin)]) /
                          static_cast<double>(total);
  }
  return range;
}

}  // namespace dispex::extract
