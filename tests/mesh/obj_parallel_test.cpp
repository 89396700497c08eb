// The parallel OBJ reader gives exactly the mesh of a one-chunk, one-thread parse, for any
// thread count and chunk size, on a multi-megabyte file that uses every feature, so that
// chunk cuts fall inside continuations, groups, tags, comments and CRLF lines.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "dispex/mesh.h"
#include "mesh/obj_syntax.h"
#include "mesh_test_util.h"

namespace dispex {
namespace {

constexpr std::size_t kOneChunk = std::size_t{1} << 40;

// About 4 MB of OBJ: a grid of vertices and quads/triangles/n-gons written with every index
// form, plus everything a reader must step over.
std::string GenerateObj(int seed) {
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::string s;
  s.reserve(5 << 20);
  s += "# generated for dispex tests\nmtllib none.mtl\n";
  const int n = 180;  // vertices per side
  std::int64_t vertices = 0;
  auto eol = [&] { s += (rng() % 7 == 0) ? "\r\n" : "\n"; };
  for (int block = 0; block < 6; ++block) {
    s += fmt::format("o part{}", block % 4);  // part0..3, part0 and part1 twice
    eol();
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int style = static_cast<int>(rng() % 16);
        const double x = i * 0.01 + block, y = j * 0.013, z = (rng() % 1000) * 1e-4;
        if (style == 0) {
          s += fmt::format("v {} \\", x);
          eol();
          s += fmt::format("  {} {}", y, z);
        } else if (style == 1) {
          s += fmt::format("v\t{:.9e}\t{:.3f} {} 1.0", x, y, z);  // w coordinate
        } else if (style == 2) {
          s += fmt::format("v {} {} {} 0.5 0.25 0.75", x, y, z);  // colour
        } else {
          s += fmt::format("v {} {} {}", x, y, z);
        }
        eol();
        ++vertices;
        if (rng() % 50 == 0) {
          s += "vt 0.5 0.5";
          eol();
          s += "vn 0 0 1";
          eol();
        }
      }
    }
    s += fmt::format("g block {}", block);
    eol();
    const std::int64_t base = vertices - n * n;  // 0-based id of this block's first vertex
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const std::int64_t a = base + j * n + i, b = a + 1, c = a + n + 1, d = a + n;
        const int style = static_cast<int>(rng() % 12);
        switch (style) {
          case 0:
            s += fmt::format("f {} {} {} {}", a + 1, b + 1, c + 1, d + 1);
            break;
          case 1:
            s += fmt::format("f {}/{} {}/{} {}/{}", a + 1, 1, b + 1, 2, c + 1, 3);
            break;
          case 2:
            s += fmt::format("f {}//{} {}//{} {}//{} {}//9", a + 1, 1, b + 1, 1, c + 1, 1, d + 1);
            break;
          case 3:
            s += fmt::format("f {}/1/1 {}/2/2 {}/3/3", a + 1, c + 1, d + 1);
            break;
          case 4:  // relative indices
            s += fmt::format("f {} {} {} {}", a - vertices, b - vertices, c - vertices,
                             d - vertices);
            break;
          case 5:  // continued face
            s += fmt::format("f {} {} \\", a + 1, b + 1);
            eol();
            s += fmt::format("   {} {}", c + 1, d + 1);
            break;
          case 6:  // a pentagon (repeats a vertex: only the parser is tested here)
            s += fmt::format("f {} {} {} {} {}", a + 1, b + 1, c + 1, d + 1, a + 1);
            break;
          case 7:
            s += fmt::format("f {} {} {} {} # comment", a + 1, b + 1, c + 1, d + 1);
            break;
          default:
            s += fmt::format("f {} {} {} {}", a + 1, b + 1, c + 1, d + 1);
            break;
        }
        eol();
        if (rng() % 97 == 0) {
          s += "usemtl m";
          eol();
          s += "s 1";
          eol();
          s += "# a comment line";
          eol();
          eol();
        }
        if (rng() % 211 == 0) {
          s += fmt::format("t crease 2/1/0 {} {} {}", a, b, (rng() % 100) * 0.1);
          eol();
        }
        if (rng() % 503 == 0) {
          s += fmt::format("t corner 1/1/0 {} 2.5", c);
          eol();
          s += "t smoothtriangles 0/0/1 \\";
          eol();
          s += "  catmark";
          eol();
        }
      }
    }
    s += fmt::format("t hole 1/0/0 {}", block * 10);
    eol();
    s += fmt::format("t interpolateboundary 1/0/0 {}", block % 3);
    eol();
  }
  return s;
}

