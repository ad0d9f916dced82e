# SPDX-License-Identifier: MIT
# libsodium for the cross build (included from the top-level CMakeLists.txt when
# cross-compiling): the fleet tag (SipHash-2-4) and Ed25519 signing and verification,
# compiled from Debian's source package (scripts/fetch_sources.sh) in its portable C
# implementations, the way libsodium's own minimal build would; nothing else of it. No
# libsodium function used here allocates, reads a clock or draws random bytes: key
# generation (randombytes) stays on the ground, where `coavoid keygen` runs.
#
# COAVOID_SODIUM_SOURCE_DIR: the unpacked source tree (scripts/fetch_sources.sh DIR, then
# DIR/libsodium). Empty: no coavoid::sodium_arm, and the firmware check measures no crypto.
set(COAVOID_SODIUM_SOURCE_DIR "" CACHE PATH
  "Unpacked libsodium source (scripts/fetch_sources.sh DIR, then DIR/libsodium); empty: none")
if(NOT COAVOID_SODIUM_SOURCE_DIR)
  return()
endif()
set(coavoid_na ${COAVOID_SODIUM_SOURCE_DIR}/src/libsodium)
if(NOT EXISTS ${coavoid_na}/include/sodium/version.h.in)
  message(FATAL_ERROR "coavoid: ${COAVOID_SODIUM_SOURCE_DIR} is not libsodium's source tree "
    "(no src/libsodium/include/sodium/version.h.in): run scripts/fetch_sources.sh DIR and "
    "pass -DCOAVOID_SODIUM_SOURCE_DIR=DIR/libsodium")
endif()
file(STRINGS ${COAVOID_SODIUM_SOURCE_DIR}/configure.ac coavoid_na_init REGEX "^AC_INIT")
if(NOT coavoid_na_init MATCHES "\\[([0-9]+\\.[0-9]+\\.[0-9]+)\\]")
  message(FATAL_ERROR "coavoid: no version in ${COAVOID_SODIUM_SOURCE_DIR}/configure.ac")
endif()
message(STATUS "coavoid: libsodium ${CMAKE_MATCH_1} source ${COAVOID_SODIUM_SOURCE_DIR}")

# version.h as libsodium's configure writes it for a minimal build.
set(VERSION ${CMAKE_MATCH_1})
set(SODIUM_LIBRARY_VERSION_MAJOR 10)
set(SODIUM_LIBRARY_VERSION_MINOR 3)
set(SODIUM_LIBRARY_MINIMAL_DEF "#define SODIUM_LIBRARY_MINIMAL 1")
set(coavoid_na_generated ${CMAKE_BINARY_DIR}/libsodium-arm/include)
configure_file(${coavoid_na}/include/sodium/version.h.in
  ${coavoid_na_generated}/sodium/version.h @ONLY)

add_library(coavoid_sodium_arm STATIC
  ${coavoid_na}/crypto_shorthash/siphash24/ref/shorthash_siphash24_ref.c
  ${coavoid_na}/crypto_sign/ed25519/sign_ed25519.c
  ${coavoid_na}/crypto_sign/ed25519/ref10/keypair.c
  ${coavoid_na}/crypto_sign/ed25519/ref10/open.c
  ${coavoid_na}/crypto_sign/ed25519/ref10/sign.c
  ${coavoid_na}/crypto_core/ed25519/ref10/ed25519_ref10.c
  ${coavoid_na}/crypto_hash/sha512/hash_sha512.c
  ${coavoid_na}/crypto_hash/sha512/cp/hash_sha512_cp.c
  ${coavoid_na}/crypto_verify/sodium/verify.c
  ${coavoid_na}/sodium/utils.c)
# CONFIGURED: what libsodium's configure would say of this part (little-endian, no 128-bit
# integers: the 32-bit field arithmetic, fe_25_5). The sources are upstream's: their
# warnings are not ours (-w).
target_compile_definitions(coavoid_sodium_arm PRIVATE CONFIGURED=1 NATIVE_LITTLE_ENDIAN=1
  PUBLIC SODIUM_STATIC=1)
target_compile_options(coavoid_sodium_arm PRIVATE -w)
set_target_properties(coavoid_sodium_arm PROPERTIES C_EXTENSIONS ON)
target_include_directories(coavoid_sodium_arm
  PRIVATE ${coavoid_na}/include/sodium
  PUBLIC ${coavoid_na_generated} ${coavoid_na}/include)
add_library(coavoid::sodium_arm ALIAS coavoid_sodium_arm)
