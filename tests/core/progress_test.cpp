#include "core/progress.h"

#include <gtest/gtest.h>

#include "core/content_hash.h"
#include "core/system.h"

namespace dispex {
namespace {

TEST(Progress, FormatsBarCountsRateAndEta) {
  EXPECT_EQ(Progress::Format("extract", 50, 100, "faces", 10.0, 10),
            "extract [#####     ] 50/100 faces 5/s ETA 10s");
  EXPECT_EQ(Progress::Format("extract", 100, 100, "faces", 125.0, 4),
            "extract [####] 100/100 faces 1/s in 2m05s");
  EXPECT_EQ(Progress::Format("x", 0, 10, "f", 0.0, 2), "x [  ] 0/10 f 0/s ETA --");
}

TEST(Progress, DisabledDrawsNothingAndCounts) {
  Progress p("x", 10, "faces", false);
  p.Advance(3);
  p.Advance();
  EXPECT_EQ(p.done(), 4u);
  p.Finish();
}

TEST(Progress, CountsIntoTheProgramsCounter) {
  ProgressCounter counter;
  counter.done = 99;
  Progress p("x", 10, "faces", false, &counter);
  EXPECT_EQ(counter.done.load(), 0u);
  EXPECT_EQ(counter.total.load(), 10u);
  p.Advance(3);
  p.Advance();
  EXPECT_EQ(counter.done.load(), 4u);
  EXPECT_EQ(p.done(), 4u);
}

TEST(ContentHash, MatchesKnownCrc32) {
  // The standard CRC-32 check value.
  EXPECT_EQ(Crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(Crc32(""), 0u);
}

TEST(System, ReportsMemory) {
  EXPECT_GT(PeakResidentBytes(), 0u);
  EXPECT_GT(AvailableMemoryBytes(), 0u);
}

}  // namespace
}  // namespace dispex
