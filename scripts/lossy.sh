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
# Each run's line also says, of the first intent of each UAV and cycle, how late after the
# cycle's start the logger heard it (the worst, in wall milliseconds, how many were later
# than 50 ms, and how many a decoupled vehicle stamped 50 ms or more after the cycle's
# start, held by its wait for the UAVs before it), and the worst of the vehicles'
# heartbeats; each node's CPU seconds and peak memory; and from the nodes' last heartbeats the
# messages they refused and dropped unchecked, and the largest inbox rate they reported;
# and from each node's summary line what reached its socket a wall second over the
# flight, read or dropped there (all also in RUN/flood.json). With --flood, a flooder (tests/forge/flood.c) in a namespace
# of its own sends copies of what it hears back to the group for the whole flight (the
# logger drops them, so the log still holds what the fleet sent).
#
# usage: scripts/lossy.sh [--loss PERCENT] [--mode centralised|decoupled] [--runs R]
#                         [--scenario FILE] [--speed S] [--build DIR] [--out DIR]
#                         [--flood heard|fresh|signed [--flood-rate N] [--flood-key ID]
#                          [--flood-cpu C[,C...]]]
#
#   --loss       percent of datagrams each receiver drops, 0..100; default 30
#   --mode       centralised (default) or decoupled
#   --runs       flights, default 9
#   --scenario   default scenarios/paper.json
#   --speed      scenario seconds per wall second; default 2
#   --build      the build directory (apps/coavoid, coavoid-coordinator, coavoid-vehicle);
#                default build
#   --out        where each run's log, summary and process lines go; default BUILD/lossy
#   --flood      heard: copies with the stamps as heard; fresh: stamps moved ahead (both
#                without keys, signatures broken); signed: signed and tagged afresh with
#                a stolen vehicle key and the fleet key (flood.c's file comment)
#   --flood-rate datagrams a second; default 100000 (signed: 10000)
#   --flood-key  the UAV whose key is stolen (signed); default the scenario's last UAV
#   --flood-cpu  CPUs C[,C...]: one flooder alone on each, sharing the rate, every other
#                process of the runs on the remaining CPUs (taskset); the kernel delivers
#                what a flooder sends on its CPU, so the fleet's CPUs carry only what the
#                nodes themselves spend. Default: one flooder, nothing pinned
#
# Needs root (it makes namespaces, a bridge and nftables rules, all inside a private
# network and mount namespace of its own: the host's network is never touched), iproute2,
# nftables, lcm-logger, lcm-gen and python3. A measurement, not a test: docs/evaluation.md has the
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
flood=
flood_rate=
flood_key=
flood_cpu=

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
    --flood) [ $# -ge 2 ] || die "--flood: missing value"; flood=$2; shift 2 ;;
    --flood-rate) [ $# -ge 2 ] || die "--flood-rate: missing value"; flood_rate=$2; shift 2 ;;
    --flood-key) [ $# -ge 2 ] || die "--flood-key: missing value"; flood_key=$2; shift 2 ;;
    --flood-cpu) [ $# -ge 2 ] || die "--flood-cpu: missing value"; flood_cpu=$2; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "${BASH_SOURCE[0]}" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$1' (see scripts/lossy.sh --help)" ;;
    esac
done
[[ $loss =~ ^[0-9]+$ ]] && [ "$loss" -le 100 ] || die "--loss: '$loss' is not a percent from 0 to 100"
case $mode in centralised | decoupled) ;; *) die "--mode: '$mode' is not centralised or decoupled" ;; esac
[[ $runs =~ ^[1-9][0-9]*$ ]] || die "--runs: '$runs' is not a count"
[[ $speed =~ ^[0-9]*\.?[0-9]+$ ]] || die "--speed: '$speed' is not a positive number"
[ -f "$scenario" ] || die "--scenario: no file '$scenario'"
case $flood in "" | heard | fresh | signed) ;; *) die "--flood: '$flood' is not heard, fresh or signed" ;; esac
if [ -z "$flood_rate" ]; then
    flood_rate=100000
    [ "$flood" = signed ] && flood_rate=10000
