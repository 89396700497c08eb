# The module layering (docs/ARCHITECTURE.md, "Modules"), checked over the sources:
#   cmake -DSOURCE_DIR=<repo> -P cmake/CheckLayering.cmake
# Run by ctest as `layering`. Data flows one way, core -> mesh -> subdiv -> trace -> spectral ->
# ptex -> extract, with verify and render above, side by side, and view (review pages) above
# them. A file of a module may include the public headers (include/dispex) of its own and
# lower modules, and the internal headers
# (src/<module>) of its own module and of core; a public header may include the public headers
# of its own and lower modules. The include paths already keep other modules' internals out of
# reach (cmake/Options.cmake); this check also covers the public headers, which every target
# sees.

# `front` is the front door, include/dispex/dispex.h: public headers only, above every module.
set(levels core 0 mesh 1 subdiv 2 trace 3 spectral 4 ptex 5 uvmap 5 extract 6 verify 7 render 7
  view 8 front 9)
# The module each public header belongs to.
set(owners
  status core ids core version core files core cancel core progress core allocator core
  mesh mesh shapes mesh mesh_summary mesh
  subdiv subdiv vector_space subdiv correspondence subdiv
  trace trace
  spectral spectral
  ptex ptex ptex_sampler ptex ptex_describe ptex
  uv_charts uvmap uv_map uvmap
  extract extract
  verify verify
  render render
  view view
  dispex front)

function(lookup list key out)
  list(FIND ${list} ${key} i)
  if(i EQUAL -1)
    set(${out} "" PARENT_SCOPE)
  else()
    math(EXPR i "${i} + 1")
    list(GET ${list} ${i} value)
    set(${out} ${value} PARENT_SCOPE)
  endif()
endfunction()

set(errors "")

# check_file(FILE MODULE): the includes of FILE, which belongs to MODULE.
function(check_file file module)
  lookup(levels ${module} level)
  # "dir/name.h" or, inside a module, "dir/sub/name.h": the module is the first folder.
  file(STRINGS ${file} lines REGEX "^#include \"[a-z_]+/([a-z_]+/)?[a-z_0-9]+\\.h\"")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE "^#include \"([a-z_]+)/([a-z_]+/)?([a-z_0-9]+)\\.h\".*" "\\1;\\3" parts
                         "${line}")
    list(GET parts 0 dir)
    list(GET parts 1 name)
    if(dir STREQUAL "dispex")
      if(name STREQUAL "version")
        continue()
      endif()
      lookup(owners ${name} owner)
      if(owner STREQUAL "")
        string(APPEND errors "${file}: dispex/${name}.h has no module in cmake/CheckLayering.cmake\n")
        continue()
      endif()
      lookup(levels ${owner} other)
      if(NOT owner STREQUAL module AND NOT other LESS level)
        string(APPEND errors "${file} (${module}) includes dispex/${name}.h (${owner}): not below it\n")
      endif()
    else()
      lookup(levels ${dir} other)
      if(NOT other STREQUAL "" AND NOT dir STREQUAL module AND NOT dir STREQUAL "core")
        string(APPEND errors "${file} (${module}) includes the internal header ${dir}/${name}.h\n")
      endif()
    endif()
  endforeach()
  set(errors "${errors}" PARENT_SCOPE)
endfunction()

file(GLOB public_headers ${SOURCE_DIR}/include/dispex/*.h)
foreach(header IN LISTS public_headers)
  get_filename_component(name ${header} NAME_WE)
  lookup(owners ${name} owner)
  if(owner STREQUAL "")
    string(APPEND errors "${header}: no module in cmake/CheckLayering.cmake\n")
  else()
    check_file(${header} ${owner})
  endif()
endforeach()

foreach(module core mesh subdiv trace spectral ptex uvmap extract verify render view)
  file(GLOB_RECURSE sources ${SOURCE_DIR}/src/${module}/*.h ${SOURCE_DIR}/src/${module}/*.cpp)
  foreach(source IN LISTS sources)
    check_file(${source} ${module})
  endforeach()
endforeach()

if(errors)
  message(FATAL_ERROR "layering broken:\n${errors}")
endif()
message(STATUS "layering: every include points down the pipeline")
