# cmake -P script behind the package_user_project test (see CMakeLists.txt here).
foreach(var ECSIM_BINARY_DIR USER_PROJECT_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_package_test.cmake: ${var} is not set")
  endif()
endforeach()

set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/user-build)
file(REMOVE_RECURSE ${WORK_DIR})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}")
  endif()
  message(STATUS "${what}: ok")
endfunction()

# Headers and libraries must match: bring what is installed up to date first.
run("build what is installed" ${CMAKE_COMMAND} --build ${ECSIM_BINARY_DIR} --target ecsim_install_deps)
run("install into ${prefix}" ${CMAKE_COMMAND} --install ${ECSIM_BINARY_DIR} --prefix ${prefix})
foreach(f lib/cmake/ecsim/ecsimConfig.cmake lib/cmake/ecsim/ecsimConfigVersion.cmake
          lib/pkgconfig/ecsim.pc include/ecsim/protocol/result.hpp
          include/ecsim/embed/simulated_network.hpp
          include/ecsim/embed/testing/network_fixture.hpp lib/libecsim_embed.a
          bin/ecsim bin/ecmaster share/ecsim/topologies/demo.xml share/ecsim/esi/ecsim_devices.xml)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "the install has no ${f}")
  endif()
endforeach()

# Only the installed package: the source and build trees are not on any search path.
run("configure the user project" ${CMAKE_COMMAND} -S ${USER_PROJECT_DIR} -B ${build}
    -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("build the user project" ${CMAKE_COMMAND} --build ${build})
run("test the user project" ${CMAKE_CTEST_COMMAND} --test-dir ${build} --output-on-failure)

# pkg-config sees the same package.
find_program(PKG_CONFIG pkg-config)
if(PKG_CONFIG)
  set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
  execute_process(COMMAND ${PKG_CONFIG} --cflags --libs ecsim RESULT_VARIABLE rc
                  OUTPUT_VARIABLE flags ERROR_VARIABLE flags)
  if(NOT rc EQUAL 0 OR NOT flags MATCHES "-lecsim_embed" OR NOT flags MATCHES "include/ecsim")
    message(FATAL_ERROR "pkg-config --cflags --libs ecsim: ${flags}")
  endif()
  message(STATUS "pkg-config: ${flags}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
