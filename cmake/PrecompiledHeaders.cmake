# Precompiled headers: the standard and third-party headers most sources include, parsed once
# per kind of target instead of once per source. Each kind has one owner, an object library of
# an empty source compiled with that kind's flags; every target of the kind reuses the owner's
# header (REUSE_FROM), which is valid only when the flags match: position-independent module
# libraries, the tool and GoogleTest executables differ, hence three owners. Parsing these
# headers was 30-45% of compiling a typical source.
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

function(dispex_pch_owner kind)
  set(owner dispex_pch_${kind})
  if(TARGET ${owner})
    return()
  endif()
  set(source ${PROJECT_BINARY_DIR}/pch/${kind}.cpp)
  file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/pch)
  file(WRITE ${source} "// The owner of dispex's precompiled ${kind} headers (cmake/PrecompiledHeaders.cmake).\n")
  add_library(${owner} OBJECT ${source})
  target_link_libraries(${owner} PRIVATE dispex_warnings dispex_options fmt::fmt TBB::tbb)
  set(headers ${DISPEX_PCH_COMMON})
  if(kind STREQUAL "library")
    set_target_properties(${owner} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  elseif(kind STREQUAL "tool")
    target_link_libraries(${owner} PRIVATE CLI11::CLI11 nlohmann_json::nlohmann_json)
    list(APPEND headers <CLI/CLI.hpp> <nlohmann/json.hpp>)
  elseif(kind STREQUAL "test")
    target_link_libraries(${owner} PRIVATE GTest::gtest dispex_test_options)
    list(APPEND headers <gtest/gtest.h>)
  else()
    message(FATAL_ERROR "dispex_precompiled_headers: unknown kind '${kind}'")
  endif()
  target_precompile_headers(${owner} PRIVATE ${headers})
endfunction()

function(dispex_precompiled_headers target kind)
  if(NOT DISPEX_PRECOMPILED_HEADERS OR
     (kind STREQUAL "library" AND NOT DISPEX_SANITIZE AND NOT DISPEX_TSAN))
    return()
  endif()
  dispex_pch_owner(${kind})
  # fmt's headers read FMT_SHARED: a target must see them as the owner did.
  target_link_libraries(${target} PRIVATE fmt::fmt)
  target_precompile_headers(${target} REUSE_FROM dispex_pch_${kind})
endfunction()
