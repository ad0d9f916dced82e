# SPDX-License-Identifier: MIT
# Fails when the core references a heap, stdio, clock, thread or LCM function.
#   cmake -DLIB=<archive> -DNM=<nm> -P check_core_symbols.cmake
# checks an archive's undefined symbols (what it needs from elsewhere); with -DLINKED=ON,
# LIB is a linked program and every symbol in it is checked (a program defines what it
# uses). Used for the host core (tests/CMakeLists.txt) and for the Cortex-M4F archive and
# firmware ELF (tests/firmware/run.sh), so the list is written once. Names with newlib's
# reentrant forms (_malloc_r, _vfprintf_r, ...) and the system calls under them
# (_sbrk, _write, ...) count too. With -DNO_DATA=ON an archive must also define no
# writable data (nm's D, d, B, b, C, G, g, S, s): the core keeps no mutable global.
set(nm_args -u)
if(LINKED)
  set(nm_args "")
endif()
execute_process(COMMAND ${NM} ${nm_args} ${LIB} OUTPUT_VARIABLE undefined RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
set(heap "malloc|calloc|realloc|reallocf|free|aligned_alloc|posix_memalign|memalign|valloc|sbrk")
set(stdio "[a-z]*printf|[a-z]*scanf|puts|fputs|putchar|fputc|putc|fwrite|fread|fopen|fdopen|freopen|fclose|fflush|fseek|fgets|fgetc|getc|getchar|perror|setvbuf|write|read|open|close")
set(clock "time|clock|clock_gettime|gettimeofday")
string(REGEX MATCHALL "[^\n]+" lines "${undefined}")
set(bad "")
foreach(line ${lines})
  string(REGEX REPLACE "^.* " "" sym "${line}")
  if(sym MATCHES "^_*(${heap}|${stdio})(_r)?$" OR sym MATCHES "^(${clock}|pthread_.*|lcm_.*)$")
    list(APPEND bad ${sym})
  endif()
endforeach()
if(bad)
  list(REMOVE_DUPLICATES bad)
  message(FATAL_ERROR "${LIB} references forbidden symbols: ${bad}")
endif()
if(NO_DATA)
  execute_process(COMMAND ${NM} ${LIB} OUTPUT_VARIABLE all RESULT_VARIABLE rc)
  string(REGEX MATCHALL "[^\n]+ [DdBbCGgSs] [^\n]+" data "${all}")
  if(data)
    message(FATAL_ERROR "${LIB} defines writable data (no mutable global): ${data}")
  endif()
endif()
message(STATUS "${LIB}: no heap, stdio, clock, thread or LCM symbol")
