// What the command line says when it cannot parse a command (tools/parse_errors.h): one line
// in the "dispex: ..." format, exit 2, naming `dispex CMD --help`, with the nearest valid name
// for a misspelled option or command and none for a word that is nothing like one.
#include <gtest/gtest.h>

#include <string>

#include "../extract/e2e_support.h"

namespace dispex {
namespace {

using testing::RunDispex;
using testing::TempDir;

// The run's stderr, checked to be one line in the common format and exit 2.
std::string ParseFailure(const std::string& args) {
  TempDir dir;
  const auto r = RunDispex(args, dir);
  EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  EXPECT_EQ(r.err.rfind("dispex: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  return r.err;
}

TEST(ParseErrors, MisspelledOptionsGetTheNearestOfTheCommandsOwn) {
  std::string err = ParseFailure("extract a.obj b.obj -o m.ptx --tolerence 0.01");
  EXPECT_NE(err.find("--tolerence: did you mean --tolerance?"), std::string::npos) << err;
  EXPECT_NE(err.find("(see dispex extract --help)"), std::string::npos) << err;
  err = ParseFailure("verify a.obj m.ptx --truht t.truth");
  EXPECT_NE(err.find("--truht: did you mean --truth?"), std::string::npos) << err;
  EXPECT_NE(err.find("(see dispex verify --help)"), std::string::npos) << err;
  // `=value` is not part of the name; an abbreviation of one option is taken as it.
  err = ParseFailure("extract a.obj b.obj -o m.ptx --search-distanse=0.1");
  EXPECT_NE(err.find("did you mean --search-distance?"), std::string::npos) << err;
  err = ParseFailure("extract a.obj b.obj -o m.ptx --watert off");
  EXPECT_NE(err.find("did you mean --watertight?"), std::string::npos) << err;
}

TEST(ParseErrors, NoGuessForAWordLikeNoOption) {
  const std::string err = ParseFailure("extract a.obj b.obj -o m.ptx --zzzzzzzzzz 1");
  EXPECT_EQ(err.find("did you mean"), std::string::npos) << err;
  EXPECT_NE(err.find("(see dispex extract --help)"), std::string::npos) << err;
}

TEST(ParseErrors, OtherParserErrorsNameTheCommandsHelp) {
  std::string err = ParseFailure("extract a.obj b.obj -o m.ptx --tolerance abc");
  EXPECT_NE(err.find("(see dispex extract --help)"), std::string::npos) << err;
  err = ParseFailure("verify");
  EXPECT_NE(err.find("(see dispex verify --help)"), std::string::npos) << err;
}

TEST(ParseErrors, MisspelledCommandsGetTheNearest) {
  std::string err = ParseFailure("extarct a.obj b.obj -o m.ptx");
  EXPECT_NE(err.find("unknown command 'extarct' (did you mean extract?)"), std::string::npos)
      << err;
  EXPECT_NE(err.find("(see dispex --help)"), std::string::npos) << err;
  err = ParseFailure("qqqqqq");
  EXPECT_EQ(err.find("did you mean"), std::string::npos) << err;
}

}  // namespace
}  // namespace dispex
