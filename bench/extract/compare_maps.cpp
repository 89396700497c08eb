// Two maps of the same base, face by face: faces whose resolutions differ, texels that differ
// and the largest |difference|. Exit 0 when every face has the same resolution.
//   compare_maps A.ptx B.ptx
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "dispex/ptex.h"

using namespace dispex;

int main(int argc, char** argv) {
  if (argc != 3) {
    fmt::print(stderr, "usage: compare_maps A.ptx B.ptx\n");
    return 2;
  }
  auto a = PtexFile::Open(argv[1]);
  auto b = PtexFile::Open(argv[2]);
  if (!a.ok() || !b.ok()) {
    fmt::print(stderr, "compare_maps: {}\n", a.ok() ? b.status().message() : a.status().message());
    return 2;
  }
  if (a->num_faces() != b->num_faces()) {
    fmt::print("maps: {} and {} faces\n", a->num_faces(), b->num_faces());
    return 1;
  }
  std::size_t resolutions = 0, texels = 0, differ = 0;
  double largest = 0;
  std::vector<float> ta, tb;
  for (int f = 0; f < a->num_faces(); ++f) {
    if (!a->ReadFace(PtexFaceId(f), 0, ta).ok() || !b->ReadFace(PtexFaceId(f), 0, tb).ok()) {
      fmt::print(stderr, "compare_maps: face {} unreadable\n", f);
      return 2;
    }
    if (ta.size() != tb.size()) {
      ++resolutions;
      continue;
    }
    for (std::size_t k = 0; k < ta.size(); ++k) {
      ++texels;
      differ += std::memcmp(&ta[k], &tb[k], sizeof(float)) != 0;
      largest = std::max(largest, std::fabs(double(ta[k]) - double(tb[k])));
    }
  }
  fmt::print("maps: {} faces, {} of other resolution; {} of {} texels differ, by at most {:.3g}\n",
             a->num_faces(), resolutions, differ, texels, largest);
  return resolutions == 0 ? 0 : 1;
}
