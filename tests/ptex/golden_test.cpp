// Golden tests (after wdas/ptex's compare_test): small textures are written, dumped to text
// (`dispex info --faces` lines, then the structural dump with every stored block inflated)
// and compared with the dumps checked in under tests/data/ptex-golden/. The dumps hold no
// compressed sizes, so they do not depend on the compressor's version.
//
// To regenerate after an intended change: DISPEX_UPDATE_GOLDEN=1 ./ptex_test
// --gtest_filter='Golden*', then review the diff of tests/data/ptex-golden/.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "dispex/ptex.h"
#include "dispex/ptex_describe.h"
#include "golden_cases.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

std::string Dump(const PtexFile& file) {
  std::string faces, structure;
  Status s = FormatPtexFaces(file, faces);
  EXPECT_TRUE(s.ok()) << s.message();
  s = FormatPtexStructure(file, structure);
  EXPECT_TRUE(s.ok()) << s.message();
  return "# dispex info --faces\n" + faces + "# structure\n" + structure;
}

class Golden : public ::testing::TestWithParam<ptex_test::GoldenCase> {};

TEST_P(Golden, DumpMatchesTheCheckedInFile) {
  const ptex_test::GoldenCase& c = GetParam();
  ptex_test::TempDir dir;
  const std::string golden_path = ptex_test::GoldenDumpPath(c.name);
  for (PtexCompressor comp : {PtexCompressor::kLibdeflate, PtexCompressor::kZlib}) {
    const std::string path = (dir / (c.name + ".ptx")).string();
    PtexWriterOptions options = c.options;
    options.compressor = comp;
    StatusOr<PtexWriter> w = PtexWriter::Create(path, options, c.num_faces);
    ASSERT_TRUE(w.ok()) << w.status().message();
    Status s = c.fill(*w);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_TRUE(w->Finish().ok());
    StatusOr<PtexFile> file = PtexFile::Open(path);
    ASSERT_TRUE(file.ok()) << file.status().message();
    const std::string dump = Dump(*file);
    const char* update = std::getenv("DISPEX_UPDATE_GOLDEN");
    if (update && std::string(update) == "1" && comp == PtexCompressor::kLibdeflate) {
      std::ofstream(golden_path, std::ios::binary) << dump;
    }
    std::ifstream in(golden_path, std::ios::binary);
    ASSERT_TRUE(in.good()) << "missing " << golden_path << " (DISPEX_UPDATE_GOLDEN=1 writes it)";
    std::stringstream golden;
    golden << in.rdbuf();
    EXPECT_EQ(dump, golden.str()) << c.name << " differs from " << golden_path;
  }
}

INSTANTIATE_TEST_SUITE_P(Textures, Golden, ::testing::ValuesIn(ptex_test::GoldenCases()),
                         [](const ::testing::TestParamInfo<ptex_test::GoldenCase>& p) {
                           return p.param.name;
                         });

}  // namespace
}  // namespace dispex
