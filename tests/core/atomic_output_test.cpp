#include "core/atomic_output.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace dispex {
namespace {

namespace fs = std::filesystem;

class AtomicOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dispex_atomic_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static std::string Slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  std::size_t FileCount() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {}));
  }

  fs::path dir_;
};

TEST_F(AtomicOutputTest, CommitReplacesTarget) {
  fs::path target = dir_ / "map.ptx";
  std::ofstream(target) << "old";
  auto out = AtomicOutput::Create(target.string());
  ASSERT_TRUE(out.ok()) << out.status().message();
  ASSERT_TRUE(out->Write("new data", 8).ok());
  EXPECT_EQ(Slurp(target), "old");  // untouched until the commit
  EXPECT_EQ(FileCount(), 2u);
  ASSERT_TRUE(out->Commit().ok());
  EXPECT_EQ(Slurp(target), "new data");
  EXPECT_EQ(FileCount(), 1u);
}

TEST_F(AtomicOutputTest, AbandonLeavesNothing) {
  fs::path target = dir_ / "map.ptx";
  {
    auto out = AtomicOutput::Create(target.string());
    ASSERT_TRUE(out.ok());
    ASSERT_TRUE(out->Write("partial", 7).ok());
  }
  EXPECT_FALSE(fs::exists(target));
  EXPECT_EQ(FileCount(), 0u);
}

TEST_F(AtomicOutputTest, SignalCleanupRemovesTemporaries) {
  fs::path target = dir_ / "map.ptx";
  auto out = AtomicOutput::Create(target.string());
  ASSERT_TRUE(out.ok());
  EXPECT_TRUE(fs::exists(out->temp_path()));
  RemoveTemporaryOutputs();
  EXPECT_FALSE(fs::exists(out->temp_path()));
}

TEST_F(AtomicOutputTest, MissingFoldersAreMadeAndRemovedWhenAbandoned) {
  const fs::path target = dir_ / "shot" / "maps" / "map.ptx";
  ASSERT_TRUE(CheckOutputFile(target.string()).ok());
  EXPECT_FALSE(fs::exists(dir_ / "shot"));  // the check makes nothing
  {
    auto out = AtomicOutput::Create(target.string());
    ASSERT_TRUE(out.ok()) << out.status().message();
    EXPECT_TRUE(fs::is_directory(dir_ / "shot" / "maps"));
  }
  EXPECT_FALSE(fs::exists(dir_ / "shot")) << "an abandoned output leaves no folder";
  auto out = AtomicOutput::Create(target.string());
  ASSERT_TRUE(out.ok());
  ASSERT_TRUE(out->Write("x", 1).ok());
  ASSERT_TRUE(out->Commit().ok());
  EXPECT_EQ(Slurp(target), "x");
}

TEST_F(AtomicOutputTest, OutputsThatCannotBeWrittenAreClearErrors) {
  auto dir = AtomicOutput::Create(dir_.string());
  ASSERT_FALSE(dir.ok());
  EXPECT_NE(dir.status().message().find("is a folder"), std::string::npos);
  std::ofstream(dir_ / "file.txt") << "x";
  const Status under_file = CheckOutputFile((dir_ / "file.txt" / "sub" / "map.ptx").string());
  ASSERT_FALSE(under_file.ok());
  EXPECT_NE(under_file.message().find("file.txt is not a folder"), std::string::npos)
      << under_file.message();
  const Status folder = CheckOutputFolder((dir_ / "file.txt").string());
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.message().find("is a file, not a folder"), std::string::npos);
  EXPECT_TRUE(CheckOutputFolder((dir_ / "new" / "tiles").string()).ok());
  EXPECT_EQ(FileCount(), 1u);
}

TEST_F(AtomicOutputTest, WriteFileAtomically) {
  fs::path target = dir_ / "a.txt";
  ASSERT_TRUE(WriteFileAtomically(target.string(), "abc", 3).ok());
  EXPECT_EQ(Slurp(target), "abc");
}

}  // namespace
}  // namespace dispex
