#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The coavoid demo: the ground coordinator, the world (terrain and tracks) and one vehicle
# process per UAV of a scenario, exchanging intents and plans over LCM's UDP multicast on
# this host, recorded by lcm-logger; then `coavoid summary` of the log: loss of
# separation or not, costs, replans, and the figure. Every message is signed: the demo
# makes fresh keys for its run (`coavoid keygen`, in OUT/keys) and every process signs
# with its own and checks the others' against OUT/keys/trust.txt.
#
# usage: scripts/demo.sh [--mode centralised|decoupled] [--scenario FILE] [--speed S]
#                        [--out DIR] [--build DIR] [--netns]
#
#   --mode       centralised (default): the coordinator plans every conflicting cluster;
#                decoupled: no coordinator, each UAV plans for itself in priority order
#   --scenario   default scenarios/paper.json (the paper's encounter)
#   --speed      scenario seconds per wall second; default 2 (see below)
#   --out        where the log, the figure and each process's messages go;
#                default BUILD/demo
#   --build      the build directory with apps/coavoid, apps/coavoid-coordinator and
#                apps/coavoid-vehicle; default build (nothing is built here)
#   --netns      run in a private network namespace (root) even when this host has a
#                multicast route, e.g. to stay apart from other LCM traffic
#
# Speed: the coordinator's plans must reach the vehicles before the next cycle starts, so
# its planning gets (dt - collect) / speed wall seconds: 0.75 s / speed for dt = 1 s. The
# paper scenario's heaviest plan (all three UAVs together, 1,331 nodes expanded) takes
# about 4.6 ms in a RelWithDebInfo build and 13 ms under the sanitizers: --speed 20 (37.5 ms)
# flies without a late plan. A plan that comes late is refused by the vehicles and planned
# again a cycle later. Every process warns on stderr when its work overran its cycle.
#
# UDP multicast needs a multicast route. A host with a default route has one; otherwise
# (a container without network, say) the demo says so and, as root, runs itself in a
# private network namespace whose loopback carries multicast.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
mode=centralised
scenario=$root/scenarios/paper.json
speed=2
out=
build=build
netns=
url="udpm://239.255.76.67:7667?ttl=0"

die() {
    echo "demo: $*" >&2
    exit 2
}

usage() {
    sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'
}

args=("$@")
while [ $# -gt 0 ]; do
    case $1 in
    --mode) [ $# -ge 2 ] || die "--mode: missing value"; mode=$2; shift 2 ;;
    --mode=*) mode=${1#*=}; shift ;;
    --scenario) [ $# -ge 2 ] || die "--scenario: missing value"; scenario=$2; shift 2 ;;
    --scenario=*) scenario=${1#*=}; shift ;;
    --speed) [ $# -ge 2 ] || die "--speed: missing value"; speed=$2; shift 2 ;;
    --speed=*) speed=${1#*=}; shift ;;
    --out) [ $# -ge 2 ] || die "--out: missing value"; out=$2; shift 2 ;;
    --out=*) out=${1#*=}; shift ;;
    --build) [ $# -ge 2 ] || die "--build: missing value"; build=$2; shift 2 ;;
    --build=*) build=${1#*=}; shift ;;
    --netns) netns=1; shift ;;
    -h | --help) usage; exit 0 ;;
    *) die "unknown argument '$1' (see scripts/demo.sh --help)" ;;
    esac
