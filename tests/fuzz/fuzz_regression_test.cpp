// The fuzz targets' checks, replayed with the normal build (gcc, and ASan/UBSan in CI): all
// three readers over every file in tests/fuzz_regressions/ (inputs that once broke a reader)
// and every seed file the fuzzers start from. Each reader must keep its contract on each file
// (fuzz/reader_contract.h): a valid result or a one-line Status that names the file, never a
// crash. The inputs that once broke a reader must now give the error the fix introduced, and
// every saved input must be explained in tests/fuzz_regressions/README.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "dispex/mesh.h"
#include "dispex/ptex.h"
#include "fuzz/reader_contract.h"

namespace dispex {
namespace {

namespace fs = std::filesystem;

// Seeds larger than this are left out, as scripts/fuzz.sh does by default.
constexpr std::uintmax_t kSeedMaxBytes = 65536;

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool IsDocumentation(const fs::path& path) {
  const std::string ext = path.extension().string();
  const std::string stem = path.filename().string();
  return ext == ".md" || ext == ".txt" || ext == ".py" || stem.rfind("LICENSE", 0) == 0 ||
         stem.rfind("NOTICE", 0) == 0;
}

// Regular files under `dir` (recursively), sorted, documentation left out.
std::vector<fs::path> FilesUnder(const fs::path& dir, std::uintmax_t max_bytes = UINTMAX_MAX) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file() || IsDocumentation(entry.path())) continue;
    if (entry.file_size() > max_bytes) continue;
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

const fs::path kRegressions = DISPEX_FUZZ_REGRESSIONS_DIR;
const fs::path kSeeds = DISPEX_FUZZ_SEEDS_DIR;
const fs::path kData = DISPEX_TEST_DATA_DIR;

// The seed corpora of scripts/fuzz.sh: meshes, malformed files and Ptex fixtures of
// tests/data, and the hand-made seeds of fuzz/seeds.
std::vector<fs::path> SeedFiles() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kData)) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    if (name == "meshes" || name.rfind("malformed", 0) == 0 || name.rfind("ptex", 0) == 0) {
      for (fs::path& f : FilesUnder(entry.path(), kSeedMaxBytes)) files.push_back(std::move(f));
    }
  }
  for (fs::path& f : FilesUnder(kSeeds)) files.push_back(std::move(f));
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<fs::path> AllInputs() {
  std::vector<fs::path> files = FilesUnder(kRegressions);
  for (fs::path& f : SeedFiles()) files.push_back(std::move(f));
  return files;
}

// Every reader over the bytes of `path`; "" or the first broken promise, prefixed with the
// reader.
std::string CheckAllReaders(const fs::path& path) {
  const std::string bytes = ReadBytes(path);
  const std::string name = path.filename().string();
  ReadOptions one_thread;
  one_thread.threads = 1;

  const StatusOr<Mesh> obj = ParseObj(bytes, name, one_thread);
  if (std::string why = fuzz::CheckMeshResult(obj, name); !why.empty()) return "OBJ: " + why;
  // The OBJ reader promises the same result for any chunk size and thread count.
  ReadOptions chunked;
  chunked.threads = 2;
  chunked.chunk_bytes = std::max<std::size_t>(16, bytes.size() / 64);
  if (std::string why = fuzz::CompareMeshResults(obj, ParseObj(bytes, name, chunked));
      !why.empty()) {
    return "OBJ, small chunks and 2 threads: " + why;
  }

  const StatusOr<Mesh> ply = ParsePly(bytes, name, one_thread);
  if (std::string why = fuzz::CheckMeshResult(ply, name); !why.empty()) return "PLY: " + why;

  if (std::string why = fuzz::ExercisePtex(bytes, name); !why.empty()) return "Ptex: " + why;
  return {};
}

