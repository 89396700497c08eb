# libdispex, the installed library (docs/LIBRARY.md): the objects of every module (src/*) as one
# shared library with a SONAME, the public headers (include/dispex and the generated
# dispex/version.h), a CMake package (find_package(dispex CONFIG) -> dispex::dispex) and a
# pkg-config file. The third-party libraries are linked PRIVATE: the public headers name none
# of their types, and the dynamic linker finds them through libdispex's own dependencies.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(DISPEX_MODULES core mesh subdiv trace spectral ptex uvmap extract verify render view)
set(module_objects "")
foreach(module IN LISTS DISPEX_MODULES)
  list(APPEND module_objects $<TARGET_OBJECTS:dispex_${module}>)
endforeach()
add_library(dispex_library SHARED ${module_objects})
add_library(dispex::dispex ALIAS dispex_library)
# 0.x: a minor release may change the ABI, so the SONAME carries major.minor.
set_target_properties(dispex_library PROPERTIES
  OUTPUT_NAME dispex EXPORT_NAME dispex LINKER_LANGUAGE CXX
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
target_link_libraries(dispex_library PRIVATE $<BUILD_INTERFACE:dispex_options>
  OpenSubdiv::osdCPU embree TBB::tbb PkgConfig::FFTW3F PkgConfig::LIBDEFLATE PkgConfig::XXHASH
  PNG::PNG ZLIB::ZLIB OpenEXR::OpenEXR fmt::fmt Threads::Threads)
target_link_options(dispex_library PRIVATE -Wl,--no-undefined)
target_include_directories(dispex_library PUBLIC
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/generated>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_compile_features(dispex_library PUBLIC cxx_std_20)

set(DISPEX_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/dispex)
install(TARGETS dispex_library EXPORT dispexTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} NAMELINK_COMPONENT Development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/dispex DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/generated/dispex/version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dispex)
install(EXPORT dispexTargets NAMESPACE dispex:: DESTINATION ${DISPEX_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/package/dispexConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/dispexConfig.cmake INSTALL_DESTINATION ${DISPEX_CMAKE_DIR})
# 0.x: only the same minor version is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/dispexConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/package/dispexConfig.cmake
  ${PROJECT_BINARY_DIR}/package/dispexConfigVersion.cmake DESTINATION ${DISPEX_CMAKE_DIR})

# pkg-config: relocatable (paths from the .pc file's own folder), so a copy installed with
# `cmake --install --prefix P` answers for P.
file(RELATIVE_PATH DISPEX_PC_TO_PREFIX
  /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${PROJECT_SOURCE_DIR}/cmake/package/dispex.pc.in
  ${PROJECT_BINARY_DIR}/package/dispex.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/package/dispex.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
