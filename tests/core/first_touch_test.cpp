#include "core/first_touch.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

namespace dispex {
namespace {

// Large enough that the new storage is touched (kFirstTouchBytes), not only reserved.
constexpr std::size_t kLarge = 3 * kFirstTouchBytes / sizeof(std::int32_t) + 123;

TEST(FirstTouch, ReserveTouchedKeepsTheElementsAndTouchesOnlyBeyondThem) {
  std::vector<std::int32_t> v(1000);
  std::iota(v.begin(), v.end(), 1);
  const std::int32_t* before = v.data();
  ReserveTouched(v, kLarge);
  EXPECT_GE(v.capacity(), kLarge);
  ASSERT_EQ(v.size(), 1000u);
  EXPECT_NE(v.data(), before);  // grown: the elements were moved into the new storage
  for (std::size_t k = 0; k < v.size(); ++k) ASSERT_EQ(v[k], static_cast<std::int32_t>(k + 1));
  v.resize(kLarge, 5);
  EXPECT_EQ(v[999], 1000);
  EXPECT_EQ(v[1000], 5);
  EXPECT_EQ(v.back(), 5);
  // Room already there: nothing is reallocated.
  const std::int32_t* grown = v.data();
  ReserveTouched(v, kLarge / 2);
  EXPECT_EQ(v.data(), grown);
  EXPECT_EQ(v.size(), kLarge);
}

TEST(FirstTouch, AssignTouchedReplacesTheContents) {
  std::vector<std::uint16_t> small(7, 9);
  AssignTouched(small, 3, std::uint16_t{2});
  EXPECT_EQ(small, std::vector<std::uint16_t>(3, 2));
  std::vector<float> large(10, 1.0f);
  AssignTouched(large, kLarge, -0.5f);
  ASSERT_EQ(large.size(), kLarge);
  for (float x : large) ASSERT_EQ(x, -0.5f);
}

constexpr std::size_t kPage = 4096;

// Page faults the calling thread has taken (those the kernel populates for it are not counted).
long ThreadFaults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt + usage.ru_majflt;
}

// One byte of every page of [p + first * kPage, p + pages * kPage) written, or summed. Not
// instrumented: a sanitizer's own shadow memory would fault on the way and be counted.
[[gnu::no_sanitize_address, gnu::no_sanitize_thread, gnu::noinline]] void WritePages(
    unsigned char* p, std::size_t first, std::size_t pages) {
  for (std::size_t k = first; k < pages; ++k)
    static_cast<volatile unsigned char*>(p)[k * kPage] = 1;
}
[[gnu::no_sanitize_address, gnu::no_sanitize_thread, gnu::noinline]] unsigned SumPages(
    const unsigned char* p, std::size_t pages) {
  unsigned sum = 0;
  for (std::size_t k = 0; k < pages; ++k)
    sum += static_cast<const volatile unsigned char*>(p)[k * kPage];
  return sum;
}

// Which pages of [p, p + pages * kPage) are resident.
std::vector<bool> Resident(void* p, std::size_t pages) {
  std::vector<unsigned char> in(pages);
  EXPECT_EQ(mincore(p, pages * kPage, in.data()), 0);
  std::vector<bool> out(pages);
  for (std::size_t k = 0; k < pages; ++k) out[k] = (in[k] & 1) != 0;
  return out;
}

// Anonymous memory in 4 KiB pages (a transparent huge page would fault in 512 at once).
void* MapPages(std::size_t pages) {
  void* map =
      mmap(nullptr, pages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (map != MAP_FAILED) madvise(map, pages * kPage, MADV_NOHUGEPAGE);
  return map;
}

TEST(FirstTouch, PopulatePagesFaultsInEveryPageTheRangeReaches) {
  ASSERT_EQ(sysconf(_SC_PAGESIZE), static_cast<long>(kPage));
  constexpr std::size_t kPages = 512;
  void* map = MapPages(kPages);
  ASSERT_NE(map, MAP_FAILED);
  auto* bytes = static_cast<unsigned char*>(map);
  // A range starting inside page 1 and ending inside page 3: pages 1 to 3.
  if (!PopulatePages(bytes + kPage + 100, 2 * kPage)) {
    munmap(map, kPages * kPage);
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_WRITE (Linux 5.14)";
  }
  std::vector<bool> resident = Resident(map, kPages);
  EXPECT_FALSE(resident[0]);
  EXPECT_TRUE(resident[1] && resident[2] && resident[3]);
  EXPECT_FALSE(resident[4]);
  // The rest, then written: no page faults on the way.
  EXPECT_TRUE(PopulatePages(bytes + 4 * kPage, (kPages - 4) * kPage));
  const long before = ThreadFaults();
  WritePages(bytes, 4, kPages);
  EXPECT_LT(ThreadFaults() - before, 8);
  // Without it, each page faults on its first write.
  void* other = MapPages(kPages);
  ASSERT_NE(other, MAP_FAILED);
  const long again = ThreadFaults();
  WritePages(static_cast<unsigned char*>(other), 0, kPages);
  EXPECT_GE(ThreadFaults() - again, static_cast<long>(kPages) / 2);
  munmap(other, kPages * kPage);
  munmap(map, kPages * kPage);
}

TEST(FirstTouch, TouchPagesLeavesTheRangeResident) {
  constexpr std::size_t kPages = 1024;
  void* map = MapPages(kPages);
  ASSERT_NE(map, MAP_FAILED);
  TouchPages(static_cast<unsigned char*>(map) + 10, (kPages - 1) * kPage - 10);
  const std::vector<bool> resident = Resident(map, kPages);
  for (std::size_t k = 0; k + 1 < kPages; ++k) ASSERT_TRUE(resident[k]) << "page " << k;
  EXPECT_FALSE(resident[kPages - 1]);
  munmap(map, kPages * kPage);
}

TEST(FirstTouch, PopulateMappedPagesMapsAFilesPages) {
  constexpr std::size_t kPages = 1024;
  char path[] = "/tmp/dispex-populate-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  unlink(path);
  const std::string page(kPage, 'x');
  for (std::size_t k = 0; k < kPages; ++k) {
    ASSERT_EQ(write(fd, page.data(), kPage), static_cast<ssize_t>(kPage));
  }
  // Without it, reading faults (at least once per 16 pages, the kernel's fault-around).
  void* plain = mmap(nullptr, kPages * kPage, PROT_READ, MAP_PRIVATE, fd, 0);
  ASSERT_NE(plain, MAP_FAILED);
  long before = ThreadFaults();
  EXPECT_EQ(SumPages(static_cast<const unsigned char*>(plain), kPages), kPages * 'x');
  const long plain_faults = ThreadFaults() - before;
  munmap(plain, kPages * kPage);
  if (plain_faults < 8) {
    close(fd);
    GTEST_SKIP() << "this kernel maps a file's cached pages in " << plain_faults
                 << " faults: too few to tell populated pages from others";
  }

  void* map = mmap(nullptr, kPages * kPage, PROT_READ, MAP_PRIVATE, fd, 0);
  ASSERT_NE(map, MAP_FAILED);
  close(fd);
  if (!PopulateMappedPages(map, kPages * kPage)) {
    munmap(map, kPages * kPage);
    GTEST_SKIP() << "this kernel has no MADV_POPULATE_READ (Linux 5.14)";
  }
  before = ThreadFaults();
  EXPECT_EQ(SumPages(static_cast<const unsigned char*>(map), kPages), kPages * 'x');
  EXPECT_LT(ThreadFaults() - before, 4);
  munmap(map, kPages * kPage);
}

}  // namespace
}  // namespace dispex