// About 3 MB of OBJ where every face names a texture coordinate at every corner, in every
// form (v/t, v/t/n, relative, continued), with a vt line right after each v line, so that
// texture id = vertex id. The vt lines come in every form too (w, continued, CRLF).
std::string GenerateTexturedObj(int seed) {
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::string s;
  s.reserve(4 << 20);
  auto eol = [&] { s += (rng() % 7 == 0) ? "\r\n" : "\n"; };
  const int n = 150;
  std::int64_t vertices = 0;
  for (int block = 0; block < 4; ++block) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        s += fmt::format("v {} {} {}", i * 0.01 + block, j * 0.013, (rng() % 1000) * 1e-4);
        eol();
        const double u = (i + 0.5) / n, v = (j + 0.25) / n;
        switch (rng() % 8) {
          case 0:
            s += fmt::format("vt {} \\", u);
            eol();
            s += fmt::format("   {}", v);
            break;
          case 1:
            s += fmt::format("vt\t{:.9e}\t{:.3f} 0", u, v);
            break;
          default:
            s += fmt::format("vt {} {}", u, v);
            break;
        }
        eol();
        ++vertices;
      }
    }
    if (rng() % 2 == 0) {
      s += "vn 0 0 1";
      eol();
    }
    const std::int64_t base = vertices - n * n;
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        const std::int64_t a = base + j * n + i, b = a + 1, c = a + n + 1, d = a + n;
        switch (rng() % 6) {
          case 0:
            s += fmt::format("f {0}/{0}/1 {1}/{1}/1 {2}/{2}/1 {3}/{3}/1", a + 1, b + 1, c + 1,
                             d + 1);
            break;
          case 1:
            s += fmt::format("f {0}/{0} {1}/{1} {2}/{2} {3}/{3}", a - vertices, b - vertices,
                             c - vertices, d - vertices);
            break;
          case 2:
            s += fmt::format("f {0}/{0} {1}/{1} \\", a + 1, b + 1);
            eol();
            s += fmt::format("  {0}/{0} {1}/{1}", c + 1, d + 1);
            break;
          case 3:
            s += fmt::format("f {0}/{0} {1}/{1} {2}/{2} # tri", a + 1, b + 1, c + 1);
            break;
          default:
            s += fmt::format("f {0}/{0} {1}/{1} {2}/{2} {3}/{3}", a + 1, b + 1, c + 1, d + 1);
            break;
        }
        eol();
      }
    }
  }
  return s;
}

