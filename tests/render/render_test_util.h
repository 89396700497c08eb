// Helpers of the render tests: temporary folders, small cages and Ptex maps written on the
// spot, pixel statistics, and running the dispex binary.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/ptex.h"
#include "dispex/render.h"
#include "dispex/vector_space.h"

namespace dispex::render_test {

namespace fs = std::filesystem;

using testing::CommandResult;
using testing::DataPath;
using testing::RunDispex;
using testing::Slurp;
using testing::TempDir;

inline void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// An n x n grid of quads over [-1, 1]^2 in the XZ plane (y = 0), facing +y. Face (i, j) (i along
// x, j along z) is face i * n + j, with corners (x_i, z_j), (x_i, z_j+1), (x_i+1, z_j+1),
// (x_i+1, z_j): its u runs along +z and its v along +x, so (u, v) of face (i, j) is the point
// x = -1 + (i + v) * 2 / n, z = -1 + (j + u) * 2 / n.
inline std::string GridCageObj(int n) {
  std::ostringstream obj;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      obj << "v " << -1.0 + 2.0 * i / n << " 0 " << -1.0 + 2.0 * j / n << "\n";
    }
  }
  auto id = [n](int i, int j) { return i * (n + 1) + j + 1; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      obj << "f " << id(i, j) << " " << id(i, j + 1) << " " << id(i + 1, j + 1) << " "
          << id(i + 1, j) << "\n";
    }
  }
  return obj.str();
}

// Writes a 1-channel float Ptex map with `faces` faces of 2^log2 x 2^log2 texels, texel (i, j)
// of face f holding value(f, u, v) at its centre (u, v) = ((i + .5) / res, (j + .5) / res).
inline void WriteMap(const std::string& path, int faces, int log2,
                     const std::function<float(int, double, double)>& value) {
  auto writer = PtexWriter::Create(path, PtexWriterOptions{}, faces);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const int res = 1 << log2;
  std::vector<float> texels(static_cast<std::size_t>(res) * res);
  for (int f = 0; f < faces; ++f) {
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        texels[static_cast<std::size_t>(j) * res + i] = value(f, (i + 0.5) / res, (j + 0.5) / res);
      }
    }
    PtexFaceInfo info;
    info.ulog2 = info.vlog2 = static_cast<std::int8_t>(log2);
    Status st = writer->SetFace(PtexFaceId(f), info, texels);
    ASSERT_TRUE(st.ok()) << st.message();
  }
  Status st = writer->Finish();
  ASSERT_TRUE(st.ok()) << st.message();
}

// Writes a 3-channel float vector map in `space` (dispex:vector_space, dispex:channels, the
// space's edge filter mode) with `faces` faces of 2^log2 x 2^log2 texels, texel (i, j) of face
// f holding the channels value(f, u, v, c) at its centre, c = 0, 1, 2.
inline void WriteVectorMap(const std::string& path, VectorSpace space, int faces, int log2,
                           const std::function<void(int, double, double, float*)>& value) {
  PtexWriterOptions options;
  options.num_channels = 3;
  if (space != VectorSpace::kObject) options.edge_filter = PtexEdgeFilterMode::kTangentVector;
  auto writer = PtexWriter::Create(path, options, faces);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  ASSERT_TRUE(writer->AddMetaData(std::string(kVectorSpaceMetaKey), VectorSpaceName(space)).ok());
  ASSERT_TRUE(
      writer->AddMetaData(std::string(kVectorChannelsMetaKey), VectorSpaceChannels(space)).ok());
  const int res = 1 << log2;
  std::vector<float> texels(3 * static_cast<std::size_t>(res) * res);
  for (int f = 0; f < faces; ++f) {
    for (int j = 0; j < res; ++j) {
      for (int i = 0; i < res; ++i) {
        value(f, (i + 0.5) / res, (j + 0.5) / res,
              &texels[3 * (static_cast<std::size_t>(j) * res + i)]);
      }
    }
    PtexFaceInfo info;
    info.ulog2 = info.vlog2 = static_cast<std::int8_t>(log2);
    Status st = writer->SetFace(PtexFaceId(f), info, texels);
    ASSERT_TRUE(st.ok()) << st.message();
  }
  Status st = writer->Finish();
  ASSERT_TRUE(st.ok()) << st.message();
}

inline int MaxChannelDifference(const std::array<std::uint8_t, 3>& a,
                                const std::array<std::uint8_t, 3>& b) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
  return d;
}

}  // namespace dispex::render_test
