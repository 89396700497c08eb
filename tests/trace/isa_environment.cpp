// Under DISPEX_EMBREE_ISA (tests/trace/CMakeLists.txt registers the suite once per Embree ISA)
// every test skips when this CPU lacks that ISA, and an unknown name fails them all.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "dispex/trace.h"

namespace {

class IsaEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    const char* isa = std::getenv("DISPEX_EMBREE_ISA");
    if (isa == nullptr || *isa == '\0') return;
    const auto names = dispex::EmbreeIsaNames();
    ASSERT_NE(std::find(names.begin(), names.end(), isa), names.end())
        << "DISPEX_EMBREE_ISA=" << isa << " is not an Embree ISA";
    const auto supported = dispex::SupportedEmbreeIsas();
    if (std::find(supported.begin(), supported.end(), isa) == supported.end()) {
      GTEST_SKIP() << "this CPU lacks the Embree ISA " << isa << " (DISPEX_EMBREE_ISA)";
    }
  }
};

[[maybe_unused]] ::testing::Environment* const kIsaEnvironment =
    ::testing::AddGlobalTestEnvironment(new IsaEnvironment);

}  // namespace
