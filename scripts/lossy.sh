#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The real processes on a lossy network: every process of a run (the world, the
# coordinator in centralised mode, one vehicle per UAV) in its own network namespace,
# joined by a bridge, each dropping a share of the multicast datagrams it receives
# (nftables' random drop on input), so that every receiver loses datagrams independently,
# as on a radio link; lcm-logger in a namespace of its own that loses nothing, so the log
# holds what was sent. Each run's log is judged by `coavoid summary --trust`; one line per
# run, then the count of runs that lost separation.
#
# usage: scripts/lossy.sh [--loss PERCENT] [--mode centralised|decoupled] [--runs R]
#                         [--scenario FILE] [--speed S] [--build DIR] [--out DIR]
#
#   --loss       percent of datagrams each receiver drops, 0..100; default 30
#   --mode       centralised (default) or decoupled
#   --runs       flights, default 9
#   --scenario   default scenarios/paper.json
#   --speed      scenario seconds per wall second; default 2
#   --build      the build directory (apps/coavoid, coavoid-coordinator, coavoid-vehicle);
#                default build
#   --out        where each run's log, summary and process lines go; default BUILD/lossy
#
# Needs root (it makes namespaces, a bridge and nftables rules, all inside a private
# network and mount namespace of its own: the host's network is never touched), iproute2,
# nftables, lcm-logger and python3. A measurement, not a test: docs/evaluation.md has the
# figures.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
loss=30
mode=centralised
runs=9
scenario=$root/scenarios/paper.json
speed=2
build=build
out=

die() {
    echo "lossy: $*" >&2
    exit 2
}

