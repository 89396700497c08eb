// A structure-aware mutation for Ptex files, used by ptex_fuzzer's LLVMFuzzerCustomMutator.
//
// Most sections of a Ptex file are zlib streams whose Adler-32 checksum rejects almost every
// byte-level mutation, so the parsers behind inflation (face records, level block tables,
// meta data records) would only ever see the seed files' contents. This mutator inflates
// one stream of the input, lets libFuzzer mutate the inflated bytes, deflates them again and
// rewrites the header fields that give the stream's sizes, the way zlib-aware mutators of
// other format fuzzers do (e.g. the PNG chunk mutators of libpng's OSS-Fuzz target).
#pragma once

#include <cstddef>
#include <cstdint>

namespace dispex::fuzz {

// Mutates the Ptex file in data[0, size) in place (room for max_size bytes): one of the
// face info, constant data, level header, meta data and large meta data header streams is
// inflated, mutated with LLVMFuzzerMutate, deflated and spliced back with its size fields
// (and the offsets behind it) adjusted. Returns the new size, or 0 when the input has no
// stream it can follow or the result would not fit max_size; the caller then mutates bytes.
std::size_t MutatePtexStream(std::uint8_t* data, std::size_t size, std::size_t max_size,
                             unsigned seed);

}  // namespace dispex::fuzz
