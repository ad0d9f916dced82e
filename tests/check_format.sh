#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The C sources keep the project's style (.clang-format, clang-format 14): every .c and .h
# under src/, include/, apps/ and tests/ as clang-format would write it, except the
# generated apps/firmware/check_problems.h (its generator's output is checked instead).
# Usage: check_format.sh SRC [CLANG_FORMAT]. Fails listing the files that differ; to fix
# them: clang-format -i --style=file FILE...
set -euo pipefail
src=${1:?usage: check_format.sh SRC [CLANG_FORMAT]}
cf=${2:-clang-format}
command -v "$cf" >/dev/null || { echo "format: $cf not found: apt-get install clang-format" >&2; exit 1; }
cd "$src"
mapfile -t files < <(find src include apps tests -name '*.[ch]' ! -path 'apps/firmware/check_problems.h' | sort)
bad=()
for f in "${files[@]}"; do
  if ! "$cf" --style=file --dry-run --Werror "$f" >/dev/null 2>&1; then
    bad+=("$f")
  fi
done
if [ ${#bad[@]} -gt 0 ]; then
  for f in "${bad[@]}"; do
    echo "format: $f differs from .clang-format (fix: clang-format -i --style=file $f)" >&2
  done
  echo "format: ${#bad[@]} of ${#files[@]} files differ" >&2
  exit 1
fi
echo "format: ${#files[@]} files as .clang-format writes them"
