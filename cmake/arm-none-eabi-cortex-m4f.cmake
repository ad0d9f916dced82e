# SPDX-License-Identifier: MIT
# Toolchain file: bare-metal Cortex-M4F with the single-precision FPU in hard-float ABI
# (Debian: gcc-arm-none-eabi, libnewlib-arm-none-eabi).
#
#   cmake -S . -B build-arm -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi-cortex-m4f.cmake
#
# The same file builds libccd from its source package (cmake/libccd_arm.cmake passes it on),
# so the core and libccd share one ABI: objects built for another float ABI would refuse to
# link rather than misbehave.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(COAVOID_ARM_PREFIX "arm-none-eabi-" CACHE STRING "Prefix of the cross tools' names")
set(CMAKE_C_COMPILER ${COAVOID_ARM_PREFIX}gcc)
# libccd's project() enables C++ as well; nothing here compiles C++.
set(CMAKE_CXX_COMPILER ${COAVOID_ARM_PREFIX}g++)
set(CMAKE_ASM_COMPILER ${COAVOID_ARM_PREFIX}gcc)
set(CMAKE_AR ${COAVOID_ARM_PREFIX}ar CACHE FILEPATH "")
set(CMAKE_RANLIB ${COAVOID_ARM_PREFIX}ranlib CACHE FILEPATH "")
set(CMAKE_NM ${COAVOID_ARM_PREFIX}nm CACHE FILEPATH "")
set(CMAKE_OBJCOPY ${COAVOID_ARM_PREFIX}objcopy CACHE FILEPATH "")
set(CMAKE_SIZE ${COAVOID_ARM_PREFIX}size CACHE FILEPATH "")

# A test program cannot link without a linker script and startup code: compiler checks
# build a static library instead.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# Every translation unit, and the link (which picks newlib's hard-float multilib from the
# same flags). Sections per function and per object let --gc-sections drop what the
# firmware does not call (most of libccd, for one).
set(COAVOID_ARM_CPU_FLAGS "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard")
set(CMAKE_C_FLAGS_INIT "${COAVOID_ARM_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${COAVOID_ARM_CPU_FLAGS} -ffunction-sections -fdata-sections")
set(CMAKE_ASM_FLAGS_INIT "${COAVOID_ARM_CPU_FLAGS}")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${COAVOID_ARM_CPU_FLAGS} -Wl,--gc-sections")

# Never look for libraries or headers on the build host (the host's /usr/include/ccd is
# double precision and 64-bit); programs (cmake, apt-get) still come from the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