done
case $mode in
centralised | decoupled) ;;
*) die "--mode: '$mode' is not centralised or decoupled" ;;
esac
[ -f "$scenario" ] || die "--scenario: no file '$scenario'"
[[ $speed =~ ^[0-9]*\.?[0-9]+$ ]] || die "--speed: '$speed' is not a positive number"
case $build in /*) ;; *) build=$PWD/$build ;; esac
[ -n "$out" ] || out=$build/demo
coavoid=$build/apps/coavoid
coordinator=$build/apps/coavoid-coordinator
vehicle=$build/apps/coavoid-vehicle
for b in "$coavoid" "$coordinator" "$vehicle"; do
    [ -x "$b" ] || die "no $b: build first (cmake -S $root -B $build && cmake --build $build -j2)"
done
command -v lcm-logger >/dev/null || die "no lcm-logger: apt-get install liblcm-bin"

# ---- a multicast route, or a private network namespace that has one ----

has_multicast_route() {
    if command -v ip >/dev/null; then
        ip route get 239.255.76.67 >/dev/null 2>&1
    else
        # Without iproute2: a default route, or one for 224.0.0.0/4 (little-endian hex).
        awk 'NR > 1 && ($2 == "00000000" || ($2 == "000000E0" && $8 == "000000F0")) {f = 1}
             END {exit !f}' /proc/net/route
    fi
}

if [ -n "${COAVOID_DEMO_IN_NETNS:-}" ]; then
    ip link set lo up multicast on
    ip route add 224.0.0.0/4 dev lo
elif [ -n "$netns" ] || ! has_multicast_route; then
    if [ -z "$netns" ]; then
        echo "demo: this host has no multicast route, which LCM's UDP multicast needs." >&2
        echo "      To add one (as root): ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo" >&2
    fi
    if [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null && command -v ip >/dev/null; then
        echo "demo: running in a private network namespace whose loopback carries multicast" >&2
        exec unshare --net env COAVOID_DEMO_IN_NETNS=1 bash "${BASH_SOURCE[0]}" "${args[@]}"
    fi
    die "a private network namespace needs root, unshare (util-linux) and ip (iproute2)"
fi

# ---- the run ----

mkdir -p "$out"
out=$(cd "$out" && pwd)
log=$out/demo.lcm
svg=$out/demo.svg
mapfile -t ids < <("$vehicle" "$scenario" --list-ids)
[ "${#ids[@]}" -gt 0 ] || die "$scenario: no vehicles"
# How long it will take, for the user (python3 is optional here).
duration=
if command -v python3 >/dev/null; then
    duration=$(python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
print(", %d cycles at speed %s: about %.0f s" % (2 * s["horizon"], sys.argv[2],
      2 + 2 * s["horizon"] * s["dt"] / float(sys.argv[2])))' "$scenario" "$speed" 2>/dev/null || true)
fi

# Fresh keys for this run: one secret key per process, and the trust file they all share.
keys=$out/keys
rm -rf "$keys"
mkdir -p "$keys"
chmod 700 "$keys"
"$coavoid" keygen "$scenario" --dir "$keys" || die "coavoid keygen failed"
key() { echo --key "$keys/$1.key" --trust "$keys/trust.txt"; }

pids=()
logger=
cleanup() {
    for p in "${pids[@]}" $logger; do kill "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
trap 'exit 130' INT TERM

lcm-logger -q -f --lcm-url="$url" "$log" >"$out/logger.out" 2>&1 &
logger=$!

# One epoch for every process, two seconds ahead so that all have started and subscribed
# (and the logger with them) before cycle 0.
epoch=$(($(date +%s%N) / 1000 + 2000000))
common=(--lcm-url "$url" --epoch "$epoch" --speed "$speed")
names=()
# shellcheck disable=SC2046 # key's words are options
"$coavoid" world "$scenario" "${common[@]}" $(key world) 2>"$out/world.txt" &
pids+=($!) names+=(world)
if [ "$mode" = centralised ]; then
    # shellcheck disable=SC2046
    "$coordinator" "$scenario" "${common[@]}" $(key coordinator) \
        2>"$out/coordinator.txt" &
    pids+=($!) names+=(coordinator)
fi
for id in "${ids[@]}"; do
    # shellcheck disable=SC2046
    "$vehicle" "$scenario" --id "$id" --mode "$mode" "${common[@]}" \
        $(key "vehicle-$id") 2>"$out/vehicle-$id.txt" &
    pids+=($!) names+=("vehicle-$id")
done
if [ "$mode" = centralised ]; then who="world, coordinator"; else who="world, no coordinator"; fi
echo "demo: $(basename "$scenario"), $mode: $who, ${#ids[@]} vehicles (ids ${ids[*]})$duration"
echo "      (epoch $epoch, $url; every message signed, keys in $keys)"

failed=0
for i in "${!pids[@]}"; do
    if ! wait "${pids[$i]}"; then
        failed=1
        echo "demo: ${names[$i]} failed: $(tail -n 1 "$out/${names[$i]}.txt")" >&2
    fi
done
pids=()
# The last intents are in flight for a moment after their senders exit.
sleep 0.3
kill -INT "$logger" 2>/dev/null || true
wait "$logger" 2>/dev/null || true
logger=

echo
echo "processes (each one's last line; all their messages are in $out/*.txt):"
for name in "${names[@]}"; do
    sed 's/^/  /' "$out/$name.txt" | grep -v '^  coavoid: ' | tail -n 1
    warnings=$(($(wc -l <"$out/$name.txt") - 1))
    if [ "$warnings" -gt 0 ]; then
        echo "    ($warnings more lines in $out/$name.txt)"
    fi
done
echo
"$coavoid" summary "$log" "$scenario" --mode "$mode" --svg "$svg" --epoch "$epoch" \
    --trust "$keys/trust.txt" || failed=1
echo
echo "log:    $log ($(wc -c <"$log") bytes; replay it with lcm-logplayer, watch it with lcm-spy)"
echo "figure: $svg"
exit "$failed"
