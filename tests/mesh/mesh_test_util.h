// Helpers shared by the mesh module's tests.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include "dispex/mesh.h"

namespace dispex::testing {

inline std::string DataPath(const std::string& relative) {
  return (std::filesystem::path(DISPEX_TEST_DATA_DIR) / relative).string();
}

// A temporary file name unique to the running test and process (ctest runs tests in parallel,
// also from several build folders).
inline std::string TempPath(const std::string& suffix) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  return ::testing::TempDir() + "/dispex_" + test->test_suite_name() + "_" + test->name() + "_" +
         std::to_string(::getpid()) + suffix;
}

// Parses OBJ text that must be valid; fails the test (and returns an empty mesh) otherwise.
inline Mesh ObjOrDie(std::string_view text, const ReadOptions& options = {}) {
  StatusOr<Mesh> mesh = ParseObj(text, "test.obj", options);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

// The error message of parsing OBJ text that must be invalid.
inline std::string ObjError(std::string_view text, const ReadOptions& options = {}) {
  StatusOr<Mesh> mesh = ParseObj(text, "test.obj", options);
  EXPECT_FALSE(mesh.ok()) << "parsed without error:\n" << text;
  return mesh.ok() ? std::string() : mesh.status().message();
}

// Field-by-field equality of two meshes, with a message naming the first difference.
inline ::testing::AssertionResult SameMesh(const Mesh& a, const Mesh& b) {
  if (a.positions.size() != b.positions.size()) {
    return ::testing::AssertionFailure()
           << "vertex counts " << a.positions.size() << " vs " << b.positions.size();
  }
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    if (std::memcmp(&a.positions[i], &b.positions[i], sizeof(Float3)) != 0) {
      return ::testing::AssertionFailure() << "position " << i << " differs";
    }
  }
  if (a.face_offsets != b.face_offsets) return ::testing::AssertionFailure() << "face offsets";
  if (a.face_indices != b.face_indices) return ::testing::AssertionFailure() << "face indices";
  if (a.face_groups != b.face_groups) return ::testing::AssertionFailure() << "face groups";
  if (a.group_names != b.group_names) return ::testing::AssertionFailure() << "group names";
  if (a.uvs.size() != b.uvs.size() ||
      (!a.uvs.empty() && std::memcmp(a.uvs.data(), b.uvs.data(), a.uvs.size() * 4) != 0)) {
    return ::testing::AssertionFailure() << "uvs";
  }
  if (a.face_uv_indices != b.face_uv_indices) {
    return ::testing::AssertionFailure() << "face uv indices";
  }
  if (a.faces_without_uvs != b.faces_without_uvs) {
    return ::testing::AssertionFailure()
           << "faces without uvs " << a.faces_without_uvs << " vs " << b.faces_without_uvs;
  }
  const SubdivTags& s = a.tags;
  const SubdivTags& t = b.tags;
  if (s.creases.size() != t.creases.size() || s.corners.size() != t.corners.size() ||
      s.holes.size() != t.holes.size() || s.boundary != t.boundary ||
      s.boundary_from_file != t.boundary_from_file || s.crease_method != t.crease_method ||
      s.crease_method_from_file != t.crease_method_from_file || s.triangles != t.triangles ||
      s.triangles_from_file != t.triangles_from_file ||
      s.ignored_tag_names != t.ignored_tag_names) {
    return ::testing::AssertionFailure() << "tag counts or settings";
  }
  for (std::size_t i = 0; i < s.creases.size(); ++i) {
    if (s.creases[i].v0 != t.creases[i].v0 || s.creases[i].v1 != t.creases[i].v1 ||
        s.creases[i].sharpness != t.creases[i].sharpness) {
      return ::testing::AssertionFailure() << "crease " << i;
    }
  }
  for (std::size_t i = 0; i < s.corners.size(); ++i) {
    if (s.corners[i].vertex != t.corners[i].vertex ||
        s.corners[i].sharpness != t.corners[i].sharpness) {
      return ::testing::AssertionFailure() << "corner " << i;
    }
  }
  for (std::size_t i = 0; i < s.holes.size(); ++i) {
    if (s.holes[i] != t.holes[i]) return ::testing::AssertionFailure() << "hole " << i;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace dispex::testing
