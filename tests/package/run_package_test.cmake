# cmake -P script behind the package_user_project test (see CMakeLists.txt here).
foreach(var ECSIM_BINARY_DIR SOURCE_DIR USER_PROJECT_DIR WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_package_test.cmake: ${var} is not set")
  endif()
endforeach()

set(prefix ${WORK_DIR}/prefix)
set(build ${WORK_DIR}/user-build)
file(REMOVE_RECURSE ${WORK_DIR})

# The installed tree alone: version, installed topologies naming only installed files, and the
# tools relocated (moved outside the build tree) with the source and build trees hidden.
function(check_installed_tree prefix)
  execute_process(COMMAND ${prefix}/bin/ecsim --version OUTPUT_VARIABLE version RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR NOT version MATCHES "^ecsim [0-9]+\\.[0-9]+\\.[0-9]+")
    message(FATAL_ERROR "ecsim --version (${rc}): ${version}")
  endif()
  message(STATUS "ecsim --version: ${version}")
  # Only the public headers, each including the others as <ecsim/...>, none of them tinyxml2
  # or Eigen (private to the libraries).
  foreach(private config/xml_util.hpp slavesim/devices/motor_model.hpp config/esi_parts.hpp)
    if(EXISTS ${prefix}/include/ecsim/${private})
      message(FATAL_ERROR "the install has the private header ${private}")
    endif()
  endforeach()
  file(GLOB_RECURSE headers ${prefix}/include/*.hpp)
  list(LENGTH headers count)
  foreach(h ${headers})
    file(STRINGS ${h} bad REGEX "#[ \t]*include[ \t]*(\"|<(tinyxml2|Eigen))")
    if(bad)
      message(FATAL_ERROR "installed ${h}: ${bad}")
    endif()
  endforeach()
  message(STATUS "${count} public headers, none private")
  file(GLOB_RECURSE topologies ${prefix}/share/ecsim/topologies/*.xml)
  foreach(t ${topologies})
    file(READ ${t} text)
    get_filename_component(dir ${t} DIRECTORY)
    string(REGEX MATCHALL "(esi|eeprom|topology|eni)=\"[^\"]+\"" refs "${text}")
    foreach(ref ${refs})
      string(REGEX REPLACE "^[a-z]+=\"([^\"]+)\"$" "\\1" file "${ref}")
      if(NOT EXISTS ${dir}/${file})
        message(FATAL_ERROR "installed ${t} names ${file}, which is not installed")
      endif()
    endforeach()
  endforeach()
endfunction()

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
  if(NOT rc EQUAL 0 OR NOT flags MATCHES "-lecsim_embed" OR flags MATCHES "include/ecsim")
    message(FATAL_ERROR "pkg-config --cflags --libs ecsim: ${flags}")
  endif()
  message(STATUS "pkg-config: ${flags}")
endif()

check_installed_tree(${prefix})
# Moved out of the build tree (a relocatable install: data found from the executable), then run
# where neither the source tree nor the build tree can be seen (the build tree first: it may
# lie inside the source tree).
string(RANDOM LENGTH 8 tag)
set(moved /tmp/ecsim-package-${tag})
set(demo_out /tmp/ecsim-package-${tag}-demo)
file(COPY ${prefix}/ DESTINATION ${moved})
file(REMOVE_RECURSE ${prefix})
execute_process(COMMAND id -u OUTPUT_VARIABLE uid OUTPUT_STRIP_TRAILING_WHITESPACE)
find_program(UNSHARE unshare)
if(uid STREQUAL "0" AND UNSHARE)
  execute_process(
    COMMAND ${UNSHARE} --mount --propagation private sh -c
            "mount -t tmpfs ecsim-hidden \"$2\" && mount -t tmpfs ecsim-hidden \"$1\" && exec \"$3/bin/ecsim\" demo --out \"$4\""
            hide ${SOURCE_DIR} ${ECSIM_BINARY_DIR} ${moved} ${demo_out}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  set(hidden "with the source and build trees hidden")
elseif("$ENV{CI}" STREQUAL "true")
  file(REMOVE_RECURSE ${moved})
  message(FATAL_ERROR "CI=true and hiding the source tree needs root and unshare (uid ${uid})")
else()
  execute_process(COMMAND ${moved}/bin/ecsim demo --out ${demo_out}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  set(hidden "(not root: source tree not hidden)")
endif()
file(REMOVE_RECURSE ${moved})
if(NOT rc EQUAL 0 OR NOT EXISTS ${demo_out}/demo.pcap)
  file(REMOVE_RECURSE ${demo_out})
  message(FATAL_ERROR "the moved install's ecsim demo ${hidden} failed (${rc}):\n${out}")
endif()
file(REMOVE_RECURSE ${demo_out})
message(STATUS "the moved install's ecsim demo ${hidden}: ok")
file(REMOVE_RECURSE ${WORK_DIR})
