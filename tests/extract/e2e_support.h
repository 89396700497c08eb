// Shared helpers of the end-to-end tests (extract, verify, cli, render): test data paths,
// temporary folders, running the dispex binary, reading files whole.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dispex/verify.h"

namespace dispex::testing {

namespace fs = std::filesystem;

inline std::string DataPath(const std::string& relative) {
  return std::string(DISPEX_TEST_DATA_DIR) + "/" + relative;
}

// A ground-truth sculpt of `cage`: refined `levels` times, displaced by `pattern`.
inline MakeSculptOptions SculptOptions(const std::string& cage, const std::string& output,
                                       int levels, Pattern pattern, double amplitude) {
  MakeSculptOptions options;
  options.cage_path = cage;
  options.output_path = output;
  options.levels = levels;
  options.pattern = pattern;
  options.amplitude = amplitude;
  return options;
}

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';  // parameterised tests
    }
    path_ = fs::temp_directory_path() / ("dispex_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

// Runs the dispex binary with `args` (already shell-quoted where needed).
inline CommandResult RunDispex(const std::string& args, const TempDir& dir) {
  std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string command = std::string(DISPEX_EXE) + " " + args + " >" + out + " 2>" + err;
  int status = std::system(command.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = Slurp(out);
  r.err = Slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

}  // namespace dispex::testing
