// Interruption: SIGINT and SIGTERM at random moments of an extraction stop it promptly, exit
// 130 / 143, leave no temporary file, and leave an existing output untouched.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <random>
#include <thread>

#include "../extract/e2e_support.h"
#include "dispex/verify.h"

extern char** environ;

namespace dispex {
namespace {

using testing::DataPath;
using testing::SculptOptions;
using testing::TempDir;
namespace fs = std::filesystem;

TEST(Interrupt, SignalsStopExtractionCleanly) {
  TempDir dir;
  const std::string cage = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  MakeSculptOptions make = SculptOptions(cage, dir / "sculpt.obj", 4, Pattern::kDetail, 0.005);
  ASSERT_TRUE(MakeSculpt(make).ok());
  const std::string target = dir / "map.ptx";
  const std::string old_content = "an older map that must survive";

  std::mt19937 rng(20261121);
  int interrupted = 0, finished = 0, handled = 0;
  for (int trial = 0; trial < 12; ++trial) {
    std::ofstream(target) << old_content;
    std::vector<std::string> args = {
        DISPEX_EXE, "extract", cage, make.output_path, "-o", target, "--oversample", "128", "-q"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    ASSERT_EQ(::posix_spawn(&pid, DISPEX_EXE, nullptr, nullptr, argv.data(), environ), 0);
    const int sig = trial % 2 ? SIGTERM : SIGINT;
    std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 1500));
    auto sent = std::chrono::steady_clock::now();
    ::kill(pid, sig);
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    // A signal that comes before dispex installs its handlers (the process is still starting,
    // slow under sanitizers) terminates it by default, before any file was opened.
    const bool before_handlers = WIFSIGNALED(status) && WTERMSIG(status) == sig;
    ASSERT_TRUE(WIFEXITED(status) || before_handlers) << "killed by signal " << WTERMSIG(status);
    const int code = before_handlers ? 128 + sig : WEXITSTATUS(status);
    if (code == 0) {
      ++finished;  // the signal came after the file was complete: a new map is there
      EXPECT_NE(testing::Slurp(target), old_content);
    } else {
      ++interrupted;
      EXPECT_EQ(code, 128 + sig);
      EXPECT_LT(seconds, 1.0) << "took " << seconds << " s to stop";
      handled += !before_handlers;
      EXPECT_EQ(testing::Slurp(target), old_content) << "the existing map was touched";
    }
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      EXPECT_EQ(entry.path().string().find(".tmp."), std::string::npos)
          << "temporary file left: " << entry.path();
    }
  }
  EXPECT_GT(handled, 0) << "no signal reached dispex's handlers";
  std::printf("interrupted %d, finished before the signal %d\n", interrupted, finished);
}

}  // namespace
}  // namespace dispex
