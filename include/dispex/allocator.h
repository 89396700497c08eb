// The process's allocator, for a program's start: the library itself leaves it alone.
#pragma once

namespace dispex {

// Asks glibc to keep the memory the process frees for its next allocations instead of returning
// it to the system (M_MMAP_MAX 0, a trim threshold of 2 GB), in one heap for all threads
// (M_ARENA_MAX 1: every thread's blocks re-use what any thread freed, instead of each worker
// growing a heap of its own): an extraction's phases free large arrays and allocate others,
// and every page the system hands out again costs a page fault on its first write
// (docs/bench-notes/extract.md, "Memory"). Call it before any
// thread starts. Does nothing, and returns false, where the C library is not glibc, when
// GLIBC_TUNABLES sets a malloc tunable (the user's own settings win) or when the environment
// sets DISPEX_KEEP_FREED_MEMORY=0.
bool KeepFreedMemory();

}  // namespace dispex
