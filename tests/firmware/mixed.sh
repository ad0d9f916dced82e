#!/bin/bash
# SPDX-License-Identifier: MIT
# The firmware as a vehicle of the fleet: the paper's encounter (with the 18 s lead-in of
# cli_multiprocess, so that cycle 0 does not depend on which process runs first) flown
# with UAV 1 on the emulated STM32F405 (coavoid-firmware-vehicle.elf in qemu's
# netduinoplus2, its USART1 on a Unix socket), joined to the LCM group by `coavoid
# bridge`, and UAVs 2 and 3 as coavoid-vehicle processes, with `coavoid world`, in each
# mode, the coordinator with the centralised one; every process signs and checks with
# keys from `coavoid keygen`. Each flight must keep separation and be `coavoid sim`'s,
# sample for sample: the fleet is single precision, as the part is (the other-precision
# build of the test tree), and compared with that build's sim. The centralised fleet
# flies with --joint-members 0, every vehicle and the sim alike: the part's block holds
# no joint search of three UAVs (docs/embedded.md). Before the flights, the bridge's bad
# options and two parts that fail it: one that never answers (exit 3 a cycle after the
# last, the configuration sent again meanwhile) and the real part refusing a vehicle its
# block cannot hold (exit 3, refused).
#
# Runs in a private network namespace (lib.bash), or where none can be made on the host's
# multicast route on a port of its own; exits 77 (skipped) where neither is. The scenario
# runs at 0.4 times real time: qemu's USART takes one byte per turn of its main loop, about
# 45 us (22 kB/s, a quarter of the 921,600 baud line the firmware sets), and a cycle
# brings the part up to 25 kB (centralised), so that the link is busy at most half the
# time; the bridge's line reports its queue's peak.
#
# usage: mixed.sh SINGLE_COAVOID SRC BUILD   (VERBOSE=1 shows more; KEEP_TMP=1 keeps files)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/../cli/lib.bash" "$@"
build=${3:?usage: mixed.sh SINGLE_COAVOID SRC BUILD}
apps=$(dirname "$bin")
vehicle=$apps/coavoid-vehicle
coordinator=$apps/coavoid-coordinator
elf=$build/firmware-arm/apps/firmware/coavoid-firmware-vehicle.elf
cmake=${CMAKE:-cmake}
for tool in qemu-system-arm lcm-logger; do
    command -v "$tool" >/dev/null || { echo "FAIL: $tool not found"; exit 1; }
done
if [ ! -x "$vehicle" ] || [ ! -x "$coordinator" ]; then
    echo "FAIL: no coavoid-vehicle/coavoid-coordinator beside $bin"
    exit 1
