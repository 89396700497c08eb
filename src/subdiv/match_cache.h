// A match of the sculpt kept in a cache folder for the next match of a sculpt with the same
// faces (an incremental run after an edit of positions only): the cells' labels, what the
// seeding read of the positions to choose its labelling, and the position check per Ptex face.
// Which labelling a match finds depends on the positions only through that choice
// (correspondence.cpp, step 3); the steps after it read the topology alone. So a kept match is the
// match of a sculpt with the same faces when the seeding, re-run on the kept record with the new
// positions, chooses the same labelling (Matcher::SeedsStillChosen); the position check is then run
// anew on the faces whose points moved. A file is keyed by the sculpt's faces, the cage and its
// limit surface (topology, positions, tags and options), the offset limit and the version, and
// checked whole by a hash of its content.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"

namespace dispex::subdiv::matching {

// What SeedComponent read of the positions for one base component, and what it chose.
struct ComponentSeeds {
  // The base vertex the seeding starts from (its class is the rarest in the sculpt: the faces
  // decide it).
  std::int32_t seed_vertex = -1;
  // The sculpt vertices Candidates ranked (those of the seed vertex's class, in the component's
  // size), ascending, and the candidates it gave, best first.
  std::vector<std::uint32_t> class_vertices;
  std::vector<std::uint32_t> candidates;
  // Per labelling tried, in order: whether its walk over the component's faces completed (the
  // positions aside), and where its list of base vertices met ends in met_w / met_x.
  std::vector<std::uint8_t> walk_complete;
  std::vector<std::uint32_t> met_end;
  // Each labelling's base vertices, in the order it met them, and the sculpt vertex there.
  std::vector<std::int32_t> met_w, met_x;
  std::int32_t chosen = -1;  // the labelling chosen
};

// The position check of a match, per Ptex face: which points of its lattice are its own (the
// vertex's home is there), the key of the positions at every point of its lattice, and what it
// measured. A face whose lattice keeps those positions measures the same.
struct PositionChecks {
  std::vector<std::uint8_t> own;      // per lattice point, the faces' lattices in order
  std::vector<Hash128> lattice_keys;  // per Ptex face
  std::vector<double> max;            // per Ptex face: the largest squared offset (-1: none)
  std::vector<double> sum_squares;    // per Ptex face
  std::vector<std::int32_t> worst;    // per Ptex face: the vertex of max (-1: none)
  std::vector<std::uint64_t> count;   // per Ptex face: vertices checked
};

struct MatchRecord {
  std::int32_t levels = 0;
  std::vector<std::uint32_t> cell_labels;  // SculptCorrespondence::cell_labels
  std::vector<ComponentSeeds> components;
  PositionChecks checks;
};

inline constexpr std::uint64_t kMatchCacheBytes = std::uint64_t{1} << 30;

// The file of `key` in `folder`.
std::string MatchRecordPath(const std::string& folder, const Hash128& key);
// The record in `path` when it is there, whole and of `key` and `num_cells` cells.
std::optional<MatchRecord> ReadMatchRecord(const std::string& path, const Hash128& key,
                                           std::size_t num_cells);
// Writes the record (a folder that cannot be written is only a slower next run), then keeps the
// folder's match files within kMatchCacheBytes, the least recently written first out.
void WriteMatchRecord(const std::string& path, const Hash128& key, std::int32_t levels,
                      std::span<const std::uint32_t> cell_labels,
                      std::span<const ComponentSeeds> components, const PositionChecks& checks);

}  // namespace dispex::subdiv::matching
