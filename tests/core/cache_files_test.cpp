// A cache folder kept within a size: the least recently written files of one prefix go first,
// never the file just written, never another prefix's; stale temporary files go.
#include "core/cache_files.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

namespace dispex {
namespace {

namespace fs = std::filesystem;

TEST(CacheFiles, LeastRecentlyWrittenGoFirst) {
  const fs::path dir = fs::path(::testing::TempDir()) / "dispex_cache_files_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto now = fs::file_time_type::clock::now();
  // rays-0 oldest ... rays-4 newest, 100 bytes each; an adjacency file; temporary files.
  auto make = [&](const std::string& name, int hours_ago) {
    std::ofstream(dir / name, std::ios::binary) << std::string(100, 'x');
    fs::last_write_time(dir / name, now - std::chrono::hours(hours_ago));
  };
  for (int i = 0; i < 5; ++i) make("rays-" + std::to_string(i) + ".bin", 10 - i);
  make("adjacency-0.bin", 20);
  make("rays-9.bin.tmp.abc", 2);
  make("rays-8.bin.tmp.def", 0);
  // Room for two and a half: all but the two newest go, except the one kept.
  EvictCacheFiles(dir.string(), "rays-", 250, (dir / "rays-0.bin").string());
  EXPECT_TRUE(fs::exists(dir / "rays-0.bin")) << "the file just written is kept";
  EXPECT_FALSE(fs::exists(dir / "rays-1.bin"));
  EXPECT_FALSE(fs::exists(dir / "rays-2.bin"));
  EXPECT_TRUE(fs::exists(dir / "rays-3.bin"));
  EXPECT_TRUE(fs::exists(dir / "rays-4.bin"));
  EXPECT_TRUE(fs::exists(dir / "adjacency-0.bin")) << "another prefix's file";
  EXPECT_FALSE(fs::exists(dir / "rays-9.bin.tmp.abc")) << "a killed run's temporary file";
  EXPECT_TRUE(fs::exists(dir / "rays-8.bin.tmp.def")) << "a running write's temporary file";
  // A folder that is not there: nothing happens.
  EvictCacheFiles((dir / "missing").string(), "rays-", 0, "");
  fs::remove_all(dir);
}

std::optional<std::string> ReadRecord(const std::string& path, std::string_view magic) {
  const std::optional<CacheRecord> read = ReadCacheRecord(path, magic);
  if (!read) return std::nullopt;
  return std::string(read->bytes);
}

// A record reads back as written (a folder made for it), and stays as it was read when the file
// is replaced; a record cut short, changed in one byte, of another magic, empty, a folder or
// missing reads as none.
TEST(CacheFiles, RecordsReadBackWholeOrNotAtAll) {
  const fs::path dir = fs::path(::testing::TempDir()) / "dispex_cache_records_test";
  fs::remove_all(dir);
  const std::string path = (dir / "folder" / "record.bin").string();
  std::string bytes = "DXTEST01";
  for (int i = 0; i < 1000; ++i) bytes += static_cast<char>(i * 7);
  ASSERT_TRUE(WriteCacheRecord(path, bytes));
  {
    const std::optional<CacheRecord> read = ReadCacheRecord(path, "DXTEST01");
    ASSERT_TRUE(read.has_value());
    EXPECT_EQ(read->bytes, bytes);
    ASSERT_TRUE(WriteCacheRecord(path, "DXTEST01 another record"));
    EXPECT_EQ(read->bytes, bytes);
    EXPECT_EQ(ReadRecord(path, "DXTEST01"), "DXTEST01 another record");
    ASSERT_TRUE(WriteCacheRecord(path, bytes));
  }
  EXPECT_EQ(ReadRecord(path, "DXTEST02"), std::nullopt);
  EXPECT_EQ(ReadRecord((dir / "missing.bin").string(), "DXTEST01"), std::nullopt);
  EXPECT_EQ(ReadRecord((dir / "folder").string(), "DXTEST01"), std::nullopt);
  std::ofstream(dir / "empty.bin").close();
  EXPECT_EQ(ReadRecord((dir / "empty.bin").string(), "DXTEST01"), std::nullopt);
  const std::uintmax_t size = fs::file_size(path);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(500);
    f.put('!');
  }
  EXPECT_EQ(ReadRecord(path, "DXTEST01"), std::nullopt) << "a changed byte";
  ASSERT_TRUE(WriteCacheRecord(path, bytes));
  fs::resize_file(path, size - 1);
  EXPECT_EQ(ReadRecord(path, "DXTEST01"), std::nullopt) << "cut short";
  // An unwritable place: false, nothing left behind.
  EXPECT_FALSE(WriteCacheRecord((dir / "folder" / "record.bin" / "below.bin").string(), bytes));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dispex
