// libFuzzer target for the Ptex reader (ParsePtex): any bytes must give a Status naming the
// file, or a file whose every face, level, sample and meta data item reads back consistently
// (see ExercisePtex in reader_contract.h). Half of the mutations rewrite one zlib stream of
// the file (ptex_stream_mutator.h), so the parsers behind inflation get fuzzed too.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "fuzz/ptex_stream_mutator.h"
#include "fuzz/reader_contract.h"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  dispex::fuzz::UseOneThread();
  return 0;
}

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size,
                                               std::size_t max_size, unsigned seed) {
  if (seed % 2 == 0) {
    const std::size_t n = dispex::fuzz::MutatePtexStream(data, size, max_size, seed / 2);
    if (n > 0) return n;
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  dispex::fuzz::RequireContract("ptex_fuzzer", dispex::fuzz::ExercisePtex(bytes, "fuzz.ptx"));
  return 0;
}
