#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the build tree into a scratch prefix, then builds a consumer against it twice:
# with find_package(coavoid) (CMake) and with pkg-config. Usage: run.sh SRC BUILD
set -euo pipefail
src=$1 build=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null

# A sanitized core needs the sanitizer runtime in whatever links it.
flags=""
if grep -q '^COAVOID_SANITIZE:BOOL=ON' "$build/CMakeCache.txt"; then
  flags="-fsanitize=address,undefined"
fi

cmake -S "$src/tests/consumer" -B "$work/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" >/dev/null
cmake --build "$work/cmake-build" >/dev/null
"$work/cmake-build/consumer"

pcdir=$(dirname "$(find "$prefix" -name coavoid.pc | head -n 1)")
export PKG_CONFIG_PATH=$pcdir
# shellcheck disable=SC2046,SC2086
cc -std=c11 $flags "$src/tests/consumer/main.c" $(pkg-config --cflags coavoid) \
  $(pkg-config --libs --static coavoid) -o "$work/consumer-pc"
"$work/consumer-pc"
echo "install_consumer: CMake package and pkg-config consumers built and ran"
