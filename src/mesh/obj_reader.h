// The OBJ reader's counting pass on its own (obj_reader.cpp): a file's vertices, faces and
// face corners, without parsing it.
#pragma once

#include <string_view>

#include "dispex/mesh.h"

namespace dispex {

// The `v` and `f` lines of `bytes` and the corners on the face lines, counted as the reader
// counts them; where a face line holds a comment or a continuation, 4 corners per face.
MeshSize CountObjElements(std::string_view bytes);

}  // namespace dispex
