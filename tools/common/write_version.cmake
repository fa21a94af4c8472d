# cmake -P script run at every build (tools/common/CMakeLists.txt): writes version.hpp with the
# project's version and the git revision of the source tree (with "-dirty" when it has
# uncommitted changes); configure_file leaves the file untouched when nothing changed, so
# nothing is rebuilt then.
foreach(var SOURCE_DIR OUTPUT TEMPLATE ECSIM_VERSION)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "write_version.cmake: ${var} is not set")
  endif()
endforeach()
set(ECSIM_GIT_REVISION "")
find_program(GIT git)
if(GIT AND EXISTS ${SOURCE_DIR}/.git)
  execute_process(COMMAND ${GIT} -C ${SOURCE_DIR} rev-parse --short=10 HEAD
                  RESULT_VARIABLE rc OUTPUT_VARIABLE rev ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(rc EQUAL 0)
    set(ECSIM_GIT_REVISION ${rev})
    execute_process(COMMAND ${GIT} -C ${SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE dirty ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT dirty STREQUAL "")
      string(APPEND ECSIM_GIT_REVISION "-dirty")
    endif()
  endif()
endif()
configure_file(${TEMPLATE} ${OUTPUT} @ONLY)
