# dispex_warnings: the warning set every dispex target compiles with.
add_library(dispex_warnings INTERFACE)
target_compile_options(dispex_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow
  -Wnon-virtual-dtor -Wcast-align -Wunused -Woverloaded-virtual
  -Wimplicit-fallthrough)
# A precompiled header that does not match a target's flags is silently parsed again: say so.
if(DISPEX_PRECOMPILED_HEADERS)
  target_compile_options(dispex_warnings INTERFACE -Winvalid-pch)
endif()
if(DISPEX_WERROR)
  target_compile_options(dispex_warnings INTERFACE -Werror)
endif()

# dispex_options: flags every dispex target shares (sanitizers, the public include root).
# src/ is not on it: a module's internal headers are reached only through its
# dispex::<name>_internal target (see dispex_add_library).
add_library(dispex_options INTERFACE)
target_include_directories(dispex_options INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>)
if(DISPEX_SANITIZE)
  target_compile_options(dispex_options INTERFACE -fsanitize=address,undefined
    -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(dispex_options INTERFACE -fsanitize=address,undefined)
endif()
if(DISPEX_TSAN)
  if(DISPEX_SANITIZE)
    message(FATAL_ERROR "DISPEX_TSAN and DISPEX_SANITIZE cannot be combined")
  endif()
  target_compile_options(dispex_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(dispex_options INTERFACE -fsanitize=thread)
endif()

# dispex_test_options: the tests' own code is compiled at -O1 in Release builds. The code under
# test is the libraries', at the build's level (-O3); at -O1 a test source compiles 30-40%
# faster (tests/ptex/round_trip_test.cpp 7.1 -> 4.2 s), which is most of what `make test`
# compiles.
add_library(dispex_test_options INTERFACE)
target_compile_options(dispex_test_options INTERFACE $<$<CONFIG:Release>:-O1>)

# dispex_add_library(NAME SOURCES... ) : one static library per src/ folder, alias dispex::NAME,
# plus dispex::NAME_internal, an interface target that puts the module's own headers
# (src/NAME/*.h, included as "NAME/x.h") on the include path and nothing else of src/. Each
# include root under build/internal_include/NAME holds one link, NAME -> src/NAME, so a target
# sees exactly the internals it links: the module itself (PRIVATE), core's (every module builds
# on core), and, for tests and benchmarks, those they link by name. The public headers
# (include/dispex) are visible to all; tests/layering checks they point down the pipeline.
function(dispex_add_library name)
  add_library(dispex_${name} STATIC ${ARGN})
  add_library(dispex::${name} ALIAS dispex_${name})
  # Position independent: the objects also make up the shared library (libdispex) and the
  # Python extension.
  set_target_properties(dispex_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  set(root ${PROJECT_BINARY_DIR}/internal_include/${name})
  file(MAKE_DIRECTORY ${root})
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/src/${name} ${root}/${name} SYMBOLIC)
  add_library(dispex_${name}_internal INTERFACE)
  add_library(dispex::${name}_internal ALIAS dispex_${name}_internal)
  target_include_directories(dispex_${name}_internal INTERFACE $<BUILD_INTERFACE:${root}>)
  target_link_libraries(dispex_${name}_internal INTERFACE dispex_options)
  if(NOT name STREQUAL "core")
    target_link_libraries(dispex_${name}_internal INTERFACE dispex_core_internal)
    target_link_libraries(dispex_${name} PRIVATE dispex_core)
  endif()
  target_link_libraries(dispex_${name} PRIVATE dispex_warnings dispex_${name}_internal
                        PUBLIC dispex_options)
  dispex_precompiled_headers(dispex_${name} library)
endfunction()
