#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The firmware's planning on an emulated STM32F405 against the host's (docs/embedded.md):
# runs coavoid-firmware-check.elf (apps/firmware/check.c, built by the `firmware` test's
# cross build in BUILD/firmware-arm) in qemu's netduinoplus2 machine (Cortex-M4F, FPU)
# with ARM semihosting, then qemu_compare.py compares every result with `coavoid plan` on
# the same scenarios (tests/firmware/qemu/*.json) in both host builds (double and single),
# and the fleet tags and Ed25519 signatures the check computed with the host's libsodium.
# Also fails when apps/firmware/check_problems.h is not what gen_check_problems.py makes
# of those scenarios. Then the vehicle protocol on the part: coavoid-firmware-replay.elf
# flies the records of vehicles the single-precision build recorded, as recorded (below).
# Last, the vehicle's receive ring (coavoid-firmware-usart-check.elf) behind a sender
# faster than its main loop. A missing qemu-system-arm is a failure, not a skip.
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
if ! log=$("$cmake" --build "$arm" --target coavoid_firmware_check coavoid_firmware_replay \
    coavoid_firmware_usart_check 2>&1); then
  echo "$log" >&2
  die "building the firmware's check and replay ELFs failed (see above)"
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

# semihosted SECONDS OUT QEMU_ARGS...: qemu's netduinoplus2 for at most SECONDS (exit 124
# past them), the firmware's semihosting output to OUT, a file of its own: nothing else of
# qemu's (monitor, UART) mixes in.
semihosted() {
  local seconds=$1 out=$2
  shift 2
  timeout "$seconds" qemu-system-arm -M netduinoplus2 -display none -monitor none \
    -chardev file,id=semihosting,path="$out" \
    -semihosting-config enable=on,target=native,chardev=semihosting "$@"
}

# -icount shift=0: virtual time is the guest instruction count (1 ns each), so the check's
# SysTick readings count instructions, the same on every run and every host.
out=$tmp/firmware.txt
semihosted 60 "$out" -icount shift=0 -serial null -kernel "$elf"
rc=$?
[ "$rc" -ne 124 ] || die "the firmware check did not exit within 60 s in qemu"
echo "== firmware check on qemu netduinoplus2 (exit $rc)"
cat "$out"
[ "$rc" -eq 0 ] || { echo "firmware_qemu: FAIL: the firmware check exited with $rc" >&2; failed=1; }
python3 "$here/qemu_compare.py" "$out" "$double" "$single" -- "$here"/qemu/*.json || failed=1

# The vehicle protocol on the part: UAV 1 of the paper's encounter in each mode and UAV 9 of
# nine converging (tests/firmware/replay/nine.json), recorded by the single-precision host
# build, replayed by coavoid-firmware-replay.elf
# (apps/firmware/replay.c), which reads the records from its working directory and must
# send every recorded byte and reach every recorded state. A centralised vehicle that does
# not fit the part's block is reported, not replayed.
replay=$arm/apps/firmware/coavoid-firmware-replay.elf
for mode in decoupled centralised; do
  "$single" sim "$src/scenarios/paper.json" --mode "$mode" \
    --record-vehicle "1:$tmp/$mode.rec" > /dev/null || die "recording UAV 1 ($mode) failed"
done
# At the part's capacity: UAV 9 of nine converging on a point, last in priority.
"$single" sim "$here/replay/nine.json" --mode decoupled --record-vehicle "9:$tmp/nine.rec" \
  > /dev/null || die "recording UAV 9 of nine failed"
(cd "$tmp" && semihosted 120 "$tmp/replay.txt" -icount shift=0 -serial null -kernel "$replay")
rc=$?
echo "== vehicle replay on qemu netduinoplus2 (exit $rc)"
cat "$tmp/replay.txt"
[ "$rc" -eq 0 ] && grep -q '^replay decoupled.rec .*: all as recorded$' "$tmp/replay.txt" &&
  grep -q '^replay nine.rec .*: all as recorded$' "$tmp/replay.txt" ||
  { echo "firmware_qemu: FAIL: the vehicle on the part did not replay its records as recorded" >&2; failed=1; }

# The receive ring (apps/firmware/usart_check.c): 4,096 bytes of a known sequence sent at
# once on USART1; the part lets its ring fill, stays busy, then must read every byte in
# order. A handler taken again for ever while the ring is full (qemu keeps the USART's
# interrupt up when RXNEIE is cleared) never lets it finish: the timeout says so.
usart=$arm/apps/firmware/coavoid-firmware-usart-check.elf
semihosted 20 "$tmp/usart.txt" -serial "unix:$tmp/usart.sock,server=on,wait=off" \
  -kernel "$usart" &
qemu=$!
python3 - "$tmp/usart.sock" 4096 <<'PY'
import socket, sys, time
path, n = sys.argv[1], int(sys.argv[2])
for _ in range(100):
    try:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.connect(path)
        break
    except OSError:
        time.sleep(0.05)
else:
    sys.exit(f"cannot connect to the part's USART at {path}")
s.sendall(bytes((i * 7 + 3) & 0xFF for i in range(n)))
s.settimeout(25)
try:
    s.recv(1)  # until qemu ends
except OSError:
    pass
PY
sent=$?
wait "$qemu"
rc=$?
echo "== receive ring on qemu netduinoplus2 (exit $rc)"
cat "$tmp/usart.txt"
if [ "$sent" -ne 0 ]; then
  echo "firmware_qemu: FAIL: the receive check's bytes were not sent" >&2
  failed=1
elif [ "$rc" -eq 124 ]; then
  echo "firmware_qemu: FAIL: the receive check did not end within 20 s: its USART handler keeps the main loop from the full ring" >&2
  failed=1
elif [ "$rc" -ne 0 ] || ! grep -q '^usart check: 4096 bytes in order through a full ring$' "$tmp/usart.txt"; then
  echo "firmware_qemu: FAIL: the receive ring lost or reordered bytes" >&2
  failed=1
fi
exit "$failed"