TEST(ObjParallel, SameUvsForAnyThreadsAndChunks) {
  const std::string text = GenerateTexturedObj(4);
  StatusOr<Mesh> reference = ParseObj(text, "uv.obj", ReadOptions{1, kOneChunk});
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  ASSERT_TRUE(reference->has_uvs());
  EXPECT_EQ(reference->num_uvs(), reference->num_vertices());
  EXPECT_EQ(reference->face_uv_indices, reference->face_indices);  // by construction
  for (int threads : {1, 2}) {
    for (std::size_t chunk :
         {std::size_t{0}, std::size_t{999}, std::size_t{4096}, std::size_t{100003}}) {
      StatusOr<Mesh> mesh = ParseObj(text, "uv.obj", ReadOptions{threads, chunk});
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      EXPECT_TRUE(testing::SameMesh(*mesh, *reference)) << threads << " threads, chunk " << chunk;
    }
  }

  // One face without texture coordinates late in the file: no UVs, one face counted, for
  // every chunking (the chunks before it kept theirs).
  std::string mixed = text;
  std::size_t pos = mixed.find("\nf ", mixed.size() * 3 / 4);
  ASSERT_NE(pos, std::string::npos);
  const std::size_t end = mixed.find('\n', pos + 1);
  mixed.replace(pos + 1, end - pos - 1, "f 1 2 3");
  StatusOr<Mesh> mixed_reference = ParseObj(mixed, "uv.obj", ReadOptions{1, kOneChunk});
  ASSERT_TRUE(mixed_reference.ok()) << mixed_reference.status().message();
  EXPECT_FALSE(mixed_reference->has_uvs());
  EXPECT_EQ(mixed_reference->faces_without_uvs, 1u);
  for (std::size_t chunk : {std::size_t{0}, std::size_t{2048}, std::size_t{65536}}) {
    StatusOr<Mesh> mesh = ParseObj(mixed, "uv.obj", ReadOptions{2, chunk});
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_TRUE(testing::SameMesh(*mesh, *mixed_reference)) << "chunk " << chunk;
  }

  // A texture index past the last vt deep in the file: the same line for every chunking.
  std::string broken = text;
  pos = broken.find("\nf ", broken.size() * 2 / 3);
  ASSERT_NE(pos, std::string::npos);
  std::size_t line = 2;
  for (std::size_t i = 0; i < pos; ++i) line += broken[i] == '\n';
  const std::size_t slash = broken.find('/', pos);
  // "a/99999999a": past the last vt; a relative "-x/99999999-y" is bad syntax instead. Either
  // way that line fails.
  broken.insert(slash + 1, "99999999");
  const std::string prefix = "uv.obj:" + std::to_string(line) + ": ";
  for (std::size_t chunk : {kOneChunk, std::size_t{0}, std::size_t{3000}, std::size_t{50000}}) {
    StatusOr<Mesh> mesh = ParseObj(broken, "uv.obj", ReadOptions{2, chunk});
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.status().message().rfind(prefix, 0), 0u) << mesh.status().message();
    StatusOr<Mesh> one = ParseObj(broken, "uv.obj", ReadOptions{1, kOneChunk});
    ASSERT_FALSE(one.ok());
    EXPECT_EQ(mesh.status().message(), one.status().message());
  }
}

TEST(ObjParallel, SameMeshForAnyThreadsAndChunks) {
  const std::string text = GenerateObj(1);
  ASSERT_GT(text.size(), std::size_t{3} << 20);
  StatusOr<Mesh> reference = ParseObj(text, "gen.obj", ReadOptions{1, kOneChunk});
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  EXPECT_EQ(reference->num_vertices(), 6u * 180 * 180);
  EXPECT_EQ(reference->num_faces(), 6u * 179 * 179);
  EXPECT_EQ(reference->group_names.size(), 6u);  // "block 0".."block 5"; part0..3 own no faces
  EXPECT_GT(reference->tags.creases.size(), 100u);
  EXPECT_EQ(reference->tags.holes.size(), 6u);
  EXPECT_EQ(reference->tags.boundary, BoundaryInterpolation::kEdgeOnly);  // last value: 2
  // Some faces name texture coordinates, most do not: no UVs, every other face counted.
  EXPECT_FALSE(reference->has_uvs());
  EXPECT_GT(reference->faces_without_uvs, reference->num_faces() / 2);
  EXPECT_LT(reference->faces_without_uvs, reference->num_faces());

  for (int threads : {1, 2, 0}) {
    for (std::size_t chunk : {std::size_t{0}, std::size_t{1000}, std::size_t{4096},
                              std::size_t{65536}, std::size_t{777777}}) {
      StatusOr<Mesh> mesh = ParseObj(text, "gen.obj", ReadOptions{threads, chunk});
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      EXPECT_TRUE(testing::SameMesh(*mesh, *reference)) << threads << " threads, chunk " << chunk;
    }
  }
}

// Through the file path too (memory-mapped, pages dropped chunk by chunk).
TEST(ObjParallel, ReadObjMatchesParseObj) {
  const std::string text = GenerateObj(2);
  const std::string path = testing::TempPath(".obj");
  {
    std::ofstream out(path, std::ios::binary);
    out << text;
  }
  StatusOr<Mesh> reference = ParseObj(text, path, ReadOptions{1, kOneChunk});
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  for (std::size_t chunk : {std::size_t{0}, std::size_t{10000}, std::size_t{1} << 20}) {
    StatusOr<Mesh> mesh = ReadObj(path, ReadOptions{2, chunk});
    ASSERT_TRUE(mesh.ok()) << mesh.status().message();
    EXPECT_TRUE(testing::SameMesh(*mesh, *reference));
  }
  std::remove(path.c_str());
}

