// Helpers of the render tests: temporary folders, small cages and Ptex maps written on the
// spot, pixel statistics, and running the dispex binary.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "dispex/render.h"

namespace dispex::render_test {

namespace fs = std::filesystem;

inline std::string DataPath(const std::string& relative) {
  return std::string(DISPEX_TEST_DATA_DIR) + "/" + relative;
}

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ =
        fs::temp_directory_path() / ("dispex_render_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

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

inline int MaxChannelDifference(const std::array<std::uint8_t, 3>& a,
                                const std::array<std::uint8_t, 3>& b) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a[c]) - int(b[c])));
  return d;
}

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs the dispex binary with `args` (already shell-quoted where needed).
inline CommandResult RunDispex(const std::string& args, const TempDir& dir) {
  const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = std::string(DISPEX_EXE) + " " + args + " >" + out + " 2>" + err;
  const int status = std::system(command.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = Slurp(out);
  r.err = Slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

}  // namespace dispex::render_test
