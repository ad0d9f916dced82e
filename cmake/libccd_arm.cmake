# SPDX-License-Identifier: MIT
# libccd for the cross build (included from the top-level CMakeLists.txt when
# cross-compiling). Debian's libccd-dev is a 64-bit, double-precision host library, so
# libccd is built here from Debian's source package, in single precision, with the same
# toolchain file as the core, and imported as the target `ccd` the core links to (the name
# Debian's CMake package gives it on the host).
#
# COAVOID_CCD_SOURCE_DIR: an unpacked libccd source tree (`apt-get source libccd`). Empty:
# the configure step runs `apt-get source libccd` into the build tree once, which needs a
# deb-src line for Debian in APT's sources and the package dpkg-dev (dpkg-source unpacks).
include(ExternalProject)

set(COAVOID_CCD_SOURCE_DIR "" CACHE PATH
  "Unpacked libccd source (apt-get source libccd); empty: fetched with apt-get source")

set(coavoid_ccd_src "${COAVOID_CCD_SOURCE_DIR}")
if(NOT coavoid_ccd_src)
  set(coavoid_ccd_fetch_dir ${CMAKE_BINARY_DIR}/libccd-source)
  file(GLOB coavoid_ccd_found LIST_DIRECTORIES true ${coavoid_ccd_fetch_dir}/libccd-*/src/ccd)
  if(NOT coavoid_ccd_found)
    # The commands on lines of their own, indented: CMake does not re-wrap those.
    set(coavoid_ccd_howto
      "libccd's source is needed for the firmware build: pass -DCOAVOID_CCD_SOURCE_DIR=<dir> "
      "(an unpacked `apt-get source libccd`), or let this step fetch it, which needs the "
      "package dpkg-dev and a deb-src line for Debian. As root:\n"
      "  printf 'Types: deb-src\\nURIs: http://deb.debian.org/debian\\nSuites: bookworm\\n"
      "Components: main\\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\\n' "
      "> /etc/apt/sources.list.d/deb-src.sources\n"
      "  apt-get update && apt-get install -y dpkg-dev\n")
    find_program(COAVOID_APT_GET apt-get)
    find_program(COAVOID_DPKG_SOURCE dpkg-source)
    if(NOT COAVOID_APT_GET)
      message(FATAL_ERROR "coavoid: apt-get not found. " ${coavoid_ccd_howto})
    endif()
    if(NOT COAVOID_DPKG_SOURCE)
      message(FATAL_ERROR "coavoid: dpkg-source not found (package dpkg-dev). " ${coavoid_ccd_howto})
    endif()
    file(MAKE_DIRECTORY ${coavoid_ccd_fetch_dir})
    message(STATUS "coavoid: apt-get source libccd into ${coavoid_ccd_fetch_dir}")
    execute_process(COMMAND ${COAVOID_APT_GET} source libccd
      WORKING_DIRECTORY ${coavoid_ccd_fetch_dir}
      RESULT_VARIABLE coavoid_rc OUTPUT_VARIABLE coavoid_out ERROR_VARIABLE coavoid_err)
    file(GLOB coavoid_ccd_found LIST_DIRECTORIES true ${coavoid_ccd_fetch_dir}/libccd-*/src/ccd)
    if(NOT coavoid_rc EQUAL 0 OR NOT coavoid_ccd_found)
      string(STRIP "${coavoid_err}" coavoid_err)
      message(FATAL_ERROR "coavoid: `apt-get source libccd` failed (${coavoid_rc}): "
        "${coavoid_err}\n" ${coavoid_ccd_howto})
    endif()
  endif()
  list(GET coavoid_ccd_found 0 coavoid_ccd_src)
  get_filename_component(coavoid_ccd_src ${coavoid_ccd_src}/../.. ABSOLUTE)
endif()
if(NOT EXISTS ${coavoid_ccd_src}/src/ccd/config.h.cmake.in)
  message(FATAL_ERROR "coavoid: ${coavoid_ccd_src} is not a libccd source tree "
    "(no src/ccd/config.h.cmake.in); COAVOID_CCD_SOURCE_DIR must name the directory "
    "`apt-get source libccd` unpacks (libccd-2.1)")
endif()
message(STATUS "coavoid: libccd source ${coavoid_ccd_src}")

# The toolchain file may have been given relative to the build or the source tree.
set(coavoid_toolchain ${CMAKE_TOOLCHAIN_FILE})
if(NOT IS_ABSOLUTE ${coavoid_toolchain})
  if(EXISTS ${CMAKE_BINARY_DIR}/${coavoid_toolchain})
    get_filename_component(coavoid_toolchain ${CMAKE_BINARY_DIR}/${coavoid_toolchain} ABSOLUTE)
  else()
    get_filename_component(coavoid_toolchain ${CMAKE_SOURCE_DIR}/${coavoid_toolchain} ABSOLUTE)
  endif()
endif()

set(coavoid_ccd_prefix ${CMAKE_BINARY_DIR}/libccd-arm)
set(coavoid_ccd_lib ${coavoid_ccd_prefix}/lib/${CMAKE_STATIC_LIBRARY_PREFIX}ccd${CMAKE_STATIC_LIBRARY_SUFFIX})
ExternalProject_Add(libccd_arm
  SOURCE_DIR ${coavoid_ccd_src}
  BINARY_DIR ${CMAKE_BINARY_DIR}/libccd-arm-build
  INSTALL_DIR ${coavoid_ccd_prefix}
  CMAKE_ARGS
    -DCMAKE_TOOLCHAIN_FILE=${coavoid_toolchain}
    -DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE}
    -DCMAKE_INSTALL_PREFIX=<INSTALL_DIR>
    -DCMAKE_INSTALL_LIBDIR=lib
    -DCMAKE_PROJECT_libccd_INCLUDE=${CMAKE_CURRENT_LIST_DIR}/stack_usage.cmake
    -DENABLE_DOUBLE_PRECISION=OFF
    -DBUILD_TESTING=OFF
    -DBUILD_SHARED_LIBS=OFF
    -DLIBM_LIBRARY:STRING=m
    # libccd asks for CMake 2.8.11; the deprecation notice is upstream's, not ours.
    -DCMAKE_WARN_DEPRECATED=OFF
  BUILD_BYPRODUCTS ${coavoid_ccd_lib})
# Reconfigure libccd when the flags injected into it change.
ExternalProject_Add_StepDependencies(libccd_arm configure
  ${CMAKE_CURRENT_LIST_DIR}/stack_usage.cmake)

# The imported target's include directory must exist when the project is configured.
file(MAKE_DIRECTORY ${coavoid_ccd_prefix}/include)
add_library(ccd STATIC IMPORTED GLOBAL)
set_target_properties(ccd PROPERTIES
  IMPORTED_LOCATION ${coavoid_ccd_lib}
  INTERFACE_INCLUDE_DIRECTORIES ${coavoid_ccd_prefix}/include
  INTERFACE_LINK_LIBRARIES m)
add_dependencies(ccd libccd_arm)
