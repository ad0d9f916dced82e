#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The firmware's planning on an emulated STM32F405 against the host's (docs/embedded.md):
# runs coavoid-firmware-check.elf (apps/firmware/check.c, built by the `firmware` test's
# cross build in BUILD/firmware-arm) in qemu's netduinoplus2 machine (Cortex-M4F, FPU)
# with ARM semihosting, then qemu_compare.py compares every result with `coavoid plan` on
# the same scenarios (tests/firmware/qemu/*.json) in both host builds (double and single),
# and the fleet tags and Ed25519 signatures the check computed with the host's libsodium.
# Also fails when apps/firmware/check_problems.h is not what gen_check_problems.py makes
# of those scenarios. A missing qemu-system-arm is a failure, not a skip.
# Usage: qemu.sh SRC BUILD DOUBLE_COAVOID SINGLE_COAVOID
set -uo pipefail
usage="usage: qemu.sh SRC BUILD DOUBLE_COAVOID SINGLE_COAVOID"
src=${1:?$usage}
build=${2:?$usage}
double=${3:?$usage}
single=${4:?$usage}
arm=$build/firmware-arm
elf=$arm/apps/firmware/coavoid-firmware-check.elf
cmake=${CMAKE:-cmake}
here=$src/tests/firmware

die() { echo "firmware_qemu: FAIL: $*" >&2; exit 1; }

command -v qemu-system-arm >/dev/null ||
  die "qemu-system-arm not found: apt-get install qemu-system-arm"
[ -f "$arm/CMakeCache.txt" ] ||
  die "$arm is not configured: the firmware test (tests/firmware/run.sh) builds it first"
if ! log=$("$cmake" --build "$arm" --target coavoid_firmware_check 2>&1); then
  echo "$log" >&2
  die "building coavoid-firmware-check.elf failed (see above)"
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0

python3 "$here/gen_check_problems.py" "$tmp/check_problems.h" "$here"/qemu/*.json || exit 1
if ! diff -u "$src/apps/firmware/check_problems.h" "$tmp/check_problems.h" >&2; then
  echo "firmware_qemu: FAIL: apps/firmware/check_problems.h is stale: run" \
       "tests/firmware/gen_check_problems.py apps/firmware/check_problems.h tests/firmware/qemu/*.json" >&2
  failed=1
fi

# Semihosting output to a file of its own: nothing else of qemu's (monitor, UART) mixes in.
# -icount shift=0: virtual time is the guest instruction count (1 ns each), so the check's
# SysTick readings count instructions, the same on every run and every host.
out=$tmp/firmware.txt
timeout 60 qemu-system-arm -M netduinoplus2 -icount shift=0 -display none -monitor none -serial null \
  -chardev file,id=semihosting,path="$out" \
  -semihosting-config enable=on,target=native,chardev=semihosting -kernel "$elf"
rc=$?
[ "$rc" -ne 124 ] || die "the firmware check did not exit within 60 s in qemu"
echo "== firmware check on qemu netduinoplus2 (exit $rc)"
cat "$out"
[ "$rc" -eq 0 ] || { echo "firmware_qemu: FAIL: the firmware check exited with $rc" >&2; failed=1; }
python3 "$here/qemu_compare.py" "$out" "$double" "$single" -- "$here"/qemu/*.json || failed=1
exit "$failed"