TEST(FuzzRegression, SeedCorporaAreThere) {
  // Guards against the checks below passing on an empty list (a moved data folder).
  std::size_t obj = 0, ply = 0, ptx = 0;
  for (const fs::path& f : SeedFiles()) {
    obj += f.extension() == ".obj";
    ply += f.extension() == ".ply";
    ptx += f.extension() == ".ptx";
  }
  EXPECT_GE(obj, 40u);
  EXPECT_GE(ply, 25u);
  EXPECT_GE(ptx, 8u);
  EXPECT_FALSE(FilesUnder(kRegressions).empty());
}

TEST(FuzzRegression, EveryInputKeepsEveryReadersContract) {
  const std::vector<fs::path> inputs = AllInputs();
  for (const fs::path& path : inputs) {
    EXPECT_EQ(CheckAllReaders(path), "") << path;
  }
}

// The file readers (memory-mapped) give what the in-memory parsers give.
TEST(FuzzRegression, FileReadersAgreeWithTheParsers) {
  ReadOptions one_thread;
  one_thread.threads = 1;
  for (const fs::path& path : FilesUnder(kRegressions)) {
    const std::string bytes = ReadBytes(path);
    const std::string p = path.string();
    EXPECT_EQ(fuzz::CompareMeshResults(ReadObj(p, one_thread), ParseObj(bytes, p, one_thread)), "")
        << p;
    EXPECT_EQ(fuzz::CompareMeshResults(ReadPly(p, one_thread), ParsePly(bytes, p, one_thread)), "")
        << p;
    const StatusOr<PtexFile> opened = PtexFile::Open(p);
    const StatusOr<PtexFile> parsed = ParsePtex(bytes, p);
    ASSERT_EQ(opened.ok(), parsed.ok()) << p;
    if (!opened.ok()) {
      EXPECT_EQ(opened.status().message(), parsed.status().message());
    }
  }
}

// Each input that once broke a reader, the reader it broke, and a fragment of the error it
// gives since the fix. (What broke and how it was fixed: tests/fuzz_regressions/README.md.)
struct Fixed {
  const char* file;
  const char* reader;    // "obj", "ply" or "ptex"
  const char* fragment;  // expected in the Status message
};

constexpr Fixed kFixed[] = {
    {"ptex_fuzzer-bc54043e8865543a", "ptex",
     ": meta data: item 0 at byte 0 ('?'): value of 285212672 bytes runs past the end of the "
     "block"},
    {"ply_fuzzer-4031ea294effc43f", "ply", ":3: element name 'ver?"},
};

TEST(FuzzRegression, FixedInputsGiveTheirError) {
  for (const Fixed& fixed : kFixed) {
    const fs::path path = kRegressions / fixed.file;
    ASSERT_TRUE(fs::exists(path)) << path;
    const std::string bytes = ReadBytes(path);
    const std::string reader = fixed.reader;
    Status status;
    if (reader == "obj") {
      status = ParseObj(bytes, fixed.file).status();
    } else if (reader == "ply") {
      status = ParsePly(bytes, fixed.file).status();
    } else {
      status = ParsePtex(bytes, fixed.file).status();
    }
    ASSERT_FALSE(status.ok()) << fixed.file;
    EXPECT_EQ(fuzz::CheckErrorMessage(status, fixed.file), "") << fixed.file;
    EXPECT_NE(status.message().find(fixed.fragment), std::string::npos)
        << fixed.file << ": " << status.message();
  }
}

