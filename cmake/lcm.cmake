# SPDX-License-Identifier: MIT
# LCM messaging: the generated message types (lcmtypes/) and the validation and
# conversion library coavoid_lcm (src/lcm/). Included from the top-level CMakeLists.txt
# after coavoid_core is defined.
option(COAVOID_BUILD_LCM "Build the LCM message types and the messaging library (needs LCM)" ON)
if(NOT COAVOID_BUILD_LCM)
  return()
endif()
#
# LCM 1.3.1 (Debian liblcm-dev) has no CMake package, and its lcm.pc needs glib's
# development files which liblcm-dev does not pull in; LCM's public headers do not
# include glib, so the header and the library are found directly.
find_path(LCM_INCLUDE_DIR lcm/lcm.h)
find_library(LCM_LIBRARY lcm)
set(LCM_JAR /usr/share/java/lcm.jar CACHE FILEPATH "LCM's Java runtime (liblcm-java)")
if(NOT LCM_INCLUDE_DIR OR NOT LCM_LIBRARY)
  message(FATAL_ERROR "coavoid: LCM not found (Debian: apt-get install liblcm-dev liblcm-bin); "
                      "or configure with -DCOAVOID_BUILD_LCM=OFF")
endif()

# LCM itself, for what publishes and subscribes (the nodes' transport, the simulation,
# the drivers, the test tools): the message coders need none of it.
if(NOT CMAKE_CROSSCOMPILING AND NOT TARGET coavoid::liblcm)
  add_library(coavoid::liblcm INTERFACE IMPORTED)
  set_target_properties(coavoid::liblcm PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES ${LCM_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES ${LCM_LIBRARY})
endif()

add_subdirectory(${PROJECT_SOURCE_DIR}/lcmtypes ${PROJECT_BINARY_DIR}/lcmtypes)

add_subdirectory(${PROJECT_SOURCE_DIR}/src/auth ${PROJECT_BINARY_DIR}/src/auth)
add_subdirectory(${PROJECT_SOURCE_DIR}/src/lcm ${PROJECT_BINARY_DIR}/src/lcm)
