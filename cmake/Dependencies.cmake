# Every dependency comes from a Debian package (scripts/install-deps.sh) and is found here,
# once, for the whole build. Each library links only what it includes.
find_package(Threads REQUIRED)
find_package(PkgConfig REQUIRED)
# Debian's OpenSubdivConfig.cmake names static libraries the package does not ship, so the
# shared CPU library is located directly.
find_path(OPENSUBDIV_INCLUDE_DIR opensubdiv/far/topologyRefiner.h REQUIRED)
find_library(OPENSUBDIV_CPU_LIBRARY NAMES osdCPU REQUIRED)
add_library(OpenSubdiv::osdCPU UNKNOWN IMPORTED)
set_target_properties(OpenSubdiv::osdCPU PROPERTIES
  IMPORTED_LOCATION ${OPENSUBDIV_CPU_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${OPENSUBDIV_INCLUDE_DIR})
find_package(embree 3 REQUIRED CONFIG)
find_package(TBB REQUIRED CONFIG)
find_package(FastFloat REQUIRED CONFIG)
find_package(CLI11 REQUIRED CONFIG)
find_package(fmt REQUIRED CONFIG)
find_package(nlohmann_json 3 REQUIRED CONFIG)
find_package(PNG REQUIRED)
find_package(ZLIB REQUIRED)
find_package(OpenEXR 3 REQUIRED CONFIG)
pkg_check_modules(LIBDEFLATE REQUIRED IMPORTED_TARGET libdeflate)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)
pkg_check_modules(FFTW3F REQUIRED IMPORTED_TARGET fftw3f)
# three.js for the pages `dispex view` writes (src/view): Debian's libjs-three (r111), embedded
# into the library when it is built, so the page needs nothing installed where it is opened.
find_file(DISPEX_THREE_JS three.min.js PATHS /usr/share/javascript/three NO_DEFAULT_PATH
  DOC "three.js (three.min.js, Debian's libjs-three)")
find_file(DISPEX_THREE_ORBIT_CONTROLS_JS OrbitControls.js
  PATHS /usr/share/javascript/three/examples/js/controls NO_DEFAULT_PATH
  DOC "three.js's OrbitControls.js (examples/js/controls, Debian's libjs-three)")
if(NOT DISPEX_THREE_JS OR NOT DISPEX_THREE_ORBIT_CONTROLS_JS)
  message(FATAL_ERROR "three.js not found: install Debian's libjs-three (scripts/install-deps.sh), "
    "or give -DDISPEX_THREE_JS=.../three.min.js -DDISPEX_THREE_ORBIT_CONTROLS_JS=.../OrbitControls.js")
endif()
if(DISPEX_BUILD_PYTHON)
  # Debian's interpreter, the one python3-numpy and python3-pytest are installed for
  # (scripts/install-deps.sh), ahead of any other python3 on PATH; -DPython_EXECUTABLE=...
  # picks another. pybind11 builds against the Python found here.
  if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python 3 REQUIRED COMPONENTS Interpreter Development.Module)
  find_package(pybind11 2.6 REQUIRED CONFIG)
endif()
if(DISPEX_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(DISPEX_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
