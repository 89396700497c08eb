#include "dispex/status.h"

#include <gtest/gtest.h>

#include "dispex/ids.h"

namespace dispex {
namespace {

StatusOr<int> Half(int x) {
  if (x % 2) return Status::Error("odd: " + std::to_string(x));
  return x / 2;
}

StatusOr<int> Quarter(int x) {
  DISPEX_ASSIGN_OR_RETURN(int half, Half(x));
  DISPEX_ASSIGN_OR_RETURN(int quarter, Half(half));
  return quarter;
}

Status CheckEven(int x) {
  DISPEX_RETURN_IF_ERROR(Half(x).status());
  return Status::Ok();
}

TEST(Status, OkAndError) {
  EXPECT_TRUE(Status::Ok().ok());
  Status e = Status::Error("bad");
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message(), "bad");
  EXPECT_EQ(e.WithPrefix("file.obj").message(), "file.obj: bad");
  EXPECT_TRUE(Status::Ok().WithPrefix("x").ok());
}

TEST(StatusOr, PropagatesTheFirstError) {
  EXPECT_EQ(Quarter(8).value(), 2);
  EXPECT_EQ(Quarter(6).status().message(), "odd: 3");
  EXPECT_EQ(Quarter(5).status().message(), "odd: 5");
  EXPECT_TRUE(CheckEven(4).ok());
  EXPECT_FALSE(CheckEven(3).ok());
}

TEST(Ids, AreDistinctTypesAndOrdered) {
  static_assert(!std::is_convertible_v<BaseFaceId, PtexFaceId>);
  static_assert(!std::is_convertible_v<int, PtexFaceId>);
  EXPECT_LT(PtexFaceId(1), PtexFaceId(2));
  EXPECT_FALSE(PtexFaceId().valid());
  EXPECT_TRUE(BaseFaceId(0).valid());
}

}  // namespace
}  // namespace dispex
