/* SPDX-License-Identifier: MIT */
/*
 * version.h: the version of coavoid, MAJOR.MINOR.PATCH. CMakeLists.txt reads it from here,
 * so the CMake package, the pkg-config file and every program's --version say the same.
 *
 * What a version promises is in docs/library.md ("Versions and stability"): before 1.0.0
 * a MINOR release may change the API; a PATCH release never does.
 */
#ifndef COAVOID_VERSION_H
#define COAVOID_VERSION_H

#define COAVOID_VERSION_MAJOR 0
#define COAVOID_VERSION_MINOR 1
#define COAVOID_VERSION_PATCH 0

/* The same as a string: "0.1.0". */
#define COAVOID_VERSION_STRING_(x) #x
#define COAVOID_VERSION_STRING(x) COAVOID_VERSION_STRING_(x)
#define COAVOID_VERSION                                                           \
    COAVOID_VERSION_STRING(COAVOID_VERSION_MAJOR)                                 \
    "." COAVOID_VERSION_STRING(COAVOID_VERSION_MINOR) "." COAVOID_VERSION_STRING( \
        COAVOID_VERSION_PATCH)

/* One number that grows with each release, for #if: MAJOR * 10000 + MINOR * 100 + PATCH. */
#define COAVOID_VERSION_NUMBER \
    (COAVOID_VERSION_MAJOR * 10000 + COAVOID_VERSION_MINOR * 100 + COAVOID_VERSION_PATCH)

#endif /* COAVOID_VERSION_H */
