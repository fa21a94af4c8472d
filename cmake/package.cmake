# The Debian package (issue #19): `cpack -G DEB` in a build tree (or `cmake --build B --target
# package`) writes ecsim_<version>_amd64.deb with everything `cmake --install` installs, under
# /usr, stripped (static libraries too: cmake/package_strip.cmake); the tools' debug
# information in ecsim-dbgsym_<version>_amd64.ddeb. Depends: the shared libraries the tools link (dpkg-shlibdeps finds
# them: libc6, libstdc++6, libfmt9, libtinyxml2-9, libpcap0.8, libre2-9, ...); Recommends: the
# development packages a consumer of the headers and CMake package needs (ecsimConfig.cmake's
# find_dependency calls). Included at the end of the top-level CMakeLists.txt.
set(CPACK_PACKAGE_NAME ecsim)
set(CPACK_PACKAGE_VENDOR "ecsim")
set(CPACK_PACKAGE_CONTACT "ecsim developers <ecsim-dev@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Software EtherCAT network for hardware-in-the-loop testing")
set(CPACK_PACKAGE_DESCRIPTION
    "Virtual EtherCAT slaves that behave like real EtherCAT Slave Controllers, devices behind
them, a network served to any master over veth/TAP or in-process, fault scenarios, and an
EtherCAT master (ecsim, ecmaster, ecsim-soak; libraries, headers and CMake package).")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_DEBUGINFO_PACKAGE ON)
find_program(CPACK_STRIP_PROGRAM strip REQUIRED)
set(CPACK_PRE_BUILD_SCRIPTS ${CMAKE_CURRENT_LIST_DIR}/package_strip.cmake)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS
    "cmake, pkg-config, libfmt-dev, libtinyxml2-dev, libeigen3-dev, libpcap-dev, libgtest-dev")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "tshark, gnuplot-nox, iproute2, ethtool")
include(CPack)
