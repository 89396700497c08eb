// libFuzzer target for the PLY reader (ParsePly: ASCII and both binary byte orders): any
// bytes must give a mesh that keeps the reader contract or a one-line Status naming the file.
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
  const std::string name = "fuzz.ply";
  dispex::ReadOptions options;
  options.threads = 1;
  const dispex::StatusOr<dispex::Mesh> mesh = dispex::ParsePly(bytes, name, options);
  dispex::fuzz::RequireContract("ply_fuzzer", dispex::fuzz::CheckMeshResult(mesh, name));
  return 0;
}
