// The part of an interpolated face's key that reads the sculpt (its field, AddFieldKey: its grid
// and apron vertices' positions and the limit patches its apron lies on), kept in a cache folder
// for the next incremental run with the positions it was computed from and each sculpt vertex's
// home (the first Ptex face whose grid holds it). The next run compares the positions: a vertex
// that moved is read only by its home and the faces around it (WithFacesAround: the faces its
// grid meets, and those whose apron reaches into it), so those alone are keyed again and every
// other face takes its kept key, without gathering its grid. A record holds for grids of the same
// vertices (the sculpt's faces and the match's labelling), the same Ptex faces and the same
// limit patches; any other change keys every face anew.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/hash128.h"
#include "dispex/subdiv.h"
#include "extract/extract_inputs.h"

namespace dispex::extract {

struct FieldKeys {
  std::vector<Hash128> keys;  // per Ptex face: the key of what AddFieldKey adds
  // Faces whose key was taken from the cache folder's record; -1: no record was read.
  std::int64_t kept = -1;
};

// Every Ptex face's field key over `inputs.grids`. With a `cache_folder`, reads the record kept
// there for these grids and takes the kept key of every face away from the vertices that moved
// since. It writes a record when there was none, or when more than 1/16 of the faces were keyed
// again (so that a run after many edits does not key them all again); a folder that cannot be
// written only makes the next run slower. The keys are those of AddFieldKey either way.
FieldKeys ComputeFieldKeys(const ExtractInputs& inputs, std::span<const BaseFacePatch> patches,
                           const std::string& cache_folder);

}  // namespace dispex::extract