// The file path counts and parses its chunks from copies read with pread (the two bytes before
// each included), the buffer path from the bytes themselves: thousands of chunks, cut beside
// continued lines (CRLF too) and comments in face lines, give the same mesh, and an error the
// same line. (Much smaller chunks of these 3-4 MB files would exceed the process's count of
// memory maps: each chunk's buffers are maps of their own.)
TEST(ObjParallel, ReadObjReadsCopiesAsParseObjReadsBytes) {
  for (int seed : {4, 5}) {
    std::string text = seed == 4 ? GenerateTexturedObj(seed) : GenerateObj(seed);
    const std::string path = testing::TempPath(".obj");
    {
      std::ofstream out(path, std::ios::binary);
      out << text;
    }
    StatusOr<Mesh> reference = ParseObj(text, path, ReadOptions{1, kOneChunk});
    ASSERT_TRUE(reference.ok()) << reference.status().message();
    for (std::size_t chunk : {std::size_t{1000}, std::size_t{4097}, std::size_t{65536}}) {
      StatusOr<Mesh> mesh = ReadObj(path, ReadOptions{2, chunk});
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      EXPECT_TRUE(testing::SameMesh(*mesh, *reference)) << "seed " << seed << ", chunk " << chunk;
    }
    // A face index 0 two thirds in.
    const std::size_t pos = text.find("\nf ", text.size() * 2 / 3);
    ASSERT_NE(pos, std::string::npos);
    text.insert(pos + 3, "0 ");
    {
      std::ofstream out(path, std::ios::binary);
      out << text;
    }
    const StatusOr<Mesh> broken = ParseObj(text, path, ReadOptions{1, kOneChunk});
    ASSERT_FALSE(broken.ok());
    for (std::size_t chunk : {std::size_t{1000}, std::size_t{4097}}) {
      EXPECT_EQ(ReadObj(path, ReadOptions{2, chunk}).status().message(), broken.status().message());
    }
    std::remove(path.c_str());
  }
}

// An error deep in the file: the same line number for every chunking.
TEST(ObjParallel, ErrorLineDoesNotDependOnChunks) {
  std::string text = GenerateObj(3);
  // Break the face on a line far into the file: the line number of that line, counted here.
  std::size_t pos = text.find("\nf ", text.size() * 2 / 3);
  ASSERT_NE(pos, std::string::npos);
  std::size_t line = 2;  // the 'f' line after the newline at `pos`
  for (std::size_t i = 0; i < pos; ++i) line += text[i] == '\n';
  text.insert(pos + 3, "0 ");  // "f 0 a b c d": index 0
  const std::string expected =
      "gen.obj:" + std::to_string(line) + ": face index 0 (OBJ indices start at 1)";
  for (std::size_t chunk : {kOneChunk, std::size_t{0}, std::size_t{3000}, std::size_t{50000}}) {
    StatusOr<Mesh> mesh = ParseObj(text, "gen.obj", ReadOptions{2, chunk});
    ASSERT_FALSE(mesh.ok());
    EXPECT_EQ(mesh.status().message(), expected) << "chunk " << chunk;
  }
}

// The counting pass's corners of a face line against a byte-by-byte count, on random lines of
// every length around the 16-byte blocks: runs of non-blanks, blanks being ' ', '\t', '\r'.
TEST(ObjParallel, FaceCornersCountedAsRunsOfNonBlanks) {
  std::mt19937 rng(7);
  const std::string alphabet = "  \t\r0123456789/-";
  for (int trial = 0; trial < 20000; ++trial) {
    std::string line(rng() % 70, ' ');
    for (char& c : line) c = alphabet[rng() % alphabet.size()];
    const bool special = rng() % 4 == 0 && !line.empty();
    if (special) line[rng() % line.size()] = rng() % 2 ? '#' : '\\';
    std::int64_t expected = 0;
    bool before_blank = true;
    for (char c : line) {
      const bool blank = c == ' ' || c == '\t' || c == '\r';
      expected += !blank && before_blank;
      before_blank = blank;
    }
    bool plain = true;
    const std::int64_t counted =
        mesh::CountFaceCorners(line.data(), line.data() + line.size(), plain);
    EXPECT_EQ(plain, !special) << "'" << line << "'";
    if (!special) {
      EXPECT_EQ(counted, expected) << "'" << line << "'";
    }
  }
}

