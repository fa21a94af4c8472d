# Project-wide compile options, applied to every ecsim target through ecsim_target_defaults().
add_library(ecsim_options INTERFACE)
target_compile_options(ecsim_options INTERFACE
  -Wall -Wextra -Wconversion -Wshadow -Werror -Wno-error=deprecated-declarations)
# GCC's `undefined` leaves out float-cast-overflow (a double out of an integer's range cast to
# it, e.g. a number read from a file): named here so that such a cast stops the test.
set(ecsim_sanitizers address,undefined,float-cast-overflow)
if(ECSIM_SANITIZE)
  target_compile_options(ecsim_options INTERFACE
    -fsanitize=${ecsim_sanitizers} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  target_link_options(ecsim_options INTERFACE -fsanitize=${ecsim_sanitizers})
endif()

function(ecsim_target_defaults target)
  target_link_libraries(${target} PRIVATE ecsim_options)
endfunction()

# ecsim_library(NAME SOURCES... DEPS ...): a library in folder NAME, public headers under
# the repository root so includes read "protocol/frame.hpp".
function(ecsim_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(ecsim_${name} STATIC ${ARG_SOURCES})
  add_library(ecsim::${name} ALIAS ecsim_${name})
  target_include_directories(ecsim_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}> $<INSTALL_INTERFACE:include>)
  target_link_libraries(ecsim_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} ecsim_options)
  set_target_properties(ecsim_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
