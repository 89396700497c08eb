# The installed library from a separate project: `cmake --install` of the build into a fresh
# prefix, then tests/package/consumer configured with find_package(dispex CONFIG), built and run,
# and the same program built again with nothing but `pkg-config --cflags --libs dispex`.
#   cmake -DBUILD_DIR=build -DSOURCE_DIR=. -DWORK=dir -DCXX=c++ -P check_package.cmake
set(prefix ${WORK}/prefix)
set(consumer ${SOURCE_DIR}/tests/package/consumer)
set(cage ${SOURCE_DIR}/tests/data/meshes/opensubdiv/catmark_cube.obj)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/cmake-run ${WORK}/pkg-config-run)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
run(${CMAKE_COMMAND} -S ${consumer} -B ${WORK}/build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX})
run(${CMAKE_COMMAND} --build ${WORK}/build)
run(${WORK}/build/consumer ${cage} ${WORK}/cmake-run)
message(STATUS "find_package: ${out}")

file(GLOB_RECURSE pc_files ${prefix}/*/dispex.pc)
list(LENGTH pc_files n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one dispex.pc under ${prefix}, found: ${pc_files}")
endif()
get_filename_component(pc_dir ${pc_files} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
run(pkg-config --cflags --libs dispex)
separate_arguments(flags UNIX_COMMAND "${out}")
if(NOT flags MATCHES "-ldispex")
  message(FATAL_ERROR "pkg-config --libs dispex: no -ldispex in '${out}'")
endif()
run(${CXX} -std=c++20 ${consumer}/main.cpp ${flags} -o ${WORK}/consumer-pc)
get_filename_component(libdir ${pc_dir} DIRECTORY)
set(ENV{LD_LIBRARY_PATH} ${libdir})
run(${WORK}/consumer-pc ${cage} ${WORK}/pkg-config-run)
message(STATUS "pkg-config: ${out}")
