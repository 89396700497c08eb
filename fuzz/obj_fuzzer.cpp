// libFuzzer target for the OBJ reader (ParseObj): any bytes must give a mesh that keeps the
// reader contract or a one-line Status naming the file, and the same result for any chunk
// size (the parallel reader cuts the file into chunks at logical line starts).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "dispex/mesh.h"
#include "fuzz/fuzz_support.h"
#include "fuzz/reader_contract.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  dispex::fuzz::UseOneThread();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::string name = "fuzz.obj";
  dispex::ReadOptions options;
  options.threads = 1;
  const dispex::StatusOr<dispex::Mesh> whole = dispex::ParseObj(bytes, name, options);
  dispex::fuzz::RequireContract("obj_fuzzer", dispex::fuzz::CheckMeshResult(whole, name));

  // The same bytes cut into small chunks: 1..64 bytes, chosen by the input so that a crash
  // replays, and at most about 64 chunks (each chunk maps its own index buffer).
  options.chunk_bytes = std::max<std::size_t>(size == 0 ? 1 : 1 + data[size / 2] % 64, size / 64);
  const dispex::StatusOr<dispex::Mesh> chunked = dispex::ParseObj(bytes, name, options);
  dispex::fuzz::RequireContract("obj_fuzzer", dispex::fuzz::CompareMeshResults(whole, chunked));
  return 0;
}
