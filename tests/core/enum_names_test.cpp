#include "core/enum_names.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace dispex {
namespace {

enum class Two : std::uint8_t { kOn, kOff };
enum class Three : std::uint8_t { kGrey, kSigned, kVector };

constexpr auto kTwo = EnumTable<Two>({{Two::kOn, "on"}, {Two::kOff, "off"}});
constexpr auto kThree = EnumTable<Three>({
    {Three::kGrey, "grey"},
    {Three::kSigned, "signed"},
    {Three::kVector, "vector"},
    {Three::kGrey, "gray", kEnumAlias},
});

TEST(EnumNames, NamesEachValue) {
  EXPECT_EQ(EnumName(kTwo, Two::kOn), "on");
  EXPECT_EQ(EnumName(kTwo, Two::kOff), "off");
  EXPECT_EQ(EnumName(kThree, Three::kGrey), "grey");  // never the alias
  EXPECT_EQ(EnumName(kThree, static_cast<Three>(9)), "?");
  static_assert(EnumName(kThree, Three::kVector) == "vector");
}

TEST(EnumNames, ParsesNamesAndAliases) {
  EXPECT_EQ(ParseEnum(kTwo, "switch", "off").value(), Two::kOff);
  EXPECT_EQ(ParseEnum(kThree, "mode", "signed").value(), Three::kSigned);
  EXPECT_EQ(ParseEnum(kThree, "mode", "gray").value(), Three::kGrey);
  EXPECT_EQ(ParseEnum(kThree, "mode", "grey").value(), Three::kGrey);
}

TEST(EnumNames, OneMessageListingTheNamesButNotTheAliases) {
  const auto two = ParseEnum(kTwo, "switch", "maybe");
  ASSERT_FALSE(two.ok());
  EXPECT_EQ(two.status().message(), "unknown switch 'maybe' (expected on or off)");
  const auto three = ParseEnum(kThree, "mode", "colour");
  ASSERT_FALSE(three.ok());
  EXPECT_EQ(three.status().message(), "unknown mode 'colour' (expected grey, signed or vector)");
  EXPECT_EQ(ParseEnum(kThree, "mode", "").status().message(),
            "unknown mode '' (expected grey, signed or vector)");
  EXPECT_FALSE(ParseEnum(kThree, "mode", "Grey").ok());  // names are case-sensitive
}

TEST(EnumNames, ListsAsTextAndAsAConstant) {
  EXPECT_EQ(EnumNameList(kTwo), "on or off");
  EXPECT_EQ(EnumNameList(kThree), "grey, signed or vector");
  static_assert(EnumNameListConstant<kTwo>() == "on or off");
  static_assert(EnumNameListConstant<kThree>() == "grey, signed or vector");
  constexpr auto kOne = EnumTable<Two>({{Two::kOn, "on"}});
  EXPECT_EQ(EnumNameList(kOne), "on");
}

}  // namespace
}  // namespace dispex
