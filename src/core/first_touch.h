// Growing a large array so that its fresh pages are first touched by every thread.
//
// The first write to a fresh page costs a page fault, and on the virtual machines the project
// is measured on that fault is most of what clearing a large array costs
// (docs/bench-notes/extract.md, "Memory"). std::vector's resize and assign clear on the calling
// thread alone; after ReserveTouched the clearing that follows runs over resident pages, at memory
// speed. Uses the current TBB arena: include only where TBB is linked.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace dispex {

// Arrays smaller than this are only reserved: their faults cost less than a parallel loop.
inline constexpr std::size_t kFirstTouchBytes = std::size_t{1} << 20;

// Asks the kernel to fault in, writable, every page that [begin, begin + bytes) reaches
// (Linux's MADV_POPULATE_WRITE, 5.14 and later), in one call instead of one fault per page.
// Returns false where it cannot (an older kernel, another system): the pages are then faulted
// in by their first write as before. The range must lie in memory the process may write.
bool PopulatePages(void* begin, std::size_t bytes);
// The same for reading (MADV_POPULATE_READ): maps the pages of a mapped file's range that the
// page cache holds (and reads those it does not) in one call.
bool PopulateMappedPages(const void* begin, std::size_t bytes);

// Writes one byte in every page of [begin, begin + bytes), raw storage no object lives in yet,
// from the threads of the current arena, each populating its part first (PopulatePages): on
// the virtual machines of docs/BENCHMARKS.md that halves what the first touch costs.
inline void TouchPages(void* begin, std::size_t bytes) {
  constexpr std::size_t kPage = 4096;
  auto* first = static_cast<unsigned char*>(begin);
  const std::size_t pages = (bytes + kPage - 1) / kPage;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pages, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      PopulatePages(first + r.begin() * kPage,
                                    std::min(bytes, r.end() * kPage) - r.begin() * kPage);
                      for (std::size_t p = r.begin(); p != r.end(); ++p) first[p * kPage] = 0;
                    });
}

// Reserves room for `n` elements in `v` and, where that allocates at least kFirstTouchBytes,
// touches the new storage beyond the elements (TouchPages). The elements are not constructed
// here: the caller's resize, assign or insert does that.
template <class T, class A>
void ReserveTouched(std::vector<T, A>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  const std::size_t bytes = (v.capacity() - v.size()) * sizeof(T);
  if (bytes >= kFirstTouchBytes) TouchPages(v.data() + v.size(), bytes);
}

// v.assign(n, value) over storage that ReserveTouched first touched.
template <class T, class A>
void AssignTouched(std::vector<T, A>& v, std::size_t n, const T& value) {
  v.clear();
  ReserveTouched(v, n);
  v.assign(n, value);
}

}  // namespace dispex
