# Precompiled headers: the standard and third-party headers most sources include, parsed once
# per kind of target instead of once per source. The first target of a kind precompiles its
# kind's headers; every later one reuses them (REUSE_FROM), which is valid only when the flags
# match: position-independent module libraries, the tool and GoogleTest executables differ,
# hence three kinds. With them precompiled, src/ptex/writer.cpp compiled in 3.6 s against 4.9 s
# and tests/core/status_test.cpp in 1.8 s against 3.1 s.
#
# The libraries (src/) use them only in the sanitizer builds. GCC's inlining is not the same
# with a precompiled header: in a Release build, src/trace/embree_tracer.cpp's
# TraceNormalsWith<PacketCaster<4>> came out at 1,054 instructions with one and 860 without.
# The Release libraries, and the benchmarks that time them, keep the code the published
# figures were measured with. The tool's own code parses options and writes reports.
#
# dispex_precompiled_headers(TARGET KIND)   KIND: library, tool or test
# Nothing happens where DISPEX_PRECOMPILED_HEADERS is OFF (the fuzz build, whose instrumented
# modules compile with flags of their own).

set(DISPEX_PCH_COMMON
  <algorithm> <array> <atomic> <cmath> <cstdint> <cstdio> <cstring> <filesystem> <fstream>
  <limits> <memory> <mutex> <optional> <random> <span> <sstream> <string> <string_view>
  <utility> <vector> <fmt/format.h> <tbb/blocked_range.h> <tbb/enumerable_thread_specific.h>
  <tbb/parallel_for.h>)
set(DISPEX_PCH_library "")
set(DISPEX_PCH_tool <CLI/CLI.hpp> <nlohmann/json.hpp>)
set(DISPEX_PCH_test <gtest/gtest.h>)

function(dispex_precompiled_headers target kind)
  if(NOT DISPEX_PRECOMPILED_HEADERS OR
     (kind STREQUAL "library" AND NOT DISPEX_SANITIZE AND NOT DISPEX_TSAN))
    return()
  endif()
  if(NOT DEFINED DISPEX_PCH_${kind})
    message(FATAL_ERROR "dispex_precompiled_headers: unknown kind '${kind}'")
  endif()
  # fmt's headers read FMT_SHARED: every target of a kind must see them as its first did.
  target_link_libraries(${target} PRIVATE fmt::fmt)
  get_property(owner GLOBAL PROPERTY DISPEX_PCH_OWNER_${kind})
  if(owner)
    target_precompile_headers(${target} REUSE_FROM ${owner})
  else()
    set_property(GLOBAL PROPERTY DISPEX_PCH_OWNER_${kind} ${target})
    target_precompile_headers(${target} PRIVATE ${DISPEX_PCH_COMMON} ${DISPEX_PCH_${kind}})
  endif()
endfunction()
