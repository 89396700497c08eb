// dispex convert IN OUT: a mesh from OBJ or PLY to OBJ or PLY (by OUT's name), e.g. a large
// sculpt to binary PLY, which reads several times faster than OBJ (docs/bench-notes/extract.md,
// "Reading the sculpt").
#include <fmt/format.h>

#include <chrono>
#include <string>
#include <vector>

#include "command.h"
#include "dispex/mesh.h"

namespace dispex::cli {
namespace {

struct ConvertArgs {
  std::string input;
  std::string output;
  bool quiet = false;
};

// What neither writer holds (both write vertices and faces only), one warning each.
std::vector<std::string> Dropped(const Mesh& mesh) {
  std::vector<std::string> dropped;
  if (mesh.has_uvs()) dropped.push_back("texture coordinates");
  const SubdivTags& tags = mesh.tags;
  if (!tags.empty() || tags.boundary_from_file || tags.crease_method_from_file ||
      tags.triangles_from_file) {
    dropped.push_back("subdivision tags");
  }
  if (mesh.group_names.size() > 1) dropped.push_back("groups");
  return dropped;
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int RunConvert(const ConvertArgs& args) {
  const MeshFormat format = MeshFormatOfName(args.output);
  if (format == MeshFormat::kUnknown) {
    return ReportFailure(
        Status::Error(fmt::format("{}: the output must be named .obj or .ply", args.output)));
  }
  if (args.output == args.input) {
    return ReportFailure(
        Status::Error(fmt::format("{}: the output must differ from the input", args.output)));
  }
  const Status outputs = CheckOutputs({{"OUTPUT", args.output}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  const auto read_start = std::chrono::steady_clock::now();
  auto mesh = ReadMesh(args.input);
  if (!mesh.ok()) return ReportFailure(mesh.status());
  const double read_seconds = SecondsSince(read_start);
  for (const std::string& what : Dropped(*mesh)) {
    fmt::print(stderr, "dispex: warning: {}: {} not written to {}\n", args.input, what,
               args.output);
  }
  const auto write_start = std::chrono::steady_clock::now();
  Status written = WriteMesh(args.output, *mesh, fmt::format("dispex convert: {}", args.input));
  if (!written.ok()) return ReportFailure(written);
  if (!args.quiet) {
    fmt::print("{} ({} vertices, {} faces) -> {}; read {:.2f}s, write {:.2f}s\n", args.input,
               mesh->num_vertices(), mesh->num_faces(), args.output, read_seconds,
               SecondsSince(write_start));
  }
  return 0;
}

void SetupConvert(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Write a mesh (OBJ, PLY) as OBJ or binary PLY, by OUT's name: binary PLY reads several "
      "times faster, for large sculpts");
  cmd->add_option("input", args->input, "mesh to read (.obj, .ply)")->required();
  cmd->add_option("output", args->output, "mesh to write (.obj, .ply)")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args, &exit_code] { exit_code = RunConvert(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(15, SetupConvert);

}  // namespace dispex::cli
