# SPDX-License-Identifier: MIT
# Injected into libccd's project (CMAKE_PROJECT_libccd_INCLUDE, cmake/libccd_arm.cmake):
# a .su and a .ci file beside each object, for the firmware test's worst stack frame and
# deepest call chain. Added to the
# toolchain file's flags rather than replacing them, as -DCMAKE_C_FLAGS would.
add_compile_options(-fstack-usage -fcallgraph-info=su)