// ptex_fuzzer-db76f2e888f691f3: faces whose zipped block is far too small for their
// resolution. Each read used to allocate and zero the whole face (4 MiB) before finding that
// out, and Sample decoded the face again at every call.
TEST(FuzzRegression, UndecodableFacesCostNoAllocationAndOneDecode) {
  const std::string name = "ptex_fuzzer-db76f2e888f691f3";
  const std::string bytes = ReadBytes(kRegressions / name);
  StatusOr<PtexFile> file = ParsePtex(bytes, name);
  ASSERT_TRUE(file.ok()) << file.status().message();
  int undecodable = 0;
  for (int f = 0; f < file->num_faces(); ++f) {
    const PtexFaceId id(f);
    if (file->face_info(id).constant) continue;
    std::vector<std::uint8_t> raw;
    const Status read = file->ReadFaceRaw(id, 0, raw);
    if (read.ok()) continue;
    ++undecodable;
    EXPECT_NE(read.message().find("compressed bytes cannot hold"), std::string::npos)
        << read.message();
    EXPECT_EQ(raw.capacity(), 0u) << "face " << f << ": allocated before the size check";
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isnan(file->Sample(id, 0.5f, 0.5f, 0)));
  }
  EXPECT_GT(undecodable, 0);
}

TEST(FuzzRegression, EverySavedInputIsExplained) {
  const std::string readme = ReadBytes(kRegressions / "README.md");
  ASSERT_FALSE(readme.empty());
  for (const fs::path& path : FilesUnder(kRegressions)) {
    std::string quoted(1, '`');  // (built in steps: gcc 12 warns on "`" + std::string)
    quoted.append(path.filename().string()).push_back('`');
    EXPECT_NE(readme.find(quoted), std::string::npos)
        << path.filename() << " is not described in tests/fuzz_regressions/README.md";
  }
  for (const Fixed& fixed : kFixed) {
    EXPECT_TRUE(fs::exists(kRegressions / fixed.file)) << fixed.file;
  }
}

// The hand-made seeds are valid files (fuzz/seeds/make_seeds.py): they must read, with the
// contents the generator wrote, or they would seed the fuzzers with errors only.
TEST(FuzzRegression, HandMadeSeedsRead) {
  ReadOptions one_thread;
  one_thread.threads = 1;
  const StatusOr<Mesh> ascii =
      ReadPly((kSeeds / "ply/cube_ascii_extra_elements.ply").string(), one_thread);
  ASSERT_TRUE(ascii.ok()) << ascii.status().message();
  EXPECT_EQ(ascii->num_vertices(), 8u);
  EXPECT_EQ(ascii->num_faces(), 6u);
  EXPECT_TRUE(ascii->all_quads());

  const StatusOr<Mesh> le =
      ReadPly((kSeeds / "ply/cube_binary_le_double.ply").string(), one_thread);
  ASSERT_TRUE(le.ok()) << le.status().message();
  EXPECT_EQ(le->num_faces(), 7u);
  EXPECT_EQ(le->face_indices.size(), 26u);

  const StatusOr<Mesh> be =
      ReadPly((kSeeds / "ply/pyramid_binary_be_vertex_list.ply").string(), one_thread);
  ASSERT_TRUE(be.ok()) << be.status().message();
  ASSERT_EQ(be->num_vertices(), 5u);
  EXPECT_EQ(be->positions[4].x, 1.0f);
  EXPECT_EQ(be->positions[4].y, 1.0f);
  EXPECT_EQ(be->positions[4].z, 1.0f);
  EXPECT_EQ(be->face_size(1), 5);

  const StatusOr<PtexFile> edited =
      PtexFile::Open((kSeeds / "ptex/quad_float1_edits.ptx").string());
  ASSERT_TRUE(edited.ok()) << edited.status().message();
  EXPECT_TRUE(edited->header().has_edits);
  const PtexMetaItem* item = edited->FindMetaData("edited");
  ASSERT_NE(item, nullptr);
  EXPECT_EQ(item->AsString(), "yes");
  std::vector<float> texels;
  ASSERT_TRUE(edited->ReadFace(PtexFaceId(1), 0, texels).ok());
  EXPECT_EQ(texels, (std::vector<float>{1, 2, 3, 4}));
  EXPECT_TRUE(edited->face_info(PtexFaceId(2)).constant);
  float value = 0;
  edited->ConstantValue(PtexFaceId(2), &value);
  EXPECT_EQ(value, -1.5f);
}

}  // namespace
}  // namespace dispex
