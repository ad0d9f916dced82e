#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Opens lcm-spy on the coavoid traffic, with the project's message types on its class path
# and the demo's LCM URL, so that every channel decodes field by field.
#
# usage: scripts/spy.sh [--build DIR] [--url URL] [--check]
#   --build DIR  the build directory whose lcmtypes/coavoid_lcmtypes.jar to load; default
#                build (the jar is built when a JDK is present: apt-get install default-jdk)
#   --url URL    the nodes' LCM URL; default the demo's, udpm://239.255.76.67:7667?ttl=0
#   --check      only check that everything lcm-spy needs is there, and say what is not
#
# Debian's /usr/bin/lcm-spy (LCM 1.3.1) does not start on OpenJDK 17 (it passes the removed
# -Xincgc option), so this starts its class, lcm.spy.Spy, directly. It needs liblcm-java
# (lcm.jar), libjchart2d-java (jchart2d.jar, the message view) and a Java runtime with AWT
# (default-jdk; default-jdk-headless has none): one line installs all three,
#   apt-get install -y --no-install-recommends liblcm-java libjchart2d-java default-jdk
# then build (cmake -S . -B build && cmake --build build) to get the types jar. Without a
# display, run it under xvfb-run -a (packages xvfb and xauth).
set -euo pipefail

build=build
url='udpm://239.255.76.67:7667?ttl=0'
check=0
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=${2:?--build: missing value}; shift 2 ;;
    --url) url=${2:?--url: missing value}; shift 2 ;;
    --check) check=1; shift ;;
    -h | --help) sed -n '3,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "spy.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

lcm_jar=/usr/share/java/lcm.jar
chart_jar=/usr/share/java/jchart2d.jar
types_jar=$build/lcmtypes/coavoid_lcmtypes.jar
missing=()
command -v java >/dev/null || missing+=("java: apt-get install default-jdk")
[ -f "$lcm_jar" ] || missing+=("$lcm_jar: apt-get install liblcm-java")
[ -f "$chart_jar" ] || missing+=("$chart_jar: apt-get install libjchart2d-java")
[ -f "$types_jar" ] ||
  missing+=("$types_jar: install a JDK (default-jdk), then cmake -S . -B $build && cmake --build $build")
if [ ${#missing[@]} -gt 0 ]; then
  printf 'spy.sh: missing %s\n' "${missing[@]}" >&2
  exit 1
fi
if [ "$check" = 1 ]; then
  echo "spy.sh: ready: java, lcm.jar, jchart2d.jar and $types_jar; URL $url"
  exit 0
fi
exec java -cp "$lcm_jar:$chart_jar:$types_jar" lcm.spy.Spy --lcm-url="$url"
