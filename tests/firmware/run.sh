#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The Cortex-M4F firmware build (docs/embedded.md), as CI runs it: configures and builds
# the cross tree with cmake/arm-none-eabi-cortex-m4f.cmake in BUILD/firmware-arm, then
#   - fails if the ARM core archive or the linked firmware ELF references a heap or stdio
#     function (tests/check_core_symbols.cmake, the list the host's core_symbols uses),
#     or if a core or firmware function has an unbounded (dynamic) stack frame;
#   - prints text, data and bss of the ELF, the core and libccd, the largest stack frames
#     (-fstack-usage) and the deepest call chains (-fcallgraph-info=su, callgraph.awk),
#     failing on recursion or a dynamic frame.
# Also builds the message checks (src/auth on libsodium, cmake/libsodium_arm.cmake) into
# the check ELF, which must link them without a heap, and the vehicle protocol
# (src/protocol) and its replay (src/replay, the replay ELF), which must need no heap or
# stdio, and reports their sizes and stack.
# Usage: run.sh SRC BUILD CCD_SOURCE_DIR SODIUM_SOURCE_DIR (the unpacked sources, fetched
# beforehand by scripts/fetch_sources.sh: a test never downloads). A missing toolchain,
# newlib or source is a failure with what to install, not a skip: CI must run this.
set -euo pipefail
usage="usage: run.sh SRC BUILD CCD_SOURCE_DIR SODIUM_SOURCE_DIR"
src=${1:?$usage}
build=${2:?$usage}
ccd_src=${3:?$usage}
sodium_src=${4:?$usage}
arm=$build/firmware-arm
cmake=${CMAKE:-cmake}
prefix=arm-none-eabi-

die() { echo "firmware: FAIL: $*" >&2; exit 1; }

command -v "${prefix}gcc" >/dev/null ||
  die "${prefix}gcc not found: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi"
libc=$("${prefix}gcc" -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard \
  -print-file-name=libc.a)
[ -f "$libc" ] || die "newlib for Cortex-M4F hard float not found: apt-get install libnewlib-arm-none-eabi"

[ -f "$ccd_src/src/ccd/config.h.cmake.in" ] ||
  die "$ccd_src is not libccd's unpacked source: scripts/fetch_sources.sh DIR, then -DCOAVOID_CCD_SOURCE_DIR=DIR/libccd"
[ -f "$sodium_src/src/libsodium/include/sodium/version.h.in" ] ||
  die "$sodium_src is not libsodium's unpacked source: scripts/fetch_sources.sh DIR, then -DCOAVOID_SODIUM_SOURCE_DIR=DIR/libsodium"
# The ARM tree is this test's own: one built from another libccd source (an earlier
# configure, or the configure step's own fetch: libccd's ExternalProject cannot switch
# sources) starts again. $arm/ccd-source names the source it was built from.
if [ -d "$arm" ] && [ "$(cat "$arm/ccd-source" 2>/dev/null)" != "$ccd_src $sodium_src" ]; then
  echo "firmware: $arm was not built from $ccd_src: rebuilding it"
  rm -rf "$arm"
fi
mkdir -p "$arm"
echo "$ccd_src $sodium_src" > "$arm/ccd-source"
args=(-S "$src" -B "$arm" -DCMAKE_TOOLCHAIN_FILE="$src/cmake/arm-none-eabi-cortex-m4f.cmake"
  -DCOAVOID_CCD_SOURCE_DIR="$ccd_src" -DCOAVOID_SODIUM_SOURCE_DIR="$sodium_src")
# Configure output only when it fails (it says what is missing: a deb-src line, dpkg-dev).
if ! log=$("$cmake" "${args[@]}" 2>&1); then
  echo "$log" >&2
  die "configuring the ARM build failed (see above)"
fi
if ! log=$("$cmake" --build "$arm" -j2 2>&1); then
  echo "$log" >&2
  die "building the ARM tree failed (see above)"
fi

core=$arm/src/core/libcoavoid_core.a
elf=$arm/apps/firmware/coavoid-firmware.elf
ccd=$arm/libccd-arm/lib/libccd.a
sodium=$arm/libcoavoid_sodium_arm.a
map=$arm/apps/firmware/coavoid-firmware.map
for f in "$core" "$elf" "$ccd" "$sodium" "$map"; do
  [ -f "$f" ] || die "$f was not built"
done
grep -q '^#define CCD_SINGLE' "$arm/libccd-arm/include/ccd/config.h" ||
  die "the ARM libccd is not single precision"

