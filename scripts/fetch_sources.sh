#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fetches and unpacks the Debian source packages the Cortex-M4F build compiles from
# (docs/embedded.md) into DIR, so that nothing is downloaded later, by the build or by
# ctest: libccd (the planner's collision checks) and libsodium (the fleet tag and Ed25519).
# DIR/libccd and DIR/libsodium are symbolic links to the unpacked trees,
# DIR/<package>-<version>; the last line of stdout is DIR.
#
# usage: scripts/fetch_sources.sh DIR        (as root, or with sudo rights for apt)
#
# Needs dpkg-dev (dpkg-source) and a deb-src entry. When apt has none for a package, one is
# derived from the machine's own configured sources: every `deb` entry of
# /etc/apt/sources.list and of the deb822 files in /etc/apt/sources.list.d/ is repeated as
# `deb-src` in /etc/apt/sources.list.d/coavoid-deb-src.{list,sources}, then apt-get update
# runs; no mirror is assumed. Run again, it fetches only what DIR does not hold yet.
set -euo pipefail

dir=${1:?usage: fetch_sources.sh DIR}
die() { echo "fetch_sources: $*" >&2; exit 1; }

# Each package and a file only its unpacked tree has.
packages=(libccd libsodium)
marker() {
  case $1 in
    libccd) echo src/ccd/config.h.cmake.in ;;
    libsodium) echo src/libsodium/include/sodium/version.h.in ;;
  esac
}

# The unpacked tree of package $1 in DIR, or failure.
unpacked() {
  local d
  for d in "$dir/$1"-*/; do
    if [ -f "$d/$(marker "$1")" ]; then
      echo "${d%/}"
      return 0
    fi
  done
  return 1
}

mkdir -p "$dir"
missing=()
for p in "${packages[@]}"; do
  if tree=$(unpacked "$p"); then
    ln -sfn "$(basename "$tree")" "$dir/$p"
  else
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "$dir"
  exit 0
fi

command -v apt-get >/dev/null || die "apt-get not found (a Debian system is needed)"
command -v dpkg-source >/dev/null || die "dpkg-source not found: apt-get install dpkg-dev"

# Whether apt already knows every missing package's source (some deb-src entry covers it).
has_source() {
  local p
  for p in "${missing[@]}"; do
    apt-get source --print-uris "$p" >/dev/null 2>&1 || return 1
  done
}

# deb-src twins of the configured deb entries, one-line and deb822.
derive_deb_src() {
  local list=/etc/apt/sources.list.d/coavoid-deb-src.list
  local d822=/etc/apt/sources.list.d/coavoid-deb-src.sources
  local f
  : > "$list.tmp"
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] && [ "$f" != "$list" ] || continue
    sed -n 's/^[[:space:]]*deb[[:space:]]/deb-src /p' "$f" >> "$list.tmp"
  done
  : > "$d822.tmp"
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && [ "$f" != "$d822" ] || continue
    # Each stanza again with Types: deb-src (only the stanzas that have deb), blank-line
    # separated; Enabled: no stanzas stay disabled.
    awk 'BEGIN { RS = ""; ORS = "\n\n" }
         { if ($0 ~ /(^|\n)Types:[^\n]*(^|[[:space:]])deb([[:space:]]|$)/) {
             out = ""; n = split($0, line, "\n")
             for (i = 1; i <= n; ++i) {
               if (line[i] ~ /^Types:/) line[i] = "Types: deb-src"
               out = out line[i] "\n"
             }
             printf "%s\n", out
           } }' "$f" >> "$d822.tmp"
  done
  if [ -s "$list.tmp" ]; then mv "$list.tmp" "$list"; else rm -f "$list.tmp"; fi
  if [ -s "$d822.tmp" ]; then mv "$d822.tmp" "$d822"; else rm -f "$d822.tmp"; fi
  [ -f "$list" ] || [ -f "$d822" ] || die "no deb entry in /etc/apt/sources.list{,.d} to derive a deb-src entry from"
}

if ! has_source; then
  derive_deb_src
  apt-get update >&2
  has_source || die "apt still finds no source for ${missing[*]} after adding deb-src entries"
fi

# apt-get source unpacks in the current directory. As root it warns that the download is
# not sandboxed (the _apt user cannot write to DIR): expected here.
for p in "${missing[@]}"; do
  (cd "$dir" && apt-get source "$p" >&2) || die "apt-get source $p failed"
  tree=$(unpacked "$p") || die "apt-get source $p left no $p-*/$(marker "$p") in $dir"
  ln -sfn "$(basename "$tree")" "$dir/$p"
done
echo "$dir"
