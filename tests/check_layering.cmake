# SPDX-License-Identifier: MIT
# The layers of docs/design.md, checked on the sources: nothing under src/ or include/
# includes a header of apps/ (by its name, or by a path into apps/), the core
# (src/core/, include/coavoid/) includes neither LCM nor stdio, and the message checks the
# firmware compiles (src/auth/auth.c, auth.h) include no LCM, stdio or stdlib, nor does
# the vehicle protocol (src/protocol/) or its replay (src/replay/).
# Usage: cmake -DSRC=<source tree> -P check_layering.cmake
cmake_minimum_required(VERSION 3.16)
if(NOT SRC)
  message(FATAL_ERROR "usage: cmake -DSRC=<source tree> -P check_layering.cmake")
endif()

file(GLOB_RECURSE app_headers RELATIVE ${SRC} ${SRC}/apps/*.h)
set(app_names "")
foreach(h ${app_headers})
  get_filename_component(n ${h} NAME)
  list(APPEND app_names ${n})
endforeach()

set(failures 0)
file(GLOB_RECURSE lib_files ${SRC}/src/*.c ${SRC}/src/*.h ${SRC}/include/*.h)
foreach(f ${lib_files})
  file(STRINGS ${f} includes REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  file(RELATIVE_PATH rel ${SRC} ${f})
  set(core FALSE)
  if(rel MATCHES "^(src/core|include/coavoid)/")
    set(core TRUE)
  endif()
  # The message checks that the firmware compiles too (src/auth/auth.c and its header).
  set(part FALSE)
  if(rel MATCHES "^src/auth/auth\\.[ch]$")
    set(part TRUE)
  endif()
  # The vehicle protocol, which runs in the autopilot, and its replay there: no LCM, no stdio,
  # no heap.
  set(protocol FALSE)
  if(rel MATCHES "^src/(protocol|replay)/")
    set(protocol TRUE)
  endif()
  foreach(line ${includes})
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"].*" "\\1" inc "${line}")
    get_filename_component(name ${inc} NAME)
    if(inc MATCHES "(^|/)apps/" OR name IN_LIST app_names)
      message(SEND_ERROR "${rel}: includes ${inc}, a header of apps/ (src/ and include/ must not)")
      math(EXPR failures "${failures} + 1")
    endif()
    if(core AND (inc MATCHES "^lcm/" OR inc MATCHES "^lcmtypes" OR inc MATCHES "coavoid_lcm" OR
                 inc STREQUAL "stdio.h"))
      message(SEND_ERROR "${rel}: the core includes ${inc} (no LCM, no stdio in the core)")
      math(EXPR failures "${failures} + 1")
    endif()
    if(part AND (inc MATCHES "^lcm/" OR inc MATCHES "coavoid_lcm" OR inc STREQUAL "stdio.h" OR
                 inc STREQUAL "stdlib.h" OR inc STREQUAL "sodium.h"))
      message(SEND_ERROR "${rel}: includes ${inc} (the message checks build for the part: "
                         "no LCM, no stdio, no heap, only the libsodium headers they use)")
      math(EXPR failures "${failures} + 1")
    endif()
    if(protocol AND (inc MATCHES "^lcm/lcm\\.h$" OR inc STREQUAL "stdio.h" OR inc STREQUAL "stdlib.h"))
      message(SEND_ERROR "${rel}: includes ${inc} (the vehicle protocol runs in the autopilot: "
                         "no LCM, no stdio, no heap)")
      math(EXPR failures "${failures} + 1")
    endif()
  endforeach()
endforeach()
list(LENGTH lib_files nfiles)
if(failures GREATER 0)
  message(FATAL_ERROR "layering: ${failures} include(s) against the layers")
endif()
message(STATUS "layering: ${nfiles} files under src/ and include/ keep to their layers")
