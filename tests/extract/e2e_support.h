// Shared helpers of the end-to-end tests (extract, verify, cli, render): test data paths,
// temporary folders, running the dispex binary, reading files whole.
#pragma once

#include <gtest/gtest.h>
#include <regex.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/ptex.h"
#include "dispex/verify.h"

namespace dispex::testing {

namespace fs = std::filesystem;

inline std::string DataPath(const std::string& relative) {
  return (fs::path(DISPEX_TEST_DATA_DIR) / relative).string();
}

// A ground-truth sculpt of `cage`: refined `levels` times, displaced by `pattern`.
// An extraction of `sculpt` onto `base` into `output` by `method`, other options at default.
inline ExtractOptions MethodOptions(const std::string& base, const std::string& sculpt,
                                    const std::string& output, ExtractMethod method) {
  ExtractOptions o;
  o.base_path = base;
  o.sculpt_path = sculpt;
  o.output_path = output;
  o.method = method;
  return o;
}

inline MakeSculptOptions SculptOptions(const std::string& cage, const std::string& output,
                                       int levels, Pattern pattern, double amplitude) {
  MakeSculptOptions options;
  options.cage_path = cage;
  options.output_path = output;
  options.levels = levels;
  options.pattern = pattern;
  options.amplitude = amplitude;
  return options;
}

// A jittered ground-truth sculpt: `density` x `density` cells per Ptex face.
inline MakeSculptOptions JitteredSculptOptions(const std::string& cage, const std::string& output,
                                               int density, Pattern pattern, double amplitude) {
  MakeSculptOptions options = SculptOptions(cage, output, 1, pattern, amplitude);
  options.layout = SculptLayout::kJittered;
  options.density = density;
  return options;
}

// Negative controls: a good map made wrong on purpose. Every accuracy check must reject each.
enum class WrongMap { kZero, kHalf, kFourFifths, kTransposed, kSignFlipped };
constexpr WrongMap kWrongMaps[] = {WrongMap::kZero, WrongMap::kHalf, WrongMap::kFourFifths,
                                   WrongMap::kTransposed, WrongMap::kSignFlipped};
inline const char* WrongMapName(WrongMap kind) {
  switch (kind) {
    case WrongMap::kZero:
      return "zero";
    case WrongMap::kHalf:
      return "scaled by 0.5";
    case WrongMap::kFourFifths:
      return "scaled by 0.8";
    case WrongMap::kTransposed:
      return "u and v transposed";
    default:
      return "sign flipped";
  }
}

// Writes the map at `good` with every face's texels changed as `kind` says (transposed: texel
// (i, j) moved to (j, i) and the resolution swapped). Adjacency is kept; meta data is not.
inline void WriteWrongMap(const std::string& good, const std::string& out, WrongMap kind) {
  auto map = PtexFile::Open(good);
  ASSERT_TRUE(map.ok()) << map.status().message();
  auto writer = PtexWriter::Create(out, PtexWriterOptions{}, map->num_faces());
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  std::vector<float> texels, swapped;
  for (int f = 0; f < map->num_faces(); ++f) {
    PtexFaceInfo info = map->face_info(PtexFaceId(f));
    ASSERT_TRUE(map->ReadFace(PtexFaceId(f), 0, texels).ok());
    const float scale = kind == WrongMap::kZero          ? 0.0f
                        : kind == WrongMap::kHalf        ? 0.5f
                        : kind == WrongMap::kFourFifths  ? 0.8f
                        : kind == WrongMap::kSignFlipped ? -1.0f
                                                         : 1.0f;
    for (float& v : texels) v *= scale;
    if (kind == WrongMap::kTransposed && texels.size() == info.num_texels()) {
      const int ures = info.ures(), vres = info.vres();
      swapped.resize(texels.size());
      for (int j = 0; j < vres; ++j) {
        for (int i = 0; i < ures; ++i)
          swapped[std::size_t(i) * vres + j] = texels[std::size_t(j) * ures + i];
      }
      texels.swap(swapped);
      std::swap(info.ulog2, info.vlog2);
    }
    info.constant = false;
    ASSERT_TRUE(writer->SetFace(PtexFaceId(f), info, texels).ok());
  }
  ASSERT_TRUE(writer->Finish().ok());
}

// The accuracy check of the end-to-end tests: `map` against the truth with verify's default
// bounds at tolerance `tau` (the per-record bound 1.5 tau + 2 e_v, RMS and p99 in units of tau).
inline VerifyReport CheckTruth(const std::string& base, const std::string& map,
                               const std::string& truth, double tau) {
  VerifyOptions verify;
  verify.base_path = base;
  verify.map_path = map;
  verify.truth_path = truth;
  verify.tolerance = tau;
  auto report = Verify(verify);
  EXPECT_TRUE(report.ok()) << report.status().message();
  return report.ok() ? *report : VerifyReport{};
}

// Where two maps differ: the first face (resolution or texels), the first face record, or the
// first meta data item; "layout only" when those are all equal. With `faces_only`, "" when every
// face is equal.
inline std::string MapDifference(const std::string& a_path, const std::string& b_path,
                                 bool faces_only = false) {
  auto a = PtexFile::Open(a_path);
  auto b = PtexFile::Open(b_path);
  if (!a.ok() || !b.ok()) return "unreadable";
  if (a->num_faces() != b->num_faces()) return "face counts";
  std::vector<float> ta, tb;
  for (int f = 0; f < a->num_faces(); ++f) {
    const PtexFaceInfo &ia = a->face_info(PtexFaceId(f)), &ib = b->face_info(PtexFaceId(f));
    if (ia.ulog2 != ib.ulog2 || ia.vlog2 != ib.vlog2) {
      return "face " + std::to_string(f) + " resolution";
    }
    if (!a->ReadFace(PtexFaceId(f), 0, ta).ok() || !b->ReadFace(PtexFaceId(f), 0, tb).ok() ||
        ta != tb) {
      return "face " + std::to_string(f) + " texels";
    }
  }
  if (faces_only) return "";
  const PtexMetaItem* ra = a->FindMetaData("dispex:face_records_v1");
  const PtexMetaItem* rb = b->FindMetaData("dispex:face_records_v1");
  if (ra && rb && ra->bytes != rb->bytes && ra->bytes.size() == rb->bytes.size()) {
    const std::size_t size = ra->bytes.size() / static_cast<std::size_t>(a->num_faces());
    std::size_t at = 0;
    while (ra->bytes[at] == rb->bytes[at]) ++at;
    return "face record " + std::to_string(at / size) + " byte " + std::to_string(at % size);
  }
  for (const PtexMetaItem& item : a->meta_data()) {
    const PtexMetaItem* other = b->FindMetaData(item.key);
    if (other == nullptr || other->bytes != item.bytes) {
      const std::string x = item.AsString(), y = other ? other->AsString() : "";
      std::size_t at = 0;
      while (at < x.size() && at < y.size() && x[at] == y[at]) ++at;
      const std::size_t from = at > 60 ? at - 60 : 0;
      return "meta data " + item.key + " at byte " + std::to_string(at) + ": ..." +
             x.substr(from, 120) + " / ..." + y.substr(from, 120);
    }
  }
  return "layout only";
}

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';  // parameterised tests
    }
    path_ = fs::temp_directory_path() / ("dispex_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

inline std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

// Runs the dispex binary with `args` (already shell-quoted where needed), through `wrapper`
// (a command that runs the rest of its line, e.g. setpriv) when one is given.
inline CommandResult RunDispex(const std::string& args, const TempDir& dir,
                               const std::string& wrapper = "") {
  std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string command =
      wrapper + (wrapper.empty() ? "" : " ") + DISPEX_EXE + " " + args + " >" + out + " 2>" + err;
  int status = std::system(command.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = Slurp(out);
  r.err = Slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

// Whether all of `line` matches the POSIX extended regular expression `pattern`; the groups
// (whole match first) when it does. POSIX regex.h rather than std::regex: GCC 12 at -O1 under
// AddressSanitizer warns (maybe-uninitialized) inside libstdc++'s regex compiler.
inline std::optional<std::vector<std::string>> MatchWhole(const std::string& line,
                                                          const std::string& pattern) {
  regex_t re;
  if (regcomp(&re, ("^(" + pattern + ")$").c_str(), REG_EXTENDED) != 0) {
    ADD_FAILURE() << "bad pattern: " << pattern;
    return std::nullopt;
  }
  std::array<regmatch_t, 10> groups{};
  const bool matched = regexec(&re, line.c_str(), groups.size(), groups.data(), 0) == 0;
  regfree(&re);
  if (!matched) return std::nullopt;
  std::vector<std::string> out;
  // Group 1 is the whole-line wrapper added above; the pattern's own groups follow it.
  for (std::size_t i = 1; i < groups.size() && groups[i].rm_so >= 0; ++i)
    out.push_back(line.substr(static_cast<std::size_t>(groups[i].rm_so),
                              static_cast<std::size_t>(groups[i].rm_eo - groups[i].rm_so)));
  return out;
}

}  // namespace dispex::testing
