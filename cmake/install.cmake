# Installation and the CMake/pkg-config packages (issue #10). Included at the end of the
# top-level CMakeLists.txt, after every library exists.
#
#   <prefix>/include/ecsim/{protocol,link,config,slavesim,topology,master,embed}/*.hpp: the
#   public headers only, included as <ecsim/master/master.hpp>
#   <prefix>/lib/libecsim_*.a
#   <prefix>/lib/cmake/ecsim/ecsimConfig.cmake (+ version, exported targets)
#   <prefix>/lib/pkgconfig/ecsim.pc
#   <prefix>/bin/ecsim, ecmaster, ecsim-soak and <prefix>/share/ecsim/{esi,topologies} (installed by
#   tools/ecsim, tools/ecmaster, tools/ecsim-soak), <prefix>/share/ecsim/examples/user-project
#
# Headers keep the source layout under include/ecsim; include/ is the exported targets' include
# directory, so users write <ecsim/protocol/result.hpp> and their own "config/..." never meets
# ours. Eigen stays private (slavesim's device models; no public header includes it).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ecsim_install_libraries protocol link config slavesim topology master embed)
set(ecsim_install_cmakedir ${CMAKE_INSTALL_LIBDIR}/cmake/ecsim)

foreach(lib ${ecsim_install_libraries})
  set_target_properties(ecsim_${lib} PROPERTIES EXPORT_NAME ${lib})
endforeach()

# The public headers only (cmake/public_headers.cmake: what the embedding API, the master and
# the fixture include), under include/ecsim and including each other as <ecsim/...>; the
# exported targets put include/ (ecsim_library's INSTALL_INTERFACE) on a user's search path.
set(ecsim_public_include ${PROJECT_BINARY_DIR}/public-include)
add_custom_target(ecsim_public_headers ALL
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DOUTPUT_DIR=${ecsim_public_include}
          "-DROOTS=embed/simulated_network.hpp,master/master.hpp,embed/testing/network_fixture.hpp"
          -P ${PROJECT_SOURCE_DIR}/cmake/public_headers.cmake
  COMMENT "" VERBATIM)
install(DIRECTORY ${ecsim_public_include}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# The static libraries link ecsim_options privately; their exported link interface names it
# ($<LINK_ONLY:...>), so it is exported too. Only its link options reach a user's program: the
# sanitizer runtime when ECSIM_SANITIZE built the libraries, nothing otherwise.
set_target_properties(ecsim_options PROPERTIES EXPORT_NAME options)

# ecsim::sim: the simulator (protocol, link, config, slavesim, topology, embed).
add_library(ecsim_sim INTERFACE)
add_library(ecsim::sim ALIAS ecsim_sim)
set_target_properties(ecsim_sim PROPERTIES EXPORT_NAME sim)
target_link_libraries(ecsim_sim INTERFACE ecsim_embed ecsim_topology ecsim_slavesim ecsim_config
                                          ecsim_link ecsim_protocol)

# ecsim::testing: the GoogleTest fixture (embed/testing/network_fixture.hpp, header-only) with
# what it needs from ecsim. The user links GTest::gtest (or gtest_main) as usual.
add_library(ecsim_testing INTERFACE)
add_library(ecsim::testing ALIAS ecsim_testing)
set_target_properties(ecsim_testing PROPERTIES EXPORT_NAME testing)
target_link_libraries(ecsim_testing INTERFACE ecsim_sim ecsim_master)

set(ecsim_install_targets ecsim_options ecsim_sim ecsim_testing)
foreach(lib ${ecsim_install_libraries})
  list(APPEND ecsim_install_targets ecsim_${lib})
endforeach()
install(TARGETS ${ecsim_install_targets} EXPORT ecsimTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT ecsimTargets NAMESPACE ecsim:: DESTINATION ${ecsim_install_cmakedir})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ecsimConfig.cmake.in
  ${PROJECT_BINARY_DIR}/ecsimConfig.cmake INSTALL_DESTINATION ${ecsim_install_cmakedir}
  PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ecsimConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/ecsimConfig.cmake ${PROJECT_BINARY_DIR}/ecsimConfigVersion.cmake
        DESTINATION ${ecsim_install_cmakedir})

# pkg-config: the same libraries in link order; dependencies through their own .pc files.
set(ecsim_pc_sanitize "")
if(ECSIM_SANITIZE)
  set(ecsim_pc_sanitize "-fsanitize=${ecsim_sanitizers}")
endif()
# Relocatable: the prefix is found from the .pc file's own folder (pkg-config's pcfiledir).
file(RELATIVE_PATH ecsim_pc_up /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" ecsim_pc_up "${ecsim_pc_up}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/ecsim.pc.in ${PROJECT_BINARY_DIR}/ecsim.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/ecsim.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# A starting point for users: the stand-alone project our package test builds.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/user-project
        DESTINATION ${CMAKE_INSTALL_DATADIR}/ecsim/examples)

# Everything `cmake --install` copies, so tests/package can bring a build tree up to date
# before installing it (a no-op after a full build).
add_custom_target(ecsim_install_deps)
add_dependencies(ecsim_install_deps ${ecsim_install_targets} ecsim_public_headers)
foreach(tool ecsim ecmaster ecsim-soak)
  if(TARGET ${tool})
    add_dependencies(ecsim_install_deps ${tool})
  endif()
endforeach()
