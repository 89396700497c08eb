// Edit blocks (docs/ptex.md, "Edit blocks"), which the dispex writer never produces: files
// assembled here with zlib, with face data edits (replacing a face, making one constant) and a meta
// data edit.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dispex/ptex.h"
#include "ptex_test_util.h"

namespace dispex {
namespace {

using ptex_test::FloatBytes;
using ptex_test::Put;
using ptex_test::RawPtex;
using ptex_test::ZippedFloats;

std::vector<float> Ramp(int n, float start) {
  std::vector<float> v;
  for (int i = 0; i < n; ++i) v.push_back(start + static_cast<float>(i));
  return v;
}

// Face 0: 4x4, face 1: 16x16 with stored reductions (levels 1, 2), meta "a" = {1}.
RawPtex BaseFile() {
  RawPtex p;
  RawPtex::AddFace(p.face_info, 2, 2, 0, {-1, 1, -1, -1}, 3 << 2);
  RawPtex::AddFace(p.face_info, 4, 4, 0, {-1, -1, -1, 0}, 1 << 6);
  p.const_data = FloatBytes({7.5f, 127.5f});
  const auto b0 = ZippedFloats(Ramp(16, 0));
  const auto b1 = ZippedFloats(Ramp(256, 0));
  p.levels.push_back(
      {{0x40000000u | std::uint32_t(b0.size()), 0x40000000u | std::uint32_t(b1.size())}, {b0, b1}});
  const auto r1 = ZippedFloats(Ramp(64, 1000));
  const auto r2 = ZippedFloats(Ramp(16, 2000));
  p.levels.push_back({{0x40000000u | std::uint32_t(r1.size())}, {r1}});
  p.levels.push_back({{0x40000000u | std::uint32_t(r2.size())}, {r2}});
  // meta "a": int32 {1}
  p.meta.push_back(2);
  p.meta.insert(p.meta.end(), {'a', 0});
  p.meta.push_back(3);
  Put<std::uint32_t>(p.meta, 4);
  Put<std::int32_t>(p.meta, 1);
  return p;
}

std::vector<std::uint8_t> Edits() {
  std::vector<std::uint8_t> e;
  // Face 1 becomes 8x4 with new texels.
  {
    std::vector<std::uint8_t> body;
    Put<std::uint32_t>(body, 1);
    RawPtex::AddFace(body, 3, 2, 0, {-1, -1, -1, 0}, 1 << 6);
    const auto block = ZippedFloats(Ramp(32, 100));
    Put<std::uint32_t>(body, 0x40000000u | std::uint32_t(block.size()));
    Put<float>(body, 115.5f);
    body.insert(body.end(), block.begin(), block.end());
    e.push_back(0);
    Put<std::uint32_t>(e, static_cast<std::uint32_t>(body.size()));
    e.insert(e.end(), body.begin(), body.end());
  }
  // Meta data: "a" replaced, "b" added.
  {
    std::vector<std::uint8_t> items;
    items.push_back(2);
    items.insert(items.end(), {'a', 0});
    items.push_back(3);
    Put<std::uint32_t>(items, 8);
    Put<std::int32_t>(items, 7);
    Put<std::int32_t>(items, 8);
    items.push_back(2);
    items.insert(items.end(), {'b', 0});
    items.push_back(0);
    Put<std::uint32_t>(items, 7);
    items.insert(items.end(), {'e', 'd', 'i', 't', 'e', 'd', 0});
    const auto z = ptex_test::ZlibCompress(items);
    e.push_back(1);
    Put<std::uint32_t>(e, static_cast<std::uint32_t>(8 + z.size()));
    Put<std::uint32_t>(e, static_cast<std::uint32_t>(z.size()));
    Put<std::uint32_t>(e, static_cast<std::uint32_t>(items.size()));
    e.insert(e.end(), z.begin(), z.end());
  }
  // Face 0 becomes constant 9.
  {
    std::vector<std::uint8_t> body;
    Put<std::uint32_t>(body, 0);
    RawPtex::AddFace(body, 2, 2, 1, {-1, 1, -1, -1}, 3 << 2);
    Put<std::uint32_t>(body, 0);
    Put<float>(body, 9.0f);
    e.push_back(0);
    Put<std::uint32_t>(e, static_cast<std::uint32_t>(body.size()));
    e.insert(e.end(), body.begin(), body.end());
  }
  return e;
}

StatusOr<PtexFile> Parse(const std::vector<std::uint8_t>& bytes) {
  return ParsePtex(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                   "edits.ptx");
}

TEST(PtexEdits, BaseFileWithoutEdits) {
  StatusOr<PtexFile> f = Parse(BaseFile().Build());
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_FALSE(f->header().has_edits);
  EXPECT_EQ(f->NumStoredLevels(PtexFaceId(1)), 3);
  std::vector<float> t;
  ASSERT_TRUE(f->ReadFace(PtexFaceId(1), 2, t).ok());
  EXPECT_EQ(t, Ramp(16, 2000));
  EXPECT_EQ(f->FindMetaData("a")->AsInt32(), std::vector<std::int32_t>{1});
}

void ExpectEditsApplied(const PtexFile& f) {
  EXPECT_TRUE(f.header().has_edits);
  const PtexFaceInfo& face1 = f.face_info(PtexFaceId(1));
  EXPECT_TRUE(face1.has_edits);
  EXPECT_EQ(face1.ulog2, 3);
  EXPECT_EQ(face1.vlog2, 2);
  EXPECT_EQ(f.NumStoredLevels(PtexFaceId(1)), 1);  // stored reductions no longer apply
  std::vector<float> t;
  ASSERT_TRUE(f.ReadFace(PtexFaceId(1), 0, t).ok());
  EXPECT_EQ(t, Ramp(32, 100));
  EXPECT_FALSE(f.ReadFace(PtexFaceId(1), 1, t).ok());
  PtexEncodedFace encoded;
  EXPECT_EQ(f.ReadEncodedFace(PtexFaceId(1), encoded).message(),
            "edits.ptx: face 1 has edits: its stored levels are not one encoding of its texels");
  float v = 0;
  f.ConstantValue(PtexFaceId(1), &v);
  EXPECT_EQ(v, 115.5f);
  const PtexFaceInfo& face0 = f.face_info(PtexFaceId(0));
  EXPECT_TRUE(face0.constant);
  EXPECT_TRUE(face0.has_edits);
  ASSERT_TRUE(f.ReadFace(PtexFaceId(0), 0, t).ok());
  EXPECT_EQ(t, std::vector<float>(16, 9.0f));
  EXPECT_EQ(f.Sample(PtexFaceId(0), 0.3f, 0.3f), 9.0f);
  ASSERT_EQ(f.meta_data().size(), 2u);
  EXPECT_EQ(f.FindMetaData("a")->AsInt32(), (std::vector<std::int32_t>{7, 8}));
  EXPECT_EQ(f.FindMetaData("b")->AsString(), "edited");
  EXPECT_TRUE(f.Validate().ok());
}

TEST(PtexEdits, FaceAndMetaDataEditsAreApplied) {
  RawPtex p = BaseFile();
  p.edits = Edits();
  StatusOr<PtexFile> f = Parse(p.Build());
  ASSERT_TRUE(f.ok()) << f.status().message();
  ExpectEditsApplied(*f);
}

TEST(PtexEdits, EditDataPosZeroScansToTheEnd) {
  RawPtex p = BaseFile();
  p.edits = Edits();
  p.edit_pos_zero = true;
  StatusOr<PtexFile> f = Parse(p.Build());
  ASSERT_TRUE(f.ok()) << f.status().message();
  ExpectEditsApplied(*f);
}

TEST(PtexEdits, AnEmptyBlockEndsTheEdits) {
  RawPtex p = BaseFile();
  p.edits = {1, 0, 0, 0, 0};  // type 1, size 0
  const auto rest = Edits();
  p.edits.insert(p.edits.end(), rest.begin(), rest.end());
  StatusOr<PtexFile> f = Parse(p.Build());
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_FALSE(f->header().has_edits);
  EXPECT_FALSE(f->face_info(PtexFaceId(1)).has_edits);
}

TEST(PtexEdits, MalformedEditsAreErrors) {
  RawPtex p = BaseFile();
  std::vector<std::uint8_t> edits = Edits();
  edits[5] = 9;  // face id 9 of 2
  p.edits = edits;
  StatusOr<PtexFile> f = Parse(p.Build());
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.status().message().rfind("edits.ptx: edit block 0", 0), 0u) << f.status().message();
  edits = Edits();
  edits[1] += 1;  // edit size one byte too long: the block no longer fills it
  p.edits = edits;
  f = Parse(p.Build());
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.status().message().find("edit block"), std::string::npos) << f.status().message();
}

}  // namespace
}  // namespace dispex
