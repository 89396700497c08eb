// One shape's extraction from its inputs on, shared by Extract (one shape read from its files)
// and ExtractAsset (the shapes of an asset, read once and split), and the thread arena both
// run in.
#pragma once

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <optional>

#include "core/system.h"
#include "dispex/extract.h"
#include "extract/extract_inputs.h"
#include "extract/incremental/shard_parts.h"

namespace dispex::extract {

// ExtractOptions::max_memory, or the memory the machine has available.
std::uint64_t MemoryLimit(const ExtractOptions& options);

// A report holding the options, paths, version and thread count.
ExtractReport StartReport(const ExtractOptions& options, int threads);

// Everything after the inputs: the incremental check, BVH, settings, face keys, faces, edges,
// totals and the map. `total_clock` started with the shape's work. A shard
// (options.shard_count) stops after its faces' first pass and writes a part; with `parts`
// (CheckShardParts'), the faces' first pass is taken from them (a merge).
StatusOr<ExtractReport> ExtractShape(const ExtractOptions& options, ExtractInputs inputs,
                                     ExtractReport report, const Stopwatch& total_clock,
                                     std::vector<ShardPart>* parts = nullptr);

// Runs work(threads) in an arena of `threads` threads (0: all cores), every parallel loop
// (Embree's BVH build included) limited to them -- more than the machine's cores if asked: the
// maps are the same at any count.
template <class Work>
auto RunInArena(int threads, Work work) {
  std::optional<tbb::global_control> thread_limit;
  if (threads > 0) {
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                         static_cast<std::size_t>(threads));
  }
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.initialize();
  const int used =
      std::min(arena.max_concurrency(), static_cast<int>(tbb::global_control::active_value(
                                            tbb::global_control::max_allowed_parallelism)));
  return arena.execute([&] { return work(used); });
}

}  // namespace dispex::extract
