// `dispex extract --progress-lines`: progress for programs that drive the command (the Blender
// add-on), with stderr a pipe: lines "progress extract DONE/TOTAL", done never going back, at
// most about ten a second plus the final one, which says done == total; without the flag no
// such line on a pipe.
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>
#include <string>
#include <vector>

#include "../extract/e2e_support.h"
#include "dispex/verify.h"

namespace dispex {
namespace {

using testing::DataPath;
using testing::MatchWhole;
using testing::RunDispex;
using testing::SculptOptions;
using testing::TempDir;

constexpr std::uint64_t kSpotPtexFaces = 252;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class ProgressLines : public ::testing::Test {
 protected:
  void SetUp() override {
    cage_ = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
    MakeSculptOptions make = SculptOptions(cage_, dir_ / "sculpt.obj", 3, Pattern::kDetail, 0.005);
    ASSERT_TRUE(MakeSculpt(make).ok());
    sculpt_ = make.output_path;
  }
  std::string Extract(const std::string& more) const {
    return "extract " + cage_ + " " + sculpt_ + " -o " + (dir_ / "map.ptx") + " " + more;
  }

  TempDir dir_;
  std::string cage_, sculpt_;
};

TEST_F(ProgressLines, PipedLinesCountTheFacesToTheEnd) {
  // Rays at 128 samples a side: about a second on 2 cores, so several lines.
  const auto start = std::chrono::steady_clock::now();
  const auto r = RunDispex(Extract("--method rays --oversample 128 -q --progress-lines"), dir_);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string line_format = "progress extract ([0-9]+)/([0-9]+)";
  const std::vector<std::string> lines = Lines(r.err);
  ASSERT_FALSE(lines.empty()) << "no progress line";
  std::uint64_t last_done = 0, last_total = 0;
  for (const std::string& line : lines) {  // -q: nothing but the progress lines
    const auto m = MatchWhole(line, line_format);
    ASSERT_TRUE(m) << "not a progress line: " << line;
    const std::uint64_t done = std::stoull((*m)[1]), total = std::stoull((*m)[2]);
    EXPECT_EQ(total, kSpotPtexFaces) << line;
    EXPECT_LE(done, total) << line;
    EXPECT_GE(done, last_done) << line << ": done went back";
    last_done = done;
    last_total = total;
  }
  EXPECT_EQ(last_done, last_total) << "the last line: " << lines.back();
  // Ten a second and the final one (a line only when the count moved).
  EXPECT_LE(static_cast<double>(lines.size()), 10 * seconds + 2)
      << lines.size() << " lines in " << seconds << " s";
  std::printf("%zu progress lines in %.2f s, the last: %s\n", lines.size(), seconds,
              lines.back().c_str());
}

TEST_F(ProgressLines, OnlyWhenAsked) {
  // Without the flag a pipe gets the summary and no progress of any kind.
  auto r = RunDispex(Extract(""), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("progress "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "a progress bar on a pipe: " << r.err;
  EXPECT_EQ(r.err.rfind("dispex: ", 0), 0u) << r.err;
  // With it and without -q: the lines, then the summary.
  r = RunDispex(Extract("--progress-lines"), dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> lines = Lines(r.err);
  std::size_t progress = 0;
  while (progress < lines.size() && lines[progress].rfind("progress extract ", 0) == 0) {
    ++progress;
  }
  ASSERT_GT(progress, 0u) << r.err;
  EXPECT_EQ(lines[progress - 1], "progress extract 252/252") << r.err;
  ASSERT_LT(progress, lines.size()) << "no summary: " << r.err;
  EXPECT_EQ(lines[progress].rfind("dispex: ", 0), 0u) << r.err;
  for (std::size_t i = progress; i < lines.size(); ++i) {
    EXPECT_NE(lines[i].rfind("progress ", 0), 0u) << "a progress line after the summary";
  }
}

}  // namespace
}  // namespace dispex
