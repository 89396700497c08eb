// view_test_map BASE OUT.ptx: the map the browser test shows (browser_test.py). Ptex face 0
// holds a constant +0.1, face 1 a constant -0.1, face 2 8 x 8 and face 3 64 x 64 texels of a
// faint ripple (+-0.001), every other face a constant 0; dispex:tolerance 0.01, and the base
// mesh's meta data.
#include <cmath>
#include <cstdio>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"

namespace {

int Fail(const dispex::Status& status) {
  std::fprintf(stderr, "view_test_map: %s\n", status.message().c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace dispex;
  if (argc != 3) {
    std::fprintf(stderr, "usage: view_test_map BASE OUT.ptx\n");
    return 2;
  }
  auto base = ReadMesh(argv[1]);
  if (!base.ok()) return Fail(base.status());
  auto surface = LimitSurface::Build(*base);
  if (!surface.ok()) return Fail(surface.status());
  std::vector<PtexFaceInfo> faces = PtexFaceTable(*surface);
  auto writer = PtexWriter::Create(argv[2], PtexWriterOptions{}, static_cast<int>(faces.size()));
  if (!writer.ok()) return Fail(writer.status());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    PtexFaceInfo info = faces[f];
    const int log2 = f == 2 ? 3 : f == 3 ? 6 : 0;
    info.ulog2 = info.vlog2 = static_cast<std::int8_t>(log2);
    const int res = 1 << log2;
    std::vector<float> texels(static_cast<std::size_t>(res) * res, 0.0f);
    if (f == 0) texels[0] = 0.1f;
    if (f == 1) texels[0] = -0.1f;
    if (log2 > 0) {
      for (int j = 0; j < res; ++j) {
        for (int i = 0; i < res; ++i) {
          texels[static_cast<std::size_t>(j) * res + i] =
              0.001f *
              static_cast<float>(std::sin(6.0 * (i + 0.5) / res) * std::cos(5.0 * j / res));
        }
      }
    }
    Status st = writer->SetFace(PtexFaceId(static_cast<std::int32_t>(f)), info, texels);
    if (!st.ok()) return Fail(st);
  }
  const double tolerance = 0.01;
  Status st = writer->AddMetaData("dispex:tolerance", std::span(&tolerance, 1));
  if (st.ok()) st = AddMeshMetaData(*writer, *base);
  if (st.ok()) st = writer->Finish();
  if (!st.ok()) return Fail(st);
  return 0;
}
