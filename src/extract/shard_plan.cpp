#include "extract/shard_plan.h"

#include <vector>

namespace dispex::extract {

ShardRange PlanShard(const LimitSurface& surface, const OversamplingPlan& plan,
                     const FaceKeys& keys, int index, int count) {
  const auto n = static_cast<std::size_t>(surface.num_ptex_faces());
  // cumulative[f]: the cost of the faces before f.
  std::vector<std::int64_t> cumulative(n + 1, 0);
  for (std::size_t f = 0; f < n; ++f) {
    std::int64_t cost = 0;
    if (!surface.is_hole(PtexFaceId(static_cast<int>(f)))) {
      const std::int64_t side = std::int64_t{1} << plan.log2[f];
      cost = side * side + keys.reach_faces[f];
    }
    cumulative[f + 1] = cumulative[f] + cost;
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
