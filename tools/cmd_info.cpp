#include "command.h"
#include "dispex/files.h"
#include "dispex/ptex_describe.h"
#include "dispex/uv_map.h"
#include "info.h"

namespace dispex::cli {
namespace {

void SetupInfo(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "info",
      "Summarise a mesh (OBJ, PLY), a Ptex file or a UV-space map (UDIM OpenEXR tiles): counts, "
      "tags, bounds, warnings");
  cmd->add_option("file", options->path,
                  "mesh (.obj, .ply), Ptex (.ptx) file, or UV map (DIR/NAME.<UDIM>.exr or a tile)")
      ->required();
  cmd->add_flag("--json", options->json, "print a machine-readable JSON summary");
  cmd->add_flag("--faces", options->faces, "Ptex: one line per face");
  cmd->add_option("--dump", options->dump_face, "Ptex: print the texels of this face id");
  cmd->add_flag("--strict", options->strict, "mesh: treat validation warnings as errors");
  cmd->add_flag("--fingerprint", options->fingerprint,
                "mesh: print only its fingerprint, as a map records the meshes it was made from "
                "(dispex:base_fingerprint, dispex:sculpt_fingerprint)");
  cmd->callback([options, &exit_code] {
    if (options->path.find("<UDIM>") != std::string::npos) {
      exit_code = UvMapInfo(*options);
      return;
    }
    Status readable = CheckReadableFile(options->path);
    if (!readable.ok()) {
      exit_code = ReportFailure(readable);
      return;
    }
    exit_code = HasPtexMagic(options->path)  ? PtexInfo(*options)
                : IsUvMapPath(options->path) ? UvMapInfo(*options)
                                             : MeshInfo(*options);
  });
}

}  // namespace

DISPEX_REGISTER_COMMAND(10, SetupInfo);

}  // namespace dispex::cli
