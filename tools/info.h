// `dispex info FILE`: a summary of a mesh (OBJ, PLY), a Ptex file or a UV-space map (UDIM
// OpenEXR tiles), chosen by content.
#pragma once

#include <string>

namespace dispex::cli {

struct InfoOptions {
  std::string path;
  bool json = false;         // machine-readable summary on stdout
  bool faces = false;        // Ptex: one line per face
  int dump_face = -1;        // Ptex: print the texels of this face
  bool strict = false;       // mesh: validation warnings are errors
  bool fingerprint = false;  // mesh: print its fingerprint only
};

// Each returns the process exit code and prints to stdout (errors on stderr).
int MeshInfo(const InfoOptions& options);
int PtexInfo(const InfoOptions& options);
int UvMapInfo(const InfoOptions& options);  // UDIM OpenEXR tiles (dispex/uv_map.h)

}  // namespace dispex::cli
