// The sculpt's half-edge adjacency alone (BuildQuadAdjacency, src/subdiv/quad_adjacency.h), the
// part of matching a refined sculpt that costs the most memory: wall and CPU seconds, the
// minor page faults and the growth of the peak resident size of each build.
//
//   adjacency_bench SCULPT [--threads N] [--repeat N] [--keep-freed-memory]
//                   [--bucket-entries N]
//
// The first build runs on fresh memory; later ones re-use what the first freed when the
// allocator keeps it (--keep-freed-memory, as the CLI does: include/dispex/allocator.h).
#include <fmt/format.h>
#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "core/system.h"
#include "dispex/allocator.h"
#include "dispex/mesh.h"
#include "subdiv/quad_adjacency.h"

namespace {

struct Usage {
  double cpu = 0;
  long faults = 0;
  long peak_kb = 0;
};

Usage Now() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  Usage u;
  u.cpu = static_cast<double>(r.ru_utime.tv_sec + r.ru_stime.tv_sec) +
          1e-6 * static_cast<double>(r.ru_utime.tv_usec + r.ru_stime.tv_usec);
  u.faults = r.ru_minflt;
  u.peak_kb = r.ru_maxrss;
  return u;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("BuildQuadAdjacency on a quad sculpt: time, page faults, peak growth");
  std::string path;
  int threads = 0, repeat = 3;
  bool keep = false;
  std::size_t bucket_entries = dispex::subdiv::kAdjacencyBucketEntries;
  app.add_option("sculpt", path, "all-quad sculpt (OBJ or PLY)")->required();
  app.add_option("--threads", threads, "worker threads (0: all)");
  app.add_option("--repeat", repeat, "builds, one after another")->check(CLI::PositiveNumber);
  app.add_flag("--keep-freed-memory", keep, "keep freed memory as the CLI does");
  app.add_option("--bucket-entries", bucket_entries, "the most half-edges bucketed at once")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  if (keep) dispex::KeepFreedMemory();
  const int n = threads > 0 ? threads : tbb::info::default_concurrency();
  tbb::global_control control(tbb::global_control::max_allowed_parallelism, n);

  dispex::StatusOr<dispex::Mesh> mesh = dispex::ReadMesh(path);
  if (!mesh.ok()) {
    fmt::print(stderr, "adjacency_bench: {}\n", mesh.status().message());
    return 1;
  }
  if (!mesh->all_quads()) {
    fmt::print(stderr, "adjacency_bench: {}: not all faces are quads\n", path);
    return 1;
  }
  fmt::print("{}: {} quads, {} vertices, {} threads\n", path, mesh->num_faces(),
             mesh->num_vertices(), n);
  for (int i = 0; i < repeat; ++i) {
    const Usage before = Now();
    dispex::Stopwatch clock;
    auto adjacency = dispex::subdiv::BuildQuadAdjacency(*mesh, bucket_entries);
    const double wall = clock.seconds();
    const Usage after = Now();
    if (!adjacency.ok()) {
      fmt::print(stderr, "adjacency_bench: {}\n", adjacency.status().message());
      return 1;
    }
    fmt::print("build {}: {:.3f} s wall, {:.3f} s CPU, {} faults, peak +{} MB\n", i + 1, wall,
               after.cpu - before.cpu, after.faults - before.faults,
               (after.peak_kb - before.peak_kb) / 1024);
  }
  return 0;
}