args=("$@")
while [ $# -gt 0 ]; do
    case $1 in
    --loss) [ $# -ge 2 ] || die "--loss: missing value"; loss=$2; shift 2 ;;
    --mode) [ $# -ge 2 ] || die "--mode: missing value"; mode=$2; shift 2 ;;
    --runs) [ $# -ge 2 ] || die "--runs: missing value"; runs=$2; shift 2 ;;
    --scenario) [ $# -ge 2 ] || die "--scenario: missing value"; scenario=$2; shift 2 ;;
    --speed) [ $# -ge 2 ] || die "--speed: missing value"; speed=$2; shift 2 ;;
    --build) [ $# -ge 2 ] || die "--build: missing value"; build=$2; shift 2 ;;
    --out) [ $# -ge 2 ] || die "--out: missing value"; out=$2; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$1' (see scripts/lossy.sh --help)" ;;
    esac
done
[[ $loss =~ ^[0-9]+$ ]] && [ "$loss" -le 100 ] || die "--loss: '$loss' is not a percent from 0 to 100"
case $mode in centralised | decoupled) ;; *) die "--mode: '$mode' is not centralised or decoupled" ;; esac
[[ $runs =~ ^[1-9][0-9]*$ ]] || die "--runs: '$runs' is not a count"
[[ $speed =~ ^[0-9]*\.?[0-9]+$ ]] || die "--speed: '$speed' is not a positive number"
[ -f "$scenario" ] || die "--scenario: no file '$scenario'"
case $build in /*) ;; *) build=$PWD/$build ;; esac
[ -n "$out" ] || out=$build/lossy
coavoid=$build/apps/coavoid
coordinator=$build/apps/coavoid-coordinator
vehicle=$build/apps/coavoid-vehicle
for b in "$coavoid" "$coordinator" "$vehicle"; do
    [ -x "$b" ] || die "no $b: build first"
done
for c in ip nft lcm-logger python3 unshare; do
    command -v "$c" >/dev/null || die "needs $c"
done
[ "$(id -u)" -eq 0 ] || die "needs root (network namespaces)"

# ---- a private network and mount namespace, then one namespace per process ----

if [ -z "${COAVOID_LOSSY_INSIDE:-}" ]; then
    exec unshare --net --mount env COAVOID_LOSSY_INSIDE=1 bash "${BASH_SOURCE[0]}" "${args[@]}"
fi
mkdir -p /run/netns
mount -t tmpfs lossy /run/netns
ip link set lo up
ip link add br0 type bridge
ip link set br0 type bridge mcast_snooping 0
ip link set br0 up

mapfile -t ids < <("$vehicle" --scenario "$scenario" --list-ids)
names=(logger world)
[ "$mode" = centralised ] && names+=(coordinator)
for id in "${ids[@]}"; do names+=("vehicle-$id"); done

# host NAME N LOSES: namespace NAME on the bridge as 10.77.0.N, dropping LOSES percent of
# the datagrams it receives from the bridge (its own looped-back ones are never lost).
host() {
    local name=$1 n=$2 drop=$3
    ip netns add "$name"
    ip link add "v$n" type veth peer name "b$n"
    ip link set "b$n" master br0 up
    ip link set "v$n" netns "$name"
    ip -n "$name" link set lo up
    ip -n "$name" addr add "10.77.0.$n/24" dev "v$n"
    ip -n "$name" link set "v$n" up multicast on
    ip -n "$name" route add 224.0.0.0/4 dev "v$n"
    if [ "$drop" -gt 0 ]; then
        ip netns exec "$name" nft add table inet lossy
        ip netns exec "$name" nft add chain inet lossy in '{ type filter hook input priority 0; }'
        local share=()
        [ "$drop" -lt 100 ] && share=(numgen random mod 100 '<' "$drop")
        # Not its own datagrams, looped back (LCM's start-up self-test is one of them).
        ip netns exec "$name" nft add rule inet lossy in iifname "v$n" ip saddr != "10.77.0.$n" \
            udp dport 7667 "${share[@]}" counter drop
    fi
}
n=1
for name in "${names[@]}"; do
    if [ "$name" = logger ]; then host "$name" "$n" 0; else host "$name" "$n" "$loss"; fi
    n=$((n + 1))
done

mkdir -p "$out"
out=$(cd "$out" && pwd)
keys=$out/keys
rm -rf "$keys"
mkdir -p "$keys"
chmod 700 "$keys"
"$coavoid" keygen "$scenario" --dir "$keys" >/dev/null
url="udpm://239.255.76.67:7667?ttl=1"

# ---- the runs ----

lost=0
for run in $(seq "$runs"); do
    dir=$out/run-$run
    rm -rf "$dir"
    mkdir -p "$dir"
    ip netns exec logger lcm-logger -q -f --lcm-url="$url" "$dir/log.lcm" >"$dir/logger.out" 2>&1 &
    logger=$!
    epoch=$(($(date +%s%N) / 1000 + 2000000))
    common=(--lcm-url "$url" --epoch "$epoch" --speed "$speed")
    pids=()
    for name in "${names[@]}"; do
        key=(--key "$keys/$name.key" --trust "$keys/trust.txt")
        case $name in
        logger) continue ;;
        world) ip netns exec world "$coavoid" world "$scenario" "${common[@]}" "${key[@]}" \
            2>"$dir/world.txt" & ;;
        coordinator) ip netns exec coordinator "$coordinator" --scenario "$scenario" \
            "${common[@]}" "${key[@]}" 2>"$dir/coordinator.txt" & ;;
        *) ip netns exec "$name" "$vehicle" --scenario "$scenario" --id "${name#vehicle-}" \
            --mode "$mode" "${common[@]}" "${key[@]}" 2>"$dir/$name.txt" & ;;
        esac
        pids+=($!)
    done
    for p in "${pids[@]}"; do wait "$p" || true; done
    sleep 0.3
    kill -INT "$logger"
    wait "$logger" || true
    "$coavoid" summary "$dir/log.lcm" "$scenario" --mode "$mode" --epoch "$epoch" --json \
        --trust "$keys/trust.txt" >"$dir/summary.json" 2>"$dir/summary.err" || true
    line=$(python3 - "$dir" <<'PY'
import glob, json, os, re, sys
d = sys.argv[1]
try:
    s = json.load(open(os.path.join(d, "summary.json")))
except Exception:
    print("no verdict: " + open(os.path.join(d, "summary.err")).read().strip()[-200:])
    sys.exit()
fallbacks = 0
for f in glob.glob(os.path.join(d, "vehicle-*.txt")):
    m = re.search(r"fallbacks (\d+)", open(f).read())
    fallbacks += int(m.group(1)) if m else 0
print("loss of separation: %s, deviation %s m^2, effort %s, replans %s, fallbacks %d, "
      "samples from an earlier plan %s" % ("yes" if s["loss_of_separation"] else "no",
      s["deviation"], s["effort"], s["replans"], fallbacks, s["log"]["samples_earlier_plan"]))
PY
)
    case $line in *"separation: yes"* | "no verdict"*) lost=$((lost + 1)) ;; esac
    echo "run $run ($mode, ${loss}% loss): $line"
done
echo "lossy: $runs runs of $(basename "$scenario"), $mode, ${loss}% loss per receiver: $lost lost separation (or gave no verdict)"
