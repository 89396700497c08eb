// ValidateExtractOptions speaks to a C++ caller: each message names the field and its value,
// never a command-line flag.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "dispex/extract.h"

namespace dispex {
namespace {

ExtractOptions Valid() {
  ExtractOptions o;
  o.base_path = "base.obj";
  o.sculpt_path = "sculpt.obj";
  o.output_path = "map.ptx";
  return o;
}

TEST(ExtractOptions, DefaultsWithPathsAreValid) {
  EXPECT_TRUE(ValidateExtractOptions(Valid()).ok());
}

TEST(ExtractOptions, MessagesNameTheFieldNotAFlag) {
  const struct {
    std::string field;
    std::function<void(ExtractOptions&)> break_it;
  } cases[] = {
      {"output_path", [](ExtractOptions& o) { o.output_path.clear(); }},
      {"oversample = 3", [](ExtractOptions& o) { o.oversample = 3; }},
      {"max_oversample = 0", [](ExtractOptions& o) { o.max_oversample = 0; }},
      {"min_oversample = 256", [](ExtractOptions& o) { o.min_oversample = 256; }},
      {"tolerance = -1", [](ExtractOptions& o) { o.tolerance = -1; }},
      {"tolerance_fraction = 0", [](ExtractOptions& o) { o.tolerance_fraction = 0; }},
      {"search_distance = 0",
       [](ExtractOptions& o) {
         o.search_distance = {SearchDistanceSpec::Kind::kAbsolute, 0};
       }},
      {"data_type", [](ExtractOptions& o) { o.data_type = PtexDataType::kUint8; }},
      {"max_miss_fraction = 2", [](ExtractOptions& o) { o.max_miss_fraction = 2; }},
      {"threads = -1", [](ExtractOptions& o) { o.threads = -1; }},
      {"method = rays",
       [](ExtractOptions& o) {
         o.vector = VectorSpace::kTangent;
         o.method = ExtractMethod::kRays;
       }},
  };
  for (const auto& c : cases) {
    ExtractOptions o = Valid();
    c.break_it(o);
    Status s = ValidateExtractOptions(o);
    ASSERT_FALSE(s.ok()) << c.field;
    EXPECT_NE(s.message().find(c.field), std::string::npos) << s.message();
    EXPECT_EQ(s.message().find("--"), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace dispex
