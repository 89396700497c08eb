// The memory checks of an extraction (step 1, extract_inputs.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "dispex/extract.h"
#include "dispex/status.h"

namespace dispex::extract {

// Memory an extraction is estimated to need, in bytes: before reading, from the input file
// sizes (mesh arrays take about half an OBJ's bytes); after reading, from the sculpt's
// arrays, its BVH (about 80 bytes per primitive at medium quality) and the output's compressed
// blocks. The check fails with a message giving the estimate and the limit.
Status CheckMemoryBeforeReading(const ExtractOptions& options, std::uint64_t limit);
Status CheckMemoryForSculpt(std::size_t sculpt_vertices, std::size_t sculpt_faces,
                            std::size_t sculpt_indices, std::uint64_t base_texels,
                            std::uint64_t limit);

}  // namespace dispex::extract
