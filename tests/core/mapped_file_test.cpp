#include "core/mapped_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

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

// The OBJ reader counts from reads of fd() while it parses the map: a new file renamed over
// the path (how pipelines re-export) must not be what fd() reads. Moving keeps the one fd.
TEST(MappedFile, FdReadsTheMappedFileAfterANewOneIsRenamedOverIt) {
  fs::path dir = fs::temp_directory_path() / ("dispex_map_fd_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path file = dir / "sculpt.obj";
  std::ofstream(file) << "v 1 2 3\n";
  auto opened = MappedFile::Open(file.string());
  ASSERT_TRUE(opened.ok()) << opened.status().message();
  MappedFile mapped = std::move(*opened);
  std::ofstream(dir / "new.obj") << "v 9 9 9 9 9\n";
  fs::rename(dir / "new.obj", file);
  char bytes[8] = {};
  ASSERT_GE(mapped.fd(), 0);
  ASSERT_EQ(::pread(mapped.fd(), bytes, sizeof bytes, 0), 8);
  EXPECT_EQ(std::string(bytes, 8), "v 1 2 3\n");
  EXPECT_EQ(mapped.view(), "v 1 2 3\n");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dispex
