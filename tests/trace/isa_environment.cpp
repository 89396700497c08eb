// Under DISPEX_EMBREE_ISA (tests/trace/CMakeLists.txt registers the suite once per Embree ISA)
// the run is skipped when this CPU lacks that ISA: exit code 77, which ctest reports as
// skipped (SKIP_RETURN_CODE, tests/CMakeLists.txt). An unknown name fails every test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
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
      std::printf("skipped: this CPU lacks the Embree ISA %s (DISPEX_EMBREE_ISA)\n", isa);
      std::fflush(stdout);
      std::exit(77);
    }
  }
};

[[maybe_unused]] ::testing::Environment* const kIsaEnvironment =
    ::testing::AddGlobalTestEnvironment(new IsaEnvironment);

}  // namespace
