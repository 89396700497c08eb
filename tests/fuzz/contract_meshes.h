// Small meshes that keep the reader contract, for the tests that break it by hand.
#pragma once

#include <string>

#include "dispex/mesh.h"

namespace dispex::fuzz_test {

// One triangle, with the spare capacity after the last position that the contract asks for.
inline Mesh Triangle(const std::string& name) {
  Mesh mesh;
  mesh.source = name;
  mesh.positions.reserve(4);
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.face_offsets = {0, 3};
  mesh.face_indices = {0, 1, 2};
  return mesh;
}

// The same triangle with a UV at each corner.
inline Mesh TexturedTriangle(const std::string& name) {
  Mesh mesh = Triangle(name);
  mesh.uvs = {0, 0, 1, 0, 0, 1};
  mesh.face_uv_indices = {0, 1, 2};
  return mesh;
}

}  // namespace dispex::fuzz_test
