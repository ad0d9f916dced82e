#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Line coverage of src/ by the test suite: builds the tree with gcc's --coverage (no
# sanitizers, no firmware: the part's code is run by the firmware tests under qemu, which
# gcov cannot see), runs ctest, and prints gcovr's table of src/ with the total line.
# Needs gcovr (Debian: apt-get install gcovr). A measurement, not a test: its figure is
# in tests/README.md.
# usage: scripts/coverage.sh [BUILD_DIR]   (default build-cov; JOBS=N for ctest -j, default 4)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-cov}
command -v gcovr >/dev/null || { echo "coverage: no gcovr (apt-get install gcovr)" >&2; exit 2; }
# Atomic counters: montecarlo's worker threads count into the same ones.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_FLAGS="--coverage -O0 -fprofile-update=atomic" \
    -DCMAKE_EXE_LINKER_FLAGS=--coverage >/dev/null
cmake --build "$build" -j2 >/dev/null
find "$build" -name '*.gcda' -delete
# Left out: the fuzzers, built by clang outside this tree (their runs count for nothing
# here); core_symbols, which finds gcov's counters as writable data in the core; and
# install_consumer, whose consumers would need gcov's runtime to link the archives.
ctest --test-dir "$build" -j"${JOBS:-4}" -E '^(fuzz_|core_symbols$|install_consumer$)' \
    --output-on-failure >"$build/ctest.log" 2>&1 ||
    echo "coverage: some tests failed (see $build/ctest.log); the figure counts what ran" >&2
tail -n 3 "$build/ctest.log"
gcovr --root . --filter 'src/' --object-directory "$build" --print-summary "$build" |
    tail -n 40
