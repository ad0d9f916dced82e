#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fetches and unpacks Debian's libccd source package into DIR (the firmware build compiles
# libccd for the Cortex-M4F from it, docs/embedded.md), so that nothing is downloaded
# later, by the build or by ctest. Prints the unpacked tree's path, DIR/libccd-<version>,
# on its last line of stdout; DIR/source is a symbolic link to it.
#
# usage: scripts/fetch_libccd_source.sh DIR        (as root, or with sudo rights for apt)
#
# Needs dpkg-dev (dpkg-source) and a deb-src entry. When apt has none for libccd, one is
# derived from the machine's own configured sources: every `deb` entry of
# /etc/apt/sources.list and of the deb822 files in /etc/apt/sources.list.d/ is repeated as
# `deb-src` in /etc/apt/sources.list.d/coavoid-deb-src.{list,sources}, then apt-get update
# runs; no mirror is assumed. Run again, it does nothing when DIR already holds the tree.
set -euo pipefail

dir=${1:?usage: fetch_libccd_source.sh DIR}
die() { echo "fetch_libccd_source: $*" >&2; exit 1; }

unpacked() {
  local d
  for d in "$dir"/libccd-*/; do
    if [ -f "$d/src/ccd/config.h.cmake.in" ]; then
      echo "${d%/}"
      return 0
    fi
  done
  return 1
}

mkdir -p "$dir"
if tree=$(unpacked); then
  ln -sfn "$(basename "$tree")" "$dir/source"
  echo "$tree"
  exit 0
fi

command -v apt-get >/dev/null || die "apt-get not found (a Debian system is needed)"
command -v dpkg-source >/dev/null || die "dpkg-source not found: apt-get install dpkg-dev"

# Whether apt already knows libccd's source (some deb-src entry covers it).
has_source() {
  apt-get source --print-uris libccd >/dev/null 2>&1
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
  has_source || die "apt still finds no source for libccd after adding deb-src entries"
fi

# apt-get source unpacks in the current directory. As root it warns that the download is
# not sandboxed (the _apt user cannot write to DIR): expected here.
(cd "$dir" && apt-get source libccd >&2) || die "apt-get source libccd failed"
tree=$(unpacked) || die "apt-get source libccd left no libccd-*/src/ccd/config.h.cmake.in in $dir"
ln -sfn "$(basename "$tree")" "$dir/source"
echo "$tree"