# Heap and stdio: what the core archive needs from outside it, and everything the ELF
# contains after --gc-sections.
"$cmake" -DLIB="$core" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the ARM core archive references a forbidden function"
"$cmake" -DLINKED=ON -DLIB="$elf" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the firmware ELF contains a forbidden function"
# The vehicle protocol, as an autopilot links it (src/protocol).
protocol=$arm/src/protocol/libcoavoid_protocol.a
[ -f "$protocol" ] || die "$protocol was not built"
"$cmake" -DLIB="$protocol" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the ARM vehicle protocol archive references a forbidden function"
replay=$arm/src/replay/libcoavoid_replay.a
[ -f "$replay" ] || die "$replay was not built"
"$cmake" -DLIB="$replay" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the ARM vehicle replay archive references a forbidden function"
# The check ELF (qemu.sh runs it) prints through semihosting calls of its own, not stdio.
check_elf=$arm/apps/firmware/coavoid-firmware-check.elf
[ -f "$check_elf" ] || die "$check_elf was not built"
"$cmake" -DLINKED=ON -DLIB="$check_elf" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the firmware check ELF contains a forbidden function"
# So does the replay ELF, the vehicle protocol linked as a firmware links it.
replay_elf=$arm/apps/firmware/coavoid-firmware-replay.elf
[ -f "$replay_elf" ] || die "$replay_elf was not built"
"$cmake" -DLINKED=ON -DLIB="$replay_elf" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the firmware replay ELF contains a forbidden function"
# And the vehicle ELF, the vehicle of the fleet on the part behind its UART (apps/firmware/vehicle.c).
vehicle_elf=$arm/apps/firmware/coavoid-firmware-vehicle.elf
[ -f "$vehicle_elf" ] || die "$vehicle_elf was not built"
"$cmake" -DLINKED=ON -DLIB="$vehicle_elf" -DNM="${prefix}nm" -P "$src/tests/check_core_symbols.cmake" ||
  die "the firmware vehicle ELF contains a forbidden function"
# (grep reads all of nm's output: -q would stop early and fail the pipe under pipefail)
[ "$("${prefix}nm" "$check_elf" | grep -c ' T fwc_crypto_run$')" -eq 1 ] ||
  die "the firmware check ELF has no message checks (fwc_crypto_run): libsodium was not built"

echo "== size (bytes; an archive's total is every function, the ELF only what it links)"
"${prefix}size" -t "$core" | tail -n 1 | sed 's/(TOTALS)/core (libcoavoid_core.a)/'
"${prefix}size" -t "$ccd" | tail -n 1 | sed 's/(TOTALS)/libccd (libccd.a)/'
"${prefix}size" -t "$sodium" | tail -n 1 | sed 's/(TOTALS)/libsodium: tag and Ed25519 (libcoavoid_sodium_arm.a)/'
"${prefix}size" -t "$arm/src/auth/libcoavoid_auth.a" | tail -n 1 | sed 's/(TOTALS)/message checks (libcoavoid_auth.a)/'
"${prefix}size" -t "$protocol" | tail -n 1 | sed 's/(TOTALS)/vehicle protocol (libcoavoid_protocol.a)/'
"${prefix}size" "$elf" | tail -n 1 | sed "s|$elf|firmware ELF|"

