#include "core/mapped_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace dispex {
namespace {

namespace fs = std::filesystem;

TEST(MappedFile, MapsContentAndReportsMissingFilesAndDirectories) {
  fs::path dir = fs::temp_directory_path() / ("dispex_map_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path file = dir / "x.obj";
  std::ofstream(file) << "v 1 2 3\n";
  auto mapped = MappedFile::Open(file.string());
  ASSERT_TRUE(mapped.ok()) << mapped.status().message();
  EXPECT_EQ(mapped->view(), "v 1 2 3\n");

  fs::path empty = dir / "empty.obj";
  std::ofstream(empty).close();
  auto e = MappedFile::Open(empty.string());
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->size(), 0u);

  auto missing = MappedFile::Open((dir / "missing.obj").string());
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("missing.obj: no such file"), std::string::npos);

  auto directory = MappedFile::Open(dir.string());
  ASSERT_FALSE(directory.ok());
  EXPECT_NE(directory.status().message().find("is a directory"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dispex
