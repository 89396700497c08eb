# dispex_warnings: the warning set every dispex target compiles with.
add_library(dispex_warnings INTERFACE)
target_compile_options(dispex_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow
  -Wnon-virtual-dtor -Wcast-align -Wunused -Woverloaded-virtual
  -Wimplicit-fallthrough)
if(DISPEX_WERROR)
  target_compile_options(dispex_warnings INTERFACE -Werror)
endif()

# dispex_options: flags every dispex target shares (sanitizers, include root).
add_library(dispex_options INTERFACE)
target_include_directories(dispex_options INTERFACE
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
  $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>)
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

# dispex_add_library(NAME SOURCES... ) : one static library per src/ folder, alias dispex::NAME.
function(dispex_add_library name)
  add_library(dispex_${name} STATIC ${ARGN})
  add_library(dispex::${name} ALIAS dispex_${name})
  target_link_libraries(dispex_${name} PRIVATE dispex_warnings PUBLIC dispex_options)
endfunction()
