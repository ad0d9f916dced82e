# SPDX-License-Identifier: MIT
# Included from apps/CMakeLists.txt when the messaging library is built.
# Sources of the node library are listed here by the people who write them.
set(COAVOID_NODE_SOURCES "")
foreach(f common.c vehicle.c coordinator.c world.c flight.c svg.c realtime.c)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/node/${f})
    list(APPEND COAVOID_NODE_SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/node/${f})
  endif()
endforeach()
if(COAVOID_NODE_SOURCES)
  add_library(coavoid_node STATIC ${COAVOID_NODE_SOURCES})
  target_include_directories(coavoid_node PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/node)
  target_link_libraries(coavoid_node PUBLIC coavoid_lcm coavoid_appsupport m)
  target_compile_definitions(coavoid_node PUBLIC COAVOID_HAVE_NODE)
endif()