fi
[[ $flood_rate =~ ^[1-9][0-9]*$ ]] || die "--flood-rate: '$flood_rate' is not a count a second"
[ -z "$flood_key" ] || [[ $flood_key =~ ^[1-9][0-9]*$ ]] || die "--flood-key: '$flood_key' is not a UAV id"
# The flooders' CPUs (one flooder each, sharing the rate); empty: one flooder, unpinned.
flood_cpus=()
if [ -n "$flood_cpu" ]; then
    [ -n "$flood" ] || die "--flood-cpu: needs --flood"
    command -v taskset >/dev/null || die "--flood-cpu: taskset not found (util-linux)"
    cpus=$(nproc --all)
    IFS=, read -r -a flood_cpus <<<"$flood_cpu"
    for c in "${flood_cpus[@]}"; do
        [[ $c =~ ^[0-9]+$ ]] && [ "$c" -lt "$cpus" ] ||
            die "--flood-cpu: '$c' is not one of this machine's $cpus CPUs (0..$((cpus - 1)))"
    done
    others=$(seq 0 $((cpus - 1)) | grep -vxF -f <(printf '%s\n' "${flood_cpus[@]}") | paste -sd, || true)
    [ -n "$others" ] || die "--flood-cpu: '$flood_cpu' leaves no CPU for the fleet"
    taskset -p -c "$others" $$ >/dev/null || die "--flood-cpu: taskset failed"