// The word-at-a-time digits of a face index against a byte-by-byte reading: after 0 to 8 digits,
// every byte value (those just below '0' and above '9' included), and random words of digits,
// blanks and the other bytes of face lines.
TEST(ObjParallel, LeadingDigitsReadEightBytesAtOnce) {
  auto expect_as_bytes = [](const char(&bytes)[8]) {
    int count = 0;
    std::uint32_t expected = 0;
    while (count < 8 && bytes[count] >= '0' && bytes[count] <= '9') {
      expected = expected * 10 + static_cast<std::uint32_t>(bytes[count++] - '0');
    }
    std::uint32_t value = 0;
    const std::string text(bytes, 8);
    ASSERT_EQ(mesh::LeadingDigits8(bytes, value), count) << "'" << text << "'";
    if (count > 0) {
      EXPECT_EQ(value, expected) << "'" << text << "'";
    }
  };
  for (int digits = 0; digits < 8; ++digits) {
    for (int c = 0; c < 256; ++c) {
      char bytes[8] = {'9', '9', '9', '9', '9', '9', '9', '9'};
      for (int i = 0; i < digits; ++i) bytes[i] = static_cast<char>('9' - i);
      bytes[digits] = static_cast<char>(c);
      expect_as_bytes(bytes);
    }
  }
  expect_as_bytes({'9', '8', '7', '6', '5', '4', '3', '2'});
  expect_as_bytes({'0', '0', '0', '0', '0', '0', '0', '1'});
  std::mt19937 rng(5);
  const std::string alphabet = "0123456789 \t\n/-#\r:";
  for (int trial = 0; trial < 100000; ++trial) {
    char bytes[8];
    const int digits = static_cast<int>(rng() % 9);
    for (int i = 0; i < 8; ++i) {
      bytes[i] =
          i < digits ? static_cast<char>('0' + rng() % 10) : alphabet[rng() % alphabet.size()];
    }
    expect_as_bytes(bytes);
  }
}

// A file whose face lines hold no comment and no continuation has its face indices parsed in
// place (counted by the counting pass); one such comment sends them through per-chunk buffers.
// Both give the same mesh, for any chunking, from a buffer and from a file; so do every index
// form and CRLF lines.
TEST(ObjParallel, FaceIndicesInPlaceEqualBuffered) {
  std::mt19937 rng(11);
  std::string plain;
  const int n = 120;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) plain += fmt::format("v {} {} {}\n", i, j, (rng() % 100) * 0.01);
  }
  plain += "vt 0 0\n";
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i + 1, b = a + 1, c = a + n + 1, d = a + n;
      switch (rng() % 5) {
        case 0:
          plain += fmt::format("f {}/1 {}/1 {}/1 {}/1\r\n", a, b, c, d);
          break;
        case 1:
          plain += fmt::format("f\t{}//4  {}//4\t {}//4 {}//4 \n", a, b, c, d);
          break;
        case 2:
          plain += fmt::format("f {} {} {}\nf {} {} {}\n", a, b, c, a, c, d);
          break;
        default:
          plain += fmt::format("f {} {} {} {}\n", a - n * n - 1, b - n * n - 1, c, d);
          break;
      }
    }
  }
  std::string commented = plain;
  commented.insert(commented.find('\n', commented.find("\nf ") + 1), " # a comment");
  StatusOr<Mesh> reference = ParseObj(plain, "grid.obj", ReadOptions{1, kOneChunk});
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  EXPECT_GT(reference->num_faces(), std::size_t(n - 1) * (n - 1));
  const std::string path = testing::TempPath(".obj");
  for (const std::string* text : {&plain, &commented}) {
    {
      std::ofstream out(path, std::ios::binary);
      out << *text;
    }
    for (std::size_t chunk : {kOneChunk, std::size_t{0}, std::size_t{1000}, std::size_t{4096}}) {
      const std::string what =
          fmt::format("chunk {}{}", chunk, text == &plain ? ", in place" : ", buffered");
      StatusOr<Mesh> mesh = ParseObj(*text, "grid.obj", ReadOptions{2, chunk});
      ASSERT_TRUE(mesh.ok()) << mesh.status().message();
      EXPECT_TRUE(testing::SameMesh(*mesh, *reference)) << what;
      StatusOr<Mesh> read = ReadObj(path, ReadOptions{2, chunk});
      ASSERT_TRUE(read.ok()) << read.status().message();
      EXPECT_TRUE(testing::SameMesh(*read, *reference)) << what << ", from the file";
    }
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace dispex
