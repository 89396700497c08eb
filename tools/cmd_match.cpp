// dispex match BASE SCULPT [--max-offset D] [--max-levels L] [--threads N] [--json FILE]
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "command.h"
#include "dispex/correspondence.h"
#include "dispex/files.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "flag_names.h"

namespace dispex::cli {
namespace {

constexpr FlagName kMatchFlags[] = {
    {"max_offset", "--max-offset"},
    {"max_levels", "--max-levels"},
    {"threads", "--threads"},
};

struct MatchArgs {
  std::string base_path, sculpt_path, json_path;
  MatchOptions options;
  bool quiet = false;
};

std::string MatchJson(const MatchArgs& args, const LimitSurface& surface, const Mesh& sculpt,
                      const SculptCorrespondence& c) {
  nlohmann::ordered_json j;
  j["base"] = args.base_path;
  j["sculpt"] = args.sculpt_path;
  j["levels"] = c.levels;
  j["reversed"] = c.reversed;
  j["components"] = c.components;
  j["ptex_faces"] = surface.num_ptex_faces();
  j["hole_ptex_faces"] = surface.stats().hole_ptex_faces;
  j["sculpt_vertices"] = sculpt.num_vertices();
  j["sculpt_faces"] = sculpt.num_faces();
  j["max_offset"] = c.max_offset;
  j["rms_offset"] = c.rms_offset;
  j["offset_limit"] = c.offset_limit;
  j["checked_vertices"] = c.checked_vertices;
  const int worst = c.worst_vertex.value;
  j["worst_vertex"] = {{"vertex", worst},
                       {"ptex_face", c.vertex_faces[worst].value},
                       {"u", c.vertex_uvs[2 * worst]},
                       {"v", c.vertex_uvs[2 * worst + 1]}};
  j["seconds"] = c.seconds;
  return j.dump(2) + "\n";
}

int RunMatch(MatchArgs& args) {
  const Status outputs = CheckOutputs({{"--json", args.json_path}});
  if (!outputs.ok()) return ReportFailure(outputs, 2);
  ReadOptions read;
  read.threads = args.options.threads;
  auto base = ReadMesh(args.base_path, read);
  if (!base.ok()) return ReportFailure(base.status());
  if (!args.quiet) {
    for (const std::string& w : IgnoredTagWarnings(*base)) {
      fmt::print(stderr, "dispex: warning: {}\n", w);
    }
  }
  auto surface = LimitSurface::Build(*base);
  if (!surface.ok()) return ReportFailure(surface.status());
  auto sculpt = ReadMesh(args.sculpt_path, read);
  if (!sculpt.ok()) return ReportFailure(sculpt.status());
  MatchOptions options = args.options;
  options.accept_reversed = true;  // as extract does; said below
  auto c = MatchRefinedSculpt(*surface, *sculpt, options);
  if (!c.ok()) return ReportFailure(c.status(), kMatchFlags);
  if (!args.json_path.empty()) {
    const std::string json = MatchJson(args, *surface, *sculpt, *c);
    Status written = WriteFileAtomically(args.json_path, json.data(), json.size());
    if (!written.ok()) return ReportFailure(written.WithPrefix("--json"));
  }
  if (!args.quiet) {
    const int worst = c->worst_vertex.value;
    fmt::print("level {} (the sculpt is {} refined {} times)\n", c->levels, args.base_path,
               c->levels);
    if (c->reversed) {
      fmt::print(
          "reversed (every sculpt face winds the other way from the cage's: flipped normals; "
          "extract reads it reversed)\n");
    }
    fmt::print("components {}\n", c->components);
    fmt::print("ptex faces {} ({} holes)\n", surface->num_ptex_faces(),
               surface->stats().hole_ptex_faces);
    fmt::print("sculpt vertices {}\n", sculpt->num_vertices());
    fmt::print("sculpt faces {}\n", sculpt->num_faces());
    fmt::print("max offset {:.6g} (limit {:.6g})\n", c->max_offset, c->offset_limit);
    fmt::print("rms offset {:.6g} ({} vertices checked)\n", c->rms_offset, c->checked_vertices);
    fmt::print("worst vertex {} (Ptex face {} at ({}, {}))\n", worst, c->vertex_faces[worst].value,
               c->vertex_uvs[2 * worst], c->vertex_uvs[2 * worst + 1]);
    fmt::print("seconds {:.3f}\n", c->seconds);
  }
  return 0;
}

void SetupMatch(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<MatchArgs>();
  MatchOptions& o = args->options;
  CLI::App* cmd = app.add_subcommand(
      "match",
      "Decide whether SCULPT is BASE refined L times (Catmull-Clark, quads, any numbering) with "
      "its vertices moved (its faces wound either way), and find every sculpt vertex's Ptex "
      "face and (u, v) on BASE; exit 1 with the reason when it is not");
  cmd->add_option("base", args->base_path, "base cage (.obj, .ply)")->required();
  cmd->add_option("sculpt", args->sculpt_path, "sculpt (.obj, .ply)")->required();
  cmd->add_option("--max-offset", o.max_offset,
                  "reject when a sculpt vertex is farther than this from its point on the "
                  "limit surface, object units (default: 15% of the base's bounding-box "
                  "diagonal)")
      ->check(Positive());
  cmd->add_option("--max-levels", o.max_levels, "refinement levels tried, 0..max")
      ->check(CLI::Range(0, 7))
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "worker threads (0: all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  cmd->add_option("--json", args->json_path, "write the facts as JSON to this file");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args, &exit_code] { exit_code = RunMatch(*args); });
}

}  // namespace

DISPEX_REGISTER_COMMAND(45, SetupMatch);

}  // namespace dispex::cli