fi
case $build in /*) ;; *) build=$PWD/$build ;; esac
[ -n "$out" ] || out=$build/lossy
coavoid=$build/apps/coavoid
coordinator=$build/apps/coavoid-coordinator
vehicle=$build/apps/coavoid-vehicle
for b in "$coavoid" "$coordinator" "$vehicle"; do
    [ -x "$b" ] || die "no $b: build first"
done
flooder=$build/tests/coavoid_test_flood
[ -z "$flood" ] || [ -x "$flooder" ] || die "no $flooder: build first"
for c in ip nft lcm-logger lcm-gen python3 unshare; do
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

mapfile -t ids < <("$vehicle" "$scenario" --list-ids)
names=(logger world)
[ "$mode" = centralised ] && names+=(coordinator)
for id in "${ids[@]}"; do names+=("vehicle-$id"); done
[ -n "$flood" ] && names+=(flood)
[ -n "$flood_key" ] || flood_key=${ids[-1]}

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
    case $name in logger | flood) host "$name" "$n" 0 ;; *) host "$name" "$n" "$loss" ;; esac
    [ "$name" = flood ] && flood_ip=10.77.0.$n
    n=$((n + 1))
done
if [ -n "$flood" ]; then
    # The log holds what the fleet sent: the logger does not hear the flooder.
    ip netns exec logger nft add table inet flood
    ip netns exec logger nft add chain inet flood in '{ type filter hook input priority 0; }'
    ip netns exec logger nft add rule inet flood in ip saddr "$flood_ip" counter drop
fi

mkdir -p "$out"
out=$(cd "$out" && pwd)
keys=$out/keys
rm -rf "$keys"
mkdir -p "$keys"
chmod 700 "$keys"
"$coavoid" keygen "$scenario" --dir "$keys" >/dev/null
url="udpm://239.255.76.67:7667?ttl=1"
rm -rf "$out/py"
lcm-gen -p --ppath "$out/py" "$root"/lcmtypes/*.lcm >/dev/null || die "lcm-gen -p failed"

# cpu NAME FILE CMD...: runs CMD in namespace NAME, its CPU time into FILE (bash's `times`:
# the last line is the user and system time of CMD).
cpu() {
    local name=$1 file=$2
    shift 2
    CPU_FILE=$file ip netns exec "$name" bash -c '"$@"; s=$?; times >"$CPU_FILE"; exit $s' _ "$@"
}

# peaks DIR EPOCH: until DIR/flying is gone, the peak resident memory (VmHWM) of every
# process of the run (its command line holds --epoch EPOCH) into DIR/peaks.json, read
# from /proc every 250 ms; a node's memory after its flight ends does not grow.
peaks() {
    python3 - "$1" "$2" <<'PEAKS'
import json, os, re, sys, time
d, epoch = sys.argv[1], sys.argv[2]
peak = {}
while os.path.exists(os.path.join(d, "flying")):
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            argv = open("/proc/%s/cmdline" % pid, "rb").read().split(b"\0")
            if b"--epoch" not in argv or argv[argv.index(b"--epoch") + 1].decode() != epoch:
                continue
            hwm = int(re.search(r"VmHWM:\s+(\d+)", open("/proc/%s/status" % pid).read()).group(1))
        except (OSError, AttributeError, IndexError, ValueError):
            continue
        cmd = b" ".join(argv).decode(errors="replace")
        m = re.search(r"--id (\d+)", cmd)
        name = ("vehicle-" + m.group(1) if m else "coordinator" if "coordinator" in cmd
                else "world" if " world " in cmd else None)
        if name is not None and not cmd.startswith(("bash", "ip ")):
            peak[name] = max(peak.get(name, 0), hwm)
    time.sleep(0.25)
json.dump(peak, open(os.path.join(d, "peaks.json"), "w"))
PEAKS
}

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
    flooder_pids=()
    for name in "${names[@]}"; do
        key=(--key "$keys/$name.key" --trust "$keys/trust.txt")
        case $name in
        logger) continue ;;
        flood)
            stolen=()
            [ "$flood" = signed ] && stolen=(--key "$keys/vehicle-$flood_key.key" --trust "$keys/trust.txt")
            if [ ${#flood_cpus[@]} -eq 0 ]; then
                ip netns exec flood "$flooder" --lcm-url "$url" --mode "$flood" \
                    --rate "$flood_rate" "${stolen[@]}" >"$dir/flood-0.txt" 2>&1 &
                flooder_pids+=($!)
            fi
            for c in "${flood_cpus[@]}"; do
                ip netns exec flood taskset -c "$c" "$flooder" --lcm-url "$url" --mode "$flood" \
                    --rate $((flood_rate / ${#flood_cpus[@]})) "${stolen[@]}" \
                    >"$dir/flood-$c.txt" 2>&1 &
                flooder_pids+=($!)
            done
            continue ;;
        world) cpu world "$dir/world.cpu" "$coavoid" world "$scenario" "${common[@]}" "${key[@]}" \
            2>"$dir/world.txt" & ;;
        coordinator) cpu coordinator "$dir/coordinator.cpu" "$coordinator" "$scenario" \
            "${common[@]}" "${key[@]}" 2>"$dir/coordinator.txt" & ;;
        *) cpu "$name" "$dir/$name.cpu" "$vehicle" "$scenario" --id "${name#vehicle-}" \
            --mode "$mode" "${common[@]}" "${key[@]}" 2>"$dir/$name.txt" & ;;
        esac
        pids+=($!)
    done
    touch "$dir/flying"
    peaks "$dir" "$epoch" &
    peaks_pid=$!
    for p in "${pids[@]}"; do wait "$p" || true; done
    rm -f "$dir/flying"
    wait "$peaks_pid" || true
    for p in "${flooder_pids[@]}"; do
        kill -TERM "$p" 2>/dev/null || true
        wait "$p" || true
    done
    sleep 0.3
    kill -INT "$logger"
    wait "$logger" || true
    "$coavoid" summary "$dir/log.lcm" "$scenario" --mode "$mode" --epoch "$epoch" --json \
        --trust "$keys/trust.txt" >"$dir/summary.json" 2>"$dir/summary.err" || true
    line=$(python3 - "$dir" "$out/py" "$epoch" "$speed" "$flood" "$scenario" <<'PY'
import glob, json, os, re, struct, sys
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
line = ("loss of separation: %s, deviation %s m^2, effort %s, replans %s, fallbacks %d, "
        "samples from an earlier plan %s" % ("yes" if s["loss_of_separation"] else "no",
        s["deviation"], s["effort"], s["replans"], fallbacks, s["log"]["samples_earlier_plan"]))
sys.path.insert(0, sys.argv[2])
from coavoid import intent_t, status_t
epoch, speed = int(sys.argv[3]), float(sys.argv[4])
dt_us = round(json.load(open(sys.argv[6]))["dt"] * 1e6)
data = open(os.path.join(d, "log.lcm"), "rb").read()
i, first, held, beats, status, codes, reasons = 0, {}, 0, {}, {}, {}, {}
ts_first, ts_last = None, 0
while i + 28 <= len(data):
    _, _, ts, clen, dlen = struct.unpack_from(">IqqII", data, i)
    ts_first = ts if ts_first is None else ts_first
    ts_last = ts
    channel = data[i + 28:i + 28 + clen].decode()
    payload = data[i + 28 + clen:i + 28 + clen + dlen]
    i += 28 + clen + dlen
    if channel == "COAVOID_INTENT":
        m = intent_t.decode(payload)
        if (m.uav_id, m.plan_utime) not in first:
            first[(m.uav_id, m.plan_utime)] = ts
            # Held by the protocol: a decoupled vehicle's wait for the UAVs before it.
            held += m.utime - m.plan_utime >= 50000
    elif channel == "COAVOID_STATUS":
        m = status_t.decode(payload)
        if m.node_id < 65000:  # a vehicle's, sent with its intent, in its cycle
            beats.setdefault((m.node_id, epoch + (m.utime - epoch) // dt_us * dt_us), ts)
        r = status.get(m.node_id, (0, 0, 0))
        status[m.node_id] = (m.messages_rejected, m.messages_dropped, max(m.inbox_rate, r[2]))
        codes.setdefault(m.node_id, set()).add(m.last_reject_code)
        reasons[m.node_id] = reasons.get(m.node_id, 0) | m.reasons
# A cycle's start in wall time: scenario time runs `speed` times the wall's from epoch.
late = [(ts - (epoch + (k - epoch) / speed)) / 1000 for (_, k), ts in first.items()]
beat_late = [(ts - (epoch + (k - epoch) / speed)) / 1000 for (_, k), ts in beats.items()]
worst = max(late) if late else float("nan")
cpu, usage = [], {}
try:
    peaks = json.load(open(os.path.join(d, "peaks.json")))
except (OSError, ValueError):
    peaks = {}
for f in sorted(glob.glob(os.path.join(d, "*.cpu"))):
    u, sy = (float(x.rstrip("s").split("m")[0]) * 60 + float(x.rstrip("s").split("m")[1])
             for x in open(f).read().split()[-2:])
    name = os.path.basename(f)[:-4]
    usage[name] = {"cpu_s": u + sy, "peak_rss_kib": peaks.get(name, 0)}
    cpu.append("%s %.1f/%.1f" % (name, u + sy, peaks.get(name, 0) / 1024))
nodes = ", ".join("%d: %d/%d/%d" % (k, *v) for k, v in sorted(status.items()))
# What reached each node's socket: datagrams read and dropped there (its summary line),
# a wall second over the flight's span in the log.
span = (ts_last - ts_first) / 1e6 if ts_last > ts_first else float("nan")
arrived = {}
for f in sorted(glob.glob(os.path.join(d, "*.txt"))):
    m = re.search(r"datagrams (\d+) \(dropped at the socket (\d+)", open(f).read())
    if m:
        arrived[os.path.basename(f)[:-4]] = (int(m.group(1)), int(m.group(2)))
# The flooders' lines, their sends and rates added up.
flood_lines = [open(f).read().strip() for f in sorted(glob.glob(os.path.join(d, "flood-*.txt")))]
sent_each = [re.search(r"sent (\d+) in ([0-9.]+) s", t) for t in flood_lines]
sent = sum(int(m.group(1)) for m in sent_each if m)
rate = sum(int(m.group(1)) / float(m.group(2)) for m in sent_each if m and float(m.group(2)) > 0)
flooded = ("flood: %d flooder(s) sent %d (%.0f a second)" % (len(flood_lines), sent, rate)
           if sys.argv[5] else "no flood")
json.dump({"loss_of_separation": s["loss_of_separation"], "worst_late_ms": worst,
           "late_over_50ms": sum(x > 50 for x in late), "intents": len(late),
           "held_by_protocol": held, "worst_heartbeat_late_ms": max(beat_late, default=0),
           "sent": sent, "sent_a_second": rate,
           "nodes": {str(k): {"refused": v[0], "dropped": v[1], "max_rate": v[2],
                              "codes": sorted(codes[k]), "reasons": reasons[k]}
                     for k, v in status.items()},
           "sockets": {k: {"datagrams": v[0], "dropped": v[1],
                           "arrived_a_second": (v[0] + v[1]) / span}
                       for k, v in arrived.items()},
           "processes": usage},
          open(os.path.join(d, "flood.json"), "w"))
sockets = ", ".join("%s %.0f/s (%d dropped)" % (k, (v[0] + v[1]) / span, v[1])
                    for k, v in arrived.items())
line += ("; intents heard late: worst %.1f ms, %d of %d over 50 ms (%d held by the "
         "protocol), vehicles' heartbeats worst %.1f ms; cpu s/peak MiB: %s; refused/dropped/max rate: "
         "%s; at the sockets: %s; %s" % (worst, sum(x > 50 for x in late), len(late), held,
                     max(beat_late, default=float("nan")), ", ".join(cpu), nodes, sockets,
                     flooded))
print(line)
PY
)
    case $line in *"separation: yes"* | "no verdict"*) lost=$((lost + 1)) ;; esac
    echo "run $run ($mode, ${loss}% loss): $line"
done
echo "lossy: $runs runs of $(basename "$scenario"), $mode, ${loss}% loss per receiver: $lost lost separation (or gave no verdict)"
