// Vector maps written by the tests themselves: a make-sculpt pattern's exact displacement D at
// every texel centre of every Ptex face, in any space, and wrong on purpose when asked.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "dispex/subdiv.h"
#include "dispex/vector_space.h"
#include "dispex/verify.h"

namespace dispex::testing {

struct PatternMapOptions {
  int log2 = 4;  // 2^log2 x 2^log2 texels per face
  // The map's space; nullopt: a scalar map holding h = D.N, what a map along the normal holds
  // at best.
  std::optional<VectorSpace> space = VectorSpace::kTangent;
  PtexDataType data_type = PtexDataType::kFloat;
  // Negative controls: the space the meta data names (default: `space`), channels 0 and 1
  // exchanged, every channel scaled (0: the zero map).
  std::optional<VectorSpace> label;
  bool swap_tangential = false;
  float scale = 1;
  // Channels 0 and 1 set to 0: in the tangent and parametric spaces D = (D.N) N, what a scalar
  // map of the same D moves a point by.
  bool drop_tangential = false;
};

// D at a limit point p with unit normal n.
using VectorField = std::function<void(const float p[3], const float n[3], double d[3])>;

// Writes to `path` the map of `field` on the limit surface of the cage at `cage_path`: texel
// (i, j) of each face holds D at the texel's centre, converted to the space's channels with
// the frame there (VectorToChannels), or D.N. A vector map carries dispex:vector_space,
// dispex:channels and the edge filter mode of its (labelled) space.
inline void WriteVectorFieldMap(const std::string& cage_path, const VectorField& field,
                                const std::string& path, const PatternMapOptions& o = {}) {
  auto cage = ReadMesh(cage_path);
  ASSERT_TRUE(cage.ok()) << cage.status().message();
  auto surface = LimitSurface::Build(*cage);
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  const std::optional<VectorSpace> label = o.label ? o.label : o.space;
  PtexWriterOptions options;
  options.data_type = o.data_type;
  options.num_channels = o.space ? 3 : 1;
  if (label && *label != VectorSpace::kObject) {
    options.edge_filter = PtexEdgeFilterMode::kTangentVector;
  }
  const int faces = surface->num_ptex_faces();
  auto writer = PtexWriter::Create(path, options, faces);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  if (label) {
    ASSERT_TRUE(
        writer->AddMetaData(std::string(kVectorSpaceMetaKey), VectorSpaceName(*label)).ok());
    ASSERT_TRUE(
        writer->AddMetaData(std::string(kVectorChannelsMetaKey), VectorSpaceChannels(*label)).ok());
  }
  std::vector<PtexFaceInfo> table = PtexFaceTable(*surface);
  LimitEvaluator evaluator(*surface);
  const int res = 1 << o.log2;
  const std::size_t texels = std::size_t(res) * res;
  std::vector<float> p(3 * texels), n(3 * texels), du(3 * texels), dv(3 * texels), values;
  for (int f = 0; f < faces; ++f) {
    PtexFaceInfo info = table[std::size_t(f)];
    if (surface->is_hole(PtexFaceId(f))) {
      const std::vector<float> zero(std::size_t(options.num_channels), 0.0f);
      ASSERT_TRUE(writer->SetConstantFace(PtexFaceId(f), info, zero).ok());
      continue;
    }
    info.ulog2 = info.vlog2 = static_cast<std::int8_t>(o.log2);
    ASSERT_TRUE(evaluator.EvaluateGridFrames(PtexFaceId(f), res, res, {p, n, du, dv}).ok());
    values.clear();
    for (std::size_t t = 0; t < texels; ++t) {
      double d[3];
      field(&p[3 * t], &n[3 * t], d);
      const Float3 vector{static_cast<float>(d[0]), static_cast<float>(d[1]),
                          static_cast<float>(d[2])};
      float c[3] = {static_cast<float>(d[0] * n[3 * t] + d[1] * n[3 * t + 1] + d[2] * n[3 * t + 2]),
                    0, 0};
      if (o.space) {
        const SurfaceFrame at{{du[3 * t], du[3 * t + 1], du[3 * t + 2]},
                              {dv[3 * t], dv[3 * t + 1], dv[3 * t + 2]},
                              {n[3 * t], n[3 * t + 1], n[3 * t + 2]}};
        VectorToChannels(*o.space, at, vector, c);
        if (o.swap_tangential) std::swap(c[0], c[1]);
        if (o.drop_tangential) c[0] = c[1] = 0;
      }
      for (int k = 0; k < options.num_channels; ++k) values.push_back(o.scale * c[k]);
    }
    Status st = writer->SetFace(PtexFaceId(f), info, values);
    ASSERT_TRUE(st.ok()) << st.message();
  }
  Status st = writer->Finish();
  ASSERT_TRUE(st.ok()) << st.message();
}

// The same for a make-sculpt pattern evaluated with `frame` (MakeSculptReport::frame): the
// map a perfect extraction would make at this resolution.
inline void WritePatternMap(const std::string& cage_path, Pattern pattern,
                            const PatternFrame& frame, const std::string& path,
                            const PatternMapOptions& o = {}) {
  WriteVectorFieldMap(
      cage_path,
      [&](const float p[3], const float n[3], double d[3]) {
        EvaluatePatternVector(pattern, frame, p, n, d);
      },
      path, o);
}

}  // namespace dispex::testing
