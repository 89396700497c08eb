// WriteObj (dispex/mesh.h): v and f lines formatted in parallel chunks, written atomically.
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <vector>

#include "core/atomic_output.h"
#include "dispex/mesh.h"

namespace dispex {

Status WriteObj(const std::string& path, const Mesh& mesh, const std::string& header) {
  DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(path));
  DISPEX_RETURN_IF_ERROR(out.Write(header.data(), header.size()));
  constexpr std::size_t kChunk = 1 << 16;
  constexpr std::size_t kBatch = 16;  // chunks formatted in parallel before writing in order
  std::vector<fmt::memory_buffer> buffers(kBatch);
  auto emit = [&](std::size_t count, auto&& format_chunk) -> Status {
    for (std::size_t start = 0; start < count; start += kChunk * kBatch) {
      std::size_t chunks = std::min(kBatch, (count - start + kChunk - 1) / kChunk);
      tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
        buffers[c].clear();
        std::size_t begin = start + c * kChunk, end = std::min(count, begin + kChunk);
        format_chunk(buffers[c], begin, end);
      });
      for (std::size_t c = 0; c < chunks; ++c) {
        DISPEX_RETURN_IF_ERROR(out.Write(buffers[c].data(), buffers[c].size()));
      }
    }
    return Status::Ok();
  };
  DISPEX_RETURN_IF_ERROR(
      emit(mesh.num_vertices(), [&](fmt::memory_buffer& b, std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v) {
          const Float3& p = mesh.positions[v];
          fmt::format_to(std::back_inserter(b), "v {} {} {}\n", p.x, p.y, p.z);
        }
      }));
  DISPEX_RETURN_IF_ERROR(
      emit(mesh.num_faces(), [&](fmt::memory_buffer& b, std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f) {
          b.push_back('f');
          for (std::int32_t v : mesh.face(f)) fmt::format_to(std::back_inserter(b), " {}", v + 1);
          b.push_back('\n');
        }
      }));
  return out.Commit();
}

}  // namespace dispex
