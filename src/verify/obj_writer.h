// Writes a Mesh as a Wavefront OBJ (v and f lines, 1-based indices), formatted in parallel
// chunks, atomically. Floats are printed in their shortest round-trip form, so reading the
// file back gives the same positions bit for bit.
#pragma once

#include <string>

#include "dispex/mesh.h"
#include "dispex/status.h"

namespace dispex {

Status WriteObj(const std::string& path, const Mesh& mesh, const std::string& header = {});

}  // namespace dispex