# Stack frames: file:line:col:function <TAB> bytes <TAB> static|dynamic[,bounded].
report_frames() { # NAME DIR
  local name=$1 dir=$2 files
  mapfile -t files < <(find "$dir" -name '*.su' | sort)
  [ "${#files[@]}" -gt 0 ] || die "no .su files under $dir (-fstack-usage missing?)"
  cat "${files[@]}" | awk -F'\t' -v name="$name" '
    { n = split($1, p, ":"); fn = p[n]; file = p[1]; sub(/.*\//, "", file)
      if ($2 + 0 > best) { best = $2 + 0; where = fn " (" file ")"; q = $3 }
      if ($3 == "dynamic") { dyn = dyn " " fn }
      total++ }
    END { printf "%-9s worst frame %5d bytes  %s [%s], %d functions\n", name, best, where, q, total
          if (dyn != "") { printf "%s: unbounded stack frames:%s\n", name, dyn; exit 1 } }'
}
echo "== stack (largest single frame; a call chain adds its callers' frames)"
report_frames core "$arm/src/core/CMakeFiles/coavoid_core.dir" || die "unbounded stack frame in the core"
# The example firmware's objects only: the check ELF (check.c) has a main of its own.
fw_objs=$arm/apps/firmware/CMakeFiles/coavoid_firmware.dir
report_frames firmware "$fw_objs" || die "unbounded stack frame in the firmware"
report_frames check "$arm/apps/firmware/CMakeFiles/coavoid_firmware_check.dir" ||
  die "unbounded stack frame in the firmware check"
report_frames libccd "$arm/libccd-arm-build/src" || true
sodium_objs=$arm/CMakeFiles/coavoid_sodium_arm.dir
report_frames libsodium "$sodium_objs" || die "unbounded stack frame in libsodium's message checks"
auth_objs=$arm/src/auth/CMakeFiles/coavoid_auth.dir
report_frames auth "$auth_objs" || die "unbounded stack frame in the message checks (src/auth)"
report_frames protocol "$arm/src/protocol/CMakeFiles/coavoid_protocol.dir" ||
  die "unbounded stack frame in the vehicle protocol"
# Call chains: the deepest sum of frames below each entry point, over the core's,
# libccd's and the firmware's call graphs; libccd's only indirect calls are to the
# callbacks geometry.c hands it. Recursion or a dynamic frame fails the test.
echo "== stack (deepest call chain: frames summed, library leaves not included)"
mapfile -t graphs < <(find "$arm/src/core/CMakeFiles/coavoid_core.dir" "$fw_objs" \
  "$arm/libccd-arm-build/src" "$sodium_objs" "$auth_objs" -name '*.ci' | sort)
[ "${#graphs[@]}" -gt 0 ] || die "no .ci files (-fcallgraph-info=su missing?)"
awk -v roots="main,fw_systick_handler,fw_task_cycle,coa_plan_decoupled,coa_plan_centralised,coa_predict,coavoid_auth_stamp,coavoid_auth_precheck,coavoid_auth_verify" \
  -v indirect="sweep_support,poly_support,sweep_centre,poly_centre" \
  -f "$src/tests/firmware/callgraph.awk" "${graphs[@]}" || die "unbounded call chain"
# The vehicle protocol's calls, over its graphs and those it calls into (the messages',
# src/auth's, libsodium's, the core's and libccd's). Its indirect calls reach the inbox's
# channel handlers, the vehicle's plan and agreement callbacks, and the link the replay
# ELF gives it (each caller's own, CALLER>TARGET); libccd's as above.
mapfile -t vgraphs < <(find "$arm/src/core/CMakeFiles/coavoid_core.dir" "$arm/libccd-arm-build/src" \
  "$sodium_objs" "$auth_objs" "$arm/src/protocol" "$arm/src/lcm" "$arm/lcmtypes" "$arm/src/replay" \
  -name '*.ci' | sort)
vindirect="sweep_support,poly_support,sweep_centre,poly_centre"
for h in on_intent on_track on_map on_status on_plan on_agreement; do
  vindirect="$vindirect,coavoid_node_inbox_receive>$h"
done
vindirect="$vindirect,on_plan>coavoid_vehicle_on_plan,on_plan>coavoid_vehicle_on_plan_row"
vindirect="$vindirect,on_agreement>coavoid_vehicle_on_agreement"
for m in intent status agreement; do vindirect="$vindirect,coavoid_node_publish_$m>replay_send"; done
awk -v roots="coavoid_vehicle_node_cycle,coavoid_vehicle_node_poll,coavoid_vehicle_node_receive" \
  -v indirect="$vindirect" -f "$src/tests/firmware/callgraph.awk" "${vgraphs[@]}" ||
  die "unbounded call chain in the vehicle protocol"
# The vehicle ELF's main loop: a frame off the UART taken by the session (session.h), whose
# node sends through the session's link, which frames onto the UART byte by byte.
svindirect=${vindirect//replay_send/session_send}
svindirect="$svindirect,coavoid_link_put_frame>put_byte,put_escaped>put_byte"
vehicle_objs=$arm/apps/firmware/CMakeFiles/coavoid_firmware_vehicle.dir
awk -v roots="main,fw_usart1_handler" -v indirect="$svindirect" -f "$src/tests/firmware/callgraph.awk" \
  "${vgraphs[@]}" "$vehicle_objs/vehicle.c.ci" "$vehicle_objs/usart.c.ci" ||
  die "unbounded call chain in the firmware vehicle"
echo "== firmware ELF by origin (input sections from the map; flash = code + constants)"
awk -f "$src/tests/firmware/mapsizes.awk" "$map"
echo "== firmware check ELF by origin (the same; its message checks are libsodium's share)"
awk -f "$src/tests/firmware/mapsizes.awk" "$arm/apps/firmware/coavoid-firmware-check.map"
echo "== firmware replay ELF by origin (a vehicle of the protocol on the part: what it links)"
awk -f "$src/tests/firmware/mapsizes.awk" "$arm/apps/firmware/coavoid-firmware-replay.map"
echo "== firmware vehicle ELF by origin (the vehicle of the fleet on the part, behind its UART)"
awk -f "$src/tests/firmware/mapsizes.awk" "$arm/apps/firmware/coavoid-firmware-vehicle.map"
echo "== firmware sections (flash: .isr_vector .text .ARM.exidx + .data's image; SRAM: .data .bss; CCM: .stack)"
"${prefix}size" -A "$elf" | awk '$1 ~ /^\.(isr_vector|text|ARM\.exidx|data|bss|stack)/ { printf "%-12s %7d bytes at 0x%08x\n", $1, $2, $3 }'
echo "firmware: ARM core and firmware link without heap or stdio"