fi
url="udpm://239.255.76.67:7667?ttl=0"
if ! in_multicast_netns "$@"; then
    # No namespace (a container without CAP_SYS_ADMIN): the host's multicast route, on a
    # port of this run's own, with ttl=0 (cli_multiprocess does the same).
    if ! { ip route get 239.255.76.67 ||
        awk 'NR > 1 && ($2 == "00000000" || ($2 == "000000E0" && $8 == "000000F0")) {f = 1}
             END {exit !f}' /proc/net/route; } >/dev/null 2>&1; then
        echo "SKIP: no private network namespace and no multicast route: the mixed flight is not flown"
        exit 77
    fi
    url="udpm://239.255.76.67:$((20000 + $$ % 20000))?ttl=0"
    echo "note: on the host's network ($url)"
fi
if [ -z "${COAVOID_MIXED_BUILT:-}" ] &&
    ! log=$("$cmake" --build "$build/firmware-arm" --target coavoid_firmware_vehicle 2>&1); then
    echo "$log"
    echo "FAIL: building coavoid-firmware-vehicle.elf failed"
    exit 1
fi
speed=${SPEED:-0.4}
# The part stands for a processor of its own, which the suite's other tests must not slow:
# qemu runs at a higher priority where that is allowed (root). Behind busy cores it falls
# behind the fleet's clock and the bridge's queue to it overflows (tests/README.md).
qemu_cmd=(qemu-system-arm)
if [ "$(nice -n -5 nice 2>/dev/null)" = -5 ]; then
    qemu_cmd=(nice -n -5 qemu-system-arm)
fi
steps=48
lead_us=2000000

keys=$tmp/keys
mkdir -p "$keys"
"$bin" keygen "$src/scenarios/paper.json" --dir "$keys" >"$tmp/keygen.out" 2>&1 ||
    { echo "FAIL: coavoid keygen: $(cat "$tmp/keygen.out")"; exit 1; }
key() { echo --key "$keys/$1.key" --trust "$keys/trust.txt"; }

# The paper's encounter, every UAV 18 s further back along its route.
scenario=$tmp/paper_lead_in.json
lead_in "$src/scenarios/paper.json" "$scenario" 18

# ---- the bridge's bad inputs, and parts that fail: one line, exit 2 or 3 ----
# (FAILURES=0 leaves them out: ctest flies each mode as a test of its own, and checks
# them with the first.)
paper=$src/scenarios/paper.json
bridge_failures() {
expect_bad "bridge without --uart" "--uart: required" bridge "$paper" --id 1 --insecure
expect_bad "bridge, a missing --uart" "$tmp/none" bridge --uart "$tmp/none" "$paper" \
    --id 1 --insecure
: >"$tmp/plain"
expect_bad "bridge, --uart a plain file" "neither a serial device nor a socket" bridge \
    --uart "$tmp/plain" "$paper" --id 1 --insecure
expect_bad "bridge without --key" "--key: required" bridge --uart "$tmp/plain" \
    "$paper" --id 1
# failing_part NAME PATTERN BRIDGE_ARGS...: the bridge exits 3 within 20 s with one line
# holding PATTERN, against the part at $tmp/NAME.sock (started by the caller).
failing_part() {
    local name=$1 pattern=$2
    shift 2
    timeout 20 "$bin" bridge --uart "$tmp/$name.sock" "$paper" --id 1 "$@" \
        >"$tmp/$name.out" 2>"$tmp/$name.err"
    local rc=$?
    if [ "$rc" -ne 3 ] || ! grep -qF -- "$pattern" "$tmp/$name.err"; then
        fail "bridge, $name: exit $rc, expected 3 naming '$pattern': $(tail -c 400 "$tmp/$name.err")"
    else
        pass
    fi
}
# A part that takes the bytes and never answers: the configuration goes again every cycle
# of wall time, and the bridge gives up a cycle after the last.
python3 - "$tmp/silent.sock" "$tmp/silent.frames" <<'PY' &
import socket, sys
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
s.bind(sys.argv[1]); s.listen(1); s.settimeout(20)
c, _ = s.accept(); c.settimeout(5); data = b""
try:
    while True:
        b = c.recv(65536)
        if not b:
            break
        data += b
except socket.timeout:
    pass
open(sys.argv[2], "w").write(str(data.count(b"\xc0\x01\x00\x00")))
PY
silent=$!
for i in $(seq 50); do [ -S "$tmp/silent.sock" ] && break; sleep 0.1; done
failing_part silent "not through cycle 1" --steps 1 --speed 10 --insecure
wait "$silent"
if [ "$(cat "$tmp/silent.frames" 2>/dev/null)" -ge 2 ] 2>/dev/null; then
    pass
else
    fail "bridge, silent part: the configuration was not sent again ($(cat "$tmp/silent.frames" 2>/dev/null) CONFIG frames)"
fi
# The part itself refusing a vehicle it cannot hold: centralised with the joint plan of the
# paper's three UAVs (553,056 bytes; its block has 111,104).
"${qemu_cmd[@]}" -M netduinoplus2 -display none -monitor none \
    -serial "unix:$tmp/refusing.sock,server=on,wait=off" -kernel "$elf" >/dev/null 2>&1 &
refusing=$!
for i in $(seq 50); do [ -S "$tmp/refusing.sock" ] && break; sleep 0.1; done
failing_part refusing "refused the configuration" --mode centralised --steps 1 --insecure
kill "$refusing"
wait "$refusing" 2>/dev/null
}
if [ "${FAILURES:-1}" != 0 ]; then
    bridge_failures
fi

# fly MODE: the flight in $tmp/MODE (each process's stderr and exit status, the log, its
# summary and sim's flight).
fly() {
    local mode=$1 dir=$tmp/$1
    local joint=()
    [ "$mode" = centralised ] && joint=(--joint-members 0)
    mkdir -p "$dir"
    "${qemu_cmd[@]}" -M netduinoplus2 -display none -monitor none \
        -serial "unix:$dir/uart.sock,server=on,wait=off" -kernel "$elf" >"$dir/qemu.txt" 2>&1 &
    local qemu=$!
    lcm-logger -q -f --lcm-url="$url" "$dir/log.lcm" >"$dir/logger.out" 2>&1 &
    local logger=$!
    local i
    for i in $(seq 50); do [ -S "$dir/uart.sock" ] && break; sleep 0.1; done
    local epoch=$(($(date +%s%N) / 1000 + lead_us))
    local common=(--lcm-url "$url" --epoch "$epoch" --speed "$speed" --steps "$steps")
    local pids=() names=()
    # shellcheck disable=SC2046 # key's words are options
    "$bin" world "$scenario" "${common[@]}" $(key world) 2>"$dir/world.txt" &
    pids+=($!) names+=(world)
    if [ "$mode" = centralised ]; then
        # shellcheck disable=SC2046
        "$coordinator" "$scenario" "${common[@]}" $(key coordinator) \
            2>"$dir/coordinator.txt" &
        pids+=($!) names+=(coordinator)
    fi
    for i in 2 3; do
        # shellcheck disable=SC2046
        "$vehicle" "$scenario" --id "$i" --mode "$mode" "${joint[@]}" "${common[@]}" \
            $(key "vehicle-$i") 2>"$dir/vehicle-$i.txt" &
        pids+=($!) names+=("vehicle-$i")
    done
    # shellcheck disable=SC2046
    "$bin" bridge --uart "$dir/uart.sock" "$scenario" --id 1 --mode "$mode" \
        "${joint[@]}" "${common[@]}" $(key vehicle-1) 2>"$dir/bridge-1.txt" &
    pids+=($!) names+=(bridge-1)
    for i in "${!pids[@]}"; do
        wait "${pids[$i]}"
        echo $? >"$dir/${names[$i]}.rc"
    done
    sleep 0.3
    kill -INT "$logger"
    wait "$logger"
    kill "$qemu"
    wait "$qemu" 2>/dev/null
    "$bin" summary "$dir/log.lcm" "$scenario" --mode "$mode" --json --epoch "$epoch" \
        --trust "$keys/trust.txt" >"$dir/summary.json" 2>"$dir/summary.err"
    echo $? >"$dir/summary.rc"
    "$bin" sim "$scenario" --mode "$mode" "${joint[@]}" --steps "$steps" --json \
        >"$dir/sim.json" 2>"$dir/sim.err"
    if [ -n "${VERBOSE:-}" ]; then
        tail -n 2 "$dir"/*.txt "$dir/summary.err"
    fi
}

# check MODE: every process exited 0; the bridge's link lost nothing and the part refused
# nothing; no loss of separation; the flight is sim's.
check() {
    local dir=$tmp/$1
    if python3 - "$dir" <<'PY' >"$tmp/check.out" 2>&1; then
import glob, json, os, re, sys
d = sys.argv[1]
rc = {os.path.basename(f)[:-3]: int(open(f).read()) for f in glob.glob(os.path.join(d, "*.rc"))}
text = {os.path.basename(f)[:-4]: open(f).read().strip() for f in glob.glob(os.path.join(d, "*.txt"))}
def num(p, key):
    m = re.search(re.escape(key) + r" (\d+)", text[p].splitlines()[-1] if text[p] else "")
    assert m, f"{p}: no '{key}' in its summary line: {text[p][-300:]!r}"
    return int(m.group(1))
problems = [f"{p} exited {c}: {text.get(p, '')[-300:]}" for p, c in sorted(rc.items()) if c != 0]
if not problems:
    for key in ("refused", "given up", "dropped", "failed", "queue full", "rejected"):
        if num("bridge-1", key) != 0:
            problems.append(f"bridge: {key} {num('bridge-1', key)}: {text['bridge-1'][-400:]}")
    if not re.search(r"\b49 cycles", text["bridge-1"].splitlines()[-1]):
        problems.append(f"bridge: not 49 cycles: {text['bridge-1'][-300:]}")
    s = json.load(open(os.path.join(d, "summary.json")))
    m = json.load(open(os.path.join(d, "sim.json")))
    if s["loss_of_separation"] or s["steps"] != 48:
        problems.append(f"summary: loss of separation or not 48 steps: {json.dumps(s)[:300]}")
    flown = [v["flown"] for v in s["vehicles"]]
    if flown != [v["flown"] for v in m["vehicles"]]:
        problems.append("the flight is not sim's: " + json.dumps(
            {"flown": [(v["id"], v["flown"][20:40]) for v in s["vehicles"]],
             "sim": [(v["id"], v["flown"][20:40]) for v in m["vehicles"]]})[:1200])
    if (s["deviation"], s["effort"]) != (m["deviation"], m["effort"]):
        problems.append(f"costs differ from sim's: {s['deviation']} {s['effort']} / "
                        f"{m['deviation']} {m['effort']}")
    print(text["bridge-1"].splitlines()[-1])
if problems:
    sys.exit("\n".join(problems))
PY
        pass
        cat "$tmp/check.out"
    else
        fail "$1: $(cat "$tmp/check.out")"
    fi
}

for mode in ${MODES:-decoupled centralised}; do
    fly "$mode"
    check "$mode"
done
finish
