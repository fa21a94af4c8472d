# CPack pre-build script (cmake/package.cmake): the -dbgsym split strips the executables; the
# static libraries keep their debug information unless stripped here (197 MB with it, 5 MB
# without). Debug information for the tools goes to the -dbgsym package.
file(GLOB_RECURSE ecsim_archives "${CPACK_TEMPORARY_DIRECTORY}/*.a")
foreach(archive ${ecsim_archives})
  execute_process(COMMAND ${CPACK_STRIP_PROGRAM} --strip-debug ${archive} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "strip --strip-debug ${archive} failed (${rc})")
  endif()
endforeach()
