#!/bin/bash
# SPDX-License-Identifier: MIT
# The real-time drivers as separate processes over LCM's UDP multicast, recorded by
# lcm-logger, in a private network namespace (so the test works where the host has no
# multicast route and never touches the host's network):
#   a) centralised: the coordinator's plans reach the vehicles and are adopted, the
#      encounter is resolved (`coavoid summary` of the log: no loss of separation), and
#      every logged message decodes with the generated types;
#   b) the coordinator is stopped (SIGTERM) mid-encounter, before it has resolved it: the
#      vehicles fall back to planning for themselves and stay separated;
#   c) decoupled without a coordinator: no loss of separation, and the same flight and
#      planning calls as `coavoid sim`;
#   d) an attacker on the group (tests/forge/forge.c, lcm-logplayer), both modes: forged
#      maps, plans and intents signed with a stolen vehicle key, copies with higher
#      sequence numbers, replays of the run's own traffic and of an earlier run's log;
#   e) a path that drops every IP datagram over 1,500 bytes (an nftables rule in the
#      namespace): every message fits one datagram, so the flight is the same as with no
#      loss, and as `coavoid sim`'s;
#   f) centralised vehicles whose coordinator never speaks, on an encounter no priority
#      order solves: they plan their group jointly and stay separated; with
#      --joint-members 0 they do not, and lose separation;
#   (d, last) an attacker holding the coordinator's key dives UAV 1 far below the
#      scenario's floor: the vehicle refuses every such plan and stays above it;
# (the flights: late_encounter.json for a and b and the dive, paper.json with a lead-in for c, d, e,
# tests/encounters/joint_plan_220.json for f)
# and every bad option or input of the drivers exits 2 with one line, the missing
# multicast route included. Every process signs and checks with keys from
# `coavoid keygen`; `--insecure` runs are named as such.
#
# Where no namespace can be made (a container without CAP_SYS_ADMIN) it runs on the host's
# multicast route instead, on a port of its own, and says so.
#
# usage: bash multiprocess.sh <path-to-coavoid> <source-dir> [FORGE [PART]]   (VERBOSE=1 shows
# more); PART is all (the default), centralised, decoupled or paths: ctest runs the three
# parts as cli_multiprocess_PART, side by side.
# The drivers are found beside coavoid (coavoid-coordinator, coavoid-vehicle).
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
scenarios=$src/scenarios
apps=$(dirname "$bin")
coordinator=$apps/coavoid-coordinator
vehicle=$apps/coavoid-vehicle
# The attacker (tests/forge/forge.c), argument 3.
forge=${3:-}
# Which flights (argument 4): all, or one part of them (the end of this file).
part=${4:-all}
if [ ! -x "$coordinator" ] || [ ! -x "$vehicle" ]; then
    echo "FAIL: no coavoid-coordinator/coavoid-vehicle beside $bin (CMake adds this test only with LCM)" >&2
    exit 1
fi
# Every fleet flies on a port of its own above port_base (fly): fleets side by side on the
# one group hear only themselves, as LCM's udpm delivers by port.
port_base=7667
netns=1
if ! in_multicast_netns "$@"; then
    # No namespace (a container without CAP_SYS_ADMIN, say): the host's own multicast
    # route will do, on a port of this run's own so that nothing else hears it; ttl=0
    # keeps it on the host.
    netns=
    if ! { ip route get 239.255.76.67 ||
        awk 'NR > 1 && ($2 == "00000000" || ($2 == "000000E0" && $8 == "000000F0")) {f = 1}
             END {exit !f}' /proc/net/route; } >/dev/null 2>&1; then
        fail "no private network namespace and no multicast route on the host: cannot run"
        finish
        exit
    fi
    port_base=$((20000 + $$ % 2000 * 20))
    echo "note: on the host's network (ports above $port_base)"
fi
# Scenario seconds per wall second; SPEED overrides. The flights whose checks hold only
# while every message meets its deadline run at half that, still twice real time: (a),
# whose UAVs never plan for themselves, and those compared with `coavoid sim` step for step
# (c, the decoupled attacks, e). A UAV hears the higher priorities within its priority wait
# (dt / 2 / speed of wall time); one in conflict whose coordinator has not committed a plan
# for it within the answer wait (0.6 dt / speed) plans for itself: safely, but not as sim
# does. At speed 4 the sanitizers sharing two cores with other tests can miss those
# deadlines (tests/README.md has the margins); SPEED_EXACT overrides.
speed=${SPEED:-4}
speed_exact=${SPEED_EXACT:-2}
# Wall time between starting the processes and cycle 0: room for them, and the fleets
# started beside them, to start and subscribe under the sanitizers.
lead_us=2500000
# How many fleets fly at once (fly); FLEETS overrides. Each waits on the scenario clock far
# more than it computes (a flight of 48 cycles takes about 1.5 CPU seconds under the
# sanitizers), so that side by side they keep the deadlines they keep alone.
fleets_at_once=${FLEETS:-6}

# The types generated from lcmtypes/ for Python: an independent decoder of the log.
if ! lcm-gen -p --ppath "$tmp/py" "$src"/lcmtypes/*.lcm >/dev/null 2>&1; then
    fail "lcm-gen -p failed"
fi

# Every event of an lcm-logger log, decoded with the generated types by its channel;
# prints a JSON summary (counts per channel, what the plans (one message per UAV: gathered
# by plan_id), statuses and conflict reports say, each node's last heartbeat reasons, the
# largest event, and how much wall time the latest switch to a coordinator's plan left
# before the answer wait ended, given the run's epoch and speed) or exits non-zero naming
# the first event that does not decode.
cat >"$tmp/log.py" <<'PY'
import json, struct, sys
sys.path.insert(0, sys.argv[2])
from coavoid import intent_t, plan_t, track_t, obstacle_map_t, conflict_report_t, status_t, \
    agreement_t
types = {"COAVOID_INTENT": intent_t, "COAVOID_PLAN": plan_t, "COAVOID_TRACK": track_t,
         "COAVOID_OBSTACLES": obstacle_map_t, "COAVOID_CONFLICTS": conflict_report_t,
         "COAVOID_STATUS": status_t, "COAVOID_AGREEMENT": agreement_t}
data = open(sys.argv[1], "rb").read()
i, n = 0, 0
counts, intents, statuses, plans, reports, rejected = {}, {}, {}, {}, [], {}
codes, reasons, largest = {}, {}, 0
# Against loss every intent and the coordinator's heartbeat go out with copies, and a plan
# may go out again (docs/protocol.md): intents are counted once per UAV and cycle
# (plan_utime), heartbeats once per node and cycle (a copy follows within half a cycle),
# plan rows once per row.
intent_cycles, last_status = set(), {}
# The default answer wait, 0.6 dt, with dt = 1 s in every scenario flown here.
epoch, speed, answer_wait = int(sys.argv[3]), float(sys.argv[4]), 600000
switched = {}
while i < len(data):
    magic, _, _, clen, dlen = struct.unpack_from(">IqqII", data, i)
    assert magic == 0xEDA1DA01, f"event {n}: bad magic at byte {i}"
    i += 28
    channel = data[i:i + clen].decode()
    payload = data[i + clen:i + clen + dlen]
    i += clen + dlen
    if channel == "LCM_SELF_TEST":  # udpm's own start-up check, one per process
        continue
    assert channel in types, f"event {n}: unknown channel {channel}"
    try:
        m = types[channel].decode(payload)
    except Exception as e:
        sys.exit(f"event {n} on {channel} does not decode: {e!r}")
    counts[channel] = counts.get(channel, 0) + 1
    largest = max(largest, dlen)
    if channel == "COAVOID_INTENT":
        if (m.uav_id, m.plan_utime) not in intent_cycles:
            intent_cycles.add((m.uav_id, m.plan_utime))
            intents[m.uav_id] = intents.get(m.uav_id, 0) + 1
    elif channel == "COAVOID_STATUS":
        if m.utime - last_status.get(m.node_id, -10**18) >= 500000:
            statuses.setdefault(m.node_id, []).append(m.mode)
        last_status[m.node_id] = m.utime
        rejected[m.node_id] = max(rejected.get(m.node_id, 0), m.messages_rejected)
        codes.setdefault(m.node_id, set()).add(m.last_reject_code)
        reasons[m.node_id] = m.reasons
    elif channel == "COAVOID_PLAN":
        p = plans.setdefault((m.coordinator_id, m.plan_id), {
            "status": m.status, "ids": list(m.uav_ids[:m.vehicle_count]), "rows": []})
        if m.row_uav_id not in p["rows"]:
            p["rows"].append(m.row_uav_id)
    elif channel == "COAVOID_CONFLICTS":
        reports.append(m.conflict_count)
    elif channel == "COAVOID_AGREEMENT" and m.kind == agreement_t.KIND_SWITCHED and \
            m.utime >= epoch:  # not a replay of an earlier run
        into = (m.utime - epoch) % 1000000
        switched.setdefault((m.node_id, m.plan_id), into)
    n += 1
margin = round((answer_wait - max(switched.values())) / speed / 1000) if switched else None
print(json.dumps({"switch_margin_ms": margin, "events": n, "counts": counts, "intents": intents,
                  "statuses": statuses, "plans": list(plans.values()), "reports": reports,
                  "rejected": rejected, "codes": {k: sorted(v) for k, v in codes.items()},
                  "reasons": reasons, "largest": largest}))
PY

# The fleet's keys, for every run (late_encounter.json and paper.json fly UAVs 1, 2, 3):
# the same keys across runs, so that an earlier run's log is a real replay.
keys=$tmp/keys
mkdir -p "$keys"
if ! "$bin" keygen "$scenarios/paper.json" --dir "$keys" >"$tmp/keygen.out" 2>&1; then
    fail "coavoid keygen: $(cat "$tmp/keygen.out")"
fi
# key NODE: a process's key options (NODE coordinator, world or vehicle-ID).
key() { echo --key "$keys/$1.key" --trust "$keys/trust.txt"; }

# ids SCENARIO: the scenario's vehicle ids.
ids() { "$vehicle" "$1" --list-ids; }

# sleep_until_cycle EPOCH CYCLE: sleeps until the wall time at which the scenario clock
# (dt = 1 s) reaches CYCLE, a real number of cycles after EPOCH.
sleep_until_cycle() {
    local wait
    wait=$(awk -v e="$1" -v c="$2" -v s="$speed" -v now="$(date +%s%N)" \
        'BEGIN { d = (e * 1000 + c * 1e9 / s - now) / 1e9; if (d < 0) d = 0; printf "%.3f", d }')
    sleep "$wait"
}

# fleet NAME SCENARIO MODE STEPS KILL_AT [COORDINATOR_ARGS...]: on the port $port,
# lcm-logger, the world, the coordinator (centralised) and one vehicle per UAV, on one
# epoch; with KILL_AT (a number of cycles, or -), the coordinator gets SIGTERM then. MODE
# leaderless: the vehicles fly centralised but no coordinator runs (it is gone before its
# first message); each vehicle also gets the options in $vehicle_args. With $attack set,
# the attacker too (forge.c's attack, its options in $forge_args; "replay-log" replays
# $replay_log with lcm-logplayer instead). Leaves in $tmp/NAME: log.lcm, each process's
# stderr (NAME.txt) and exit status (NAME.rc), log.json (log.py's summary) and
# summary.json (`coavoid summary --json` of the log).
fleet() {
    local name=$1 scenario=$2 mode=$3 steps=$4 kill_at=$5
    shift 5
    local dir=$tmp/$name vmode=$mode url="udpm://239.255.76.67:${port:?fleet flies under fly}?ttl=0"
    [ "$mode" = leaderless ] && vmode=centralised
    mkdir -p "$dir"
    lcm-logger -q -f --lcm-url="$url" "$dir/log.lcm" >"$dir/logger.out" 2>&1 &
    local logger=$!
    local epoch=$(($(date +%s%N) / 1000 + lead_us))
    echo "$epoch" >"$dir/epoch"
    # The scenario time past the run's last stamp (its cycles 0..STEPS), for a replay of its
    # log that must come after it.
    echo $((epoch + (steps + 1) * 1000000)) >"$dir/end"
    local common=(--lcm-url "$url" --epoch "$epoch" --speed "$speed" --steps "$steps")
    local pids=() names=() cpid=
    # shellcheck disable=SC2046 # key's words are options
    "$bin" world "$scenario" "${common[@]}" $(key world) 2>"$dir/world.txt" &
    pids+=($!) names+=(world)
    if [ "$mode" = centralised ]; then
        # shellcheck disable=SC2046
        "$coordinator" "$scenario" "${common[@]}" $(key coordinator) "$@" \
            2>"$dir/coordinator.txt" &
        cpid=$!
        pids+=("$cpid") names+=(coordinator)
    fi
    if [ "${attack:-}" = replay-log ]; then
        lcm-logplayer --lcm-url="$url" "$replay_log" >"$dir/forge.txt" 2>&1 &
        pids+=($!) names+=(forge)
    elif [ -n "${attack:-}" ]; then
        local seconds
        seconds=$(awk -v l="$lead_us" -v n="$steps" -v s="$speed" 'BEGIN { print l / 1e6 + n / s + 1 }')
        # shellcheck disable=SC2086 # forge_args are options
        "$forge" --lcm-url "$url" --attack "$attack" --seconds "$seconds" --target 1 --other 2 \
            ${forge_args:-} >"$dir/forge.txt" 2>&1 &
        pids+=($!) names+=(forge)
    fi
    local id
    for id in $(ids "$scenario"); do
        # shellcheck disable=SC2046
        # shellcheck disable=SC2086 # vehicle_args are options
        "$vehicle" "$scenario" --id "$id" --mode "$vmode" "${common[@]}" \
            $(key "vehicle-$id") ${vehicle_args:-} 2>"$dir/vehicle-$id.txt" &
        pids+=($!) names+=("vehicle-$id")
    done
    if [ "$kill_at" != - ]; then
        sleep_until_cycle "$epoch" "$kill_at"
        kill -TERM "$cpid"
    fi
    local i
    for i in "${!pids[@]}"; do
        wait "${pids[$i]}"
        echo $? >"$dir/${names[$i]}.rc"
    done
    sleep 0.3 # the last messages are in flight for a moment
    kill -INT "$logger"
    wait "$logger"
    python3 "$tmp/log.py" "$dir/log.lcm" "$tmp/py" "$epoch" "$speed" >"$dir/log.json" \
        2>"$dir/log.err"
    "$bin" summary "$dir/log.lcm" "$scenario" --mode "$vmode" --json --epoch "$epoch" \
        --trust "$keys/trust.txt" >"$dir/summary.json" 2>"$dir/summary.err"
    echo $? >"$dir/summary.rc"
    if [ -n "${VERBOSE:-}" ]; then
        tail -n 3 "$dir"/*.txt "$dir/log.json" "$dir/summary.err"
    fi
}

# fly FLEET_ARGS...: fleet FLEET_ARGS... in the background, on the next port, once fewer
# than $fleets_at_once fly; landed NAME waits for fleet NAME to end.
declare -A flying=()
port_next=$port_base
fly() {
    while [ "$(jobs -rp | wc -l)" -ge "$fleets_at_once" ]; do
        wait -n
    done
    port_next=$((port_next + 1))
    port=$port_next fleet "$@" &
    flying[$1]=$!
}
landed() { wait "${flying[$1]}"; }
land_all() {
    local name
    for name in "${!flying[@]}"; do
        landed "$name"
    done
}

# check NAME ASSERTIONS: judges fleet NAME (judge) once every fleet has landed (settle),
# in the order the checks were asked for.
checks=()
check() {
    printf '%s\n' "$2" >"$tmp/$1.asserts"
    checks+=("$1")
}
settle() {
    local name
    land_all
    for name in "${checks[@]}"; do
        judge "$name" "$(cat "$tmp/$name.asserts")"
    done
    checks=()
}

# judge NAME ASSERTIONS: evaluates each line of ASSERTIONS (Python) over the run in
# $tmp/NAME, with
#   rc[p]      exit status of process p ("world", "coordinator", "vehicle-1", ...; and
#              "summary", `coavoid summary`)
#   line[p]    its last stderr line (the summary), and num(p, key) a number in it
#              ("plans adopted" -> the integer after it)
#   log        log.py's summary of the log, and s the summary's JSON result (None when
#              it failed)
judge() {
    local name=$1 asserts=$2
    local dir=$tmp/$name
    if ! python3 - "$dir" "$asserts" >"$tmp/py.out" 2>&1 <<'PY'; then
import glob, json, os, re, sys
d = sys.argv[1]
rc, line, text = {}, {}, {}
for f in glob.glob(os.path.join(d, "*.rc")):
    p = os.path.basename(f)[:-3]
    rc[p] = int(open(f).read())
for f in glob.glob(os.path.join(d, "*.txt")):
    p = os.path.basename(f)[:-4]
    text[p] = open(f).read()
    lines = text[p].strip().splitlines()
    line[p] = lines[-1] if lines else ""
def num(p, key):
    m = re.search(re.escape(key) + r" (\d+)", line[p])
    assert m, f"{p}: no '{key}' in its summary line: {line[p]!r}"
    return int(m.group(1))
try:
    log = json.load(open(os.path.join(d, "log.json")))
except Exception:
    sys.exit("the log does not decode: " + open(os.path.join(d, "log.err")).read()[-600:])
try:
    s = json.load(open(os.path.join(d, "summary.json")))
except Exception:
    s = None
for a in sys.argv[2].strip().splitlines():
    if not eval(a):
        sys.exit("assertion failed: " + a + "\n" + "\n".join(
            f"  {p}: rc {rc.get(p)}: {text[p].strip()[-400:]}" for p in sorted(text)) +
            f"\n  log: {json.dumps(log)[:600]}\n  summary: " +
            (json.dumps(s)[:300] if s is not None else
             open(os.path.join(d, "summary.err")).read()[-300:]))
if log.get("switch_margin_ms") is not None:
    print(f"note: {os.path.basename(d)}: the latest switch to a plan came "
          f"{log['switch_margin_ms']} ms of wall time before the answer wait ended")
PY
        fail "$name: $(cat "$tmp/py.out")"
    else
        cat "$tmp/py.out"
        pass
    fi
}

headon=$scenarios/headon.json
coavoid=$bin
paper=$scenarios/paper.json
late=$scenarios/late_encounter.json
# z of UAV i's flown samples 30..38 (the crossing of late_encounter.json), from the
# summary's JSON.
crossing='[p[3] for v in s["vehicles"] if v["id"] == i for p in v["flown"][30:39]]'
# The paper's flight with a lead-in (c), and `coavoid sim`'s flight of it, decoupled: flown
# and compared with by (c), (d) and (e).
lead_in "$paper" "$tmp/paper_lead_in.json" 18
mkdir -p "$tmp/decoupled"
"$bin" sim "$tmp/paper_lead_in.json" --mode decoupled --steps 48 --json >"$tmp/decoupled/sim.json"

# ---- bad options and inputs: exit 2, one line ----

section_bad_inputs() {
bin=$vehicle expect_bad "vehicle without --id" "--id" "$headon"
bin=$vehicle expect_bad "vehicle without a scenario" "missing SCENARIO.json" --id 1
bin=$vehicle expect_bad "vehicle with an unknown id" "no vehicle 9" "$headon" --id 9
bin=$vehicle expect_bad "vehicle id 0" "--id" "$headon" --id 0
bin=$vehicle expect_bad "vehicle, bad mode" "--mode" "$headon" --id 1 --mode fast
bin=$vehicle expect_bad "vehicle, a missing scenario" "$tmp/none.json" "$tmp/none.json" --id 1
bin=$vehicle expect_bad "vehicle, speed 0" "--speed" "$headon" --id 1 --speed 0
bin=$vehicle expect_bad "vehicle, speed nan" "--speed" "$headon" --id 1 --speed nan
bin=$vehicle expect_bad "vehicle, steps 0" "--steps" "$headon" --id 1 --steps 0
bin=$vehicle expect_bad "vehicle, an epoch in seconds" "--epoch" "$headon" --id 1 --epoch 17
bin=$vehicle expect_bad "vehicle, a run that has ended" "ended" "$headon" --id 1 \
    --epoch 1000000 --steps 5
bin=$vehicle expect_bad "vehicle, epoch given twice" "more than once" "$headon" --id 1 \
    --epoch 1 --epoch 2
bin=$vehicle expect_bad "vehicle, priority wait of a whole cycle" "--priority-wait" \
    "$headon" --id 1 --mode decoupled --priority-wait 1 --insecure
bin=$vehicle expect_bad "vehicle, coordinator timeout when decoupled" "--coordinator-timeout" \
    "$headon" --id 1 --mode decoupled --coordinator-timeout 2
bin=$vehicle expect_bad "vehicle, a joint plan of one" "--joint-members" "$headon" --id 1 \
    --joint-members 1 --insecure
bin=$vehicle expect_bad "vehicle, a joint plan of 11" "--joint-members" "$headon" --id 1 \
    --joint-members 11 --insecure
bin=$vehicle expect_bad "vehicle, a joint plan when decoupled" "--joint-members" \
    "$headon" --id 1 --mode decoupled --joint-members 3 --insecure
bin=$vehicle expect_bad "vehicle, a joint beta with no joint plan" "--joint-beta" \
    "$headon" --id 1 --joint-members 0 --joint-beta 100 --insecure
bin=$vehicle expect_bad "vehicle, joint beta 0" "--joint-beta" "$headon" --id 1 \
    --joint-beta 0 --insecure
bin=$vehicle expect_bad "vehicle, an unknown LCM provider" "--lcm-url" "$headon" --id 1 \
    --lcm-url "nope://" --insecure
bin=$vehicle expect_bad "vehicle, a stray argument" "unexpected argument" "$headon" "$headon" --id 1
bin=$coordinator expect_bad "coordinator, --max-centralised 11" "--max-centralised" \
    "$headon" --max-centralised 11
bin=$coordinator expect_bad "coordinator, --beta 0" "--beta" "$headon" --beta 0
bin=$coordinator expect_bad "coordinator, --collect of a whole cycle" "--collect" \
    "$headon" --collect 1 --insecure
bin=$coordinator expect_bad "coordinator, an unknown option" "unknown option" \
    "$headon" --id 1
# A horizon whose intents would not fit one datagram (docs/messages.md).
python3 - "$headon" "$tmp/long.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["horizon"] = 41
json.dump(s, open(sys.argv[2], "w"))
PY
bin=$vehicle expect_bad "vehicle, horizon 41" "at most 40" "$tmp/long.json" --id 1
bin=$coordinator expect_bad "coordinator, horizon 41" "at most 40" "$tmp/long.json"
expect_bad "world, horizon 41" "at most 40" world "$tmp/long.json"
expect_bad "world without a scenario" "SCENARIO" world
expect_bad "world, bad speed" "--speed" world "$headon" --speed -1
# Keys: required unless --insecure, never both; a key file must be the node's own, its
# owner's only, and every line of a trust file is checked.
bin=$vehicle expect_bad "vehicle without --key" "--key: required" "$paper" --id 1
bin=$vehicle expect_bad "vehicle without --trust" "--trust: required" "$paper" --id 1 \
    --key "$keys/vehicle-1.key"
bin=$vehicle expect_bad "vehicle, --insecure with --key" "--insecure" "$paper" --id 1 \
    --insecure --key "$keys/vehicle-1.key"
bin=$vehicle expect_bad "vehicle 2 with vehicle 1's key" "not this node's" "$paper" \
    --id 2 --key "$keys/vehicle-1.key" --trust "$keys/trust.txt"
bin=$coordinator expect_bad "coordinator with the world's key" "not this node's" \
    "$paper" --key "$keys/world.key" --trust "$keys/trust.txt"
cp "$keys/vehicle-1.key" "$tmp/open.key" && chmod 644 "$tmp/open.key"
bin=$vehicle expect_bad "vehicle, a key readable by others" "readable by others" \
    "$paper" --id 1 --key "$tmp/open.key" --trust "$keys/trust.txt"
printf '1 coordinator 65001 00\n' >"$tmp/bad-trust.txt"
bin=$vehicle expect_bad "vehicle, a bad trust line" "line 1: PUBLIC_KEY_HEX" \
    "$paper" --id 1 --key "$keys/vehicle-1.key" --trust "$tmp/bad-trust.txt"
bin=$vehicle expect_bad "vehicle, a missing key file" "cannot read" \
    "$paper" --id 1 --key "$tmp/none.key" --trust "$keys/trust.txt"
expect_bad "world without --key" "--key: required" world "$paper"
# Without a multicast route (a fresh namespace inside this one) LCM cannot start; the
# drivers say so in one line with the fix.
if [ -n "$netns" ]; then
    how=-rn
    if [ "$(id -u)" -eq 0 ]; then how=--net; fi
    also="ip route add 224.0.0.0/4 dev lo" bin=unshare expect_bad \
        "vehicle without a multicast route" "no multicast route" \
        "$how" "$vehicle" "$headon" --id 1 --insecure
    also="ip route add 224.0.0.0/4 dev lo" bin=unshare expect_bad \
        "world without a multicast route" "no multicast route" "$how" "$coavoid" world "$headon" --insecure
fi
if "$vehicle" "$paper" --list-ids >"$tmp/ids" 2>&1 &&
    [ "$(tr '\n' ' ' <"$tmp/ids")" = "1 2 3 " ]; then
    pass
else
    fail "--list-ids: $(cat "$tmp/ids")"
fi

# The drivers are listed where users look for them.
if "$bin" --help | grep -q '^  world ' && "$bin" world --help | grep -q -- '--epoch UTIME' &&
    "$vehicle" --help | grep -q -- '--coordinator-timeout S' &&
    "$coordinator" --help | grep -q -- '--max-centralised N'; then
    pass
else
    fail "--help: world is not listed, or a driver's help lacks its options"
fi
}

# ---- a) centralised: plans reach the vehicles, the encounters are resolved ----

# A head-on pair in conflict from the start, and UAV 3 crossing UAV 1's path around
# t = 35 s, which enters the horizon (20 s) later: the coordinator plans both.
section_centralised() {
speed=$speed_exact
fly centralised "$late" centralised 40 -
check centralised "
rc == {'world': 0, 'coordinator': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'summary': 0}
all(num(f'vehicle-{i}', 'plans adopted') >= 1 for i in (1, 2, 3))
all(num(f'vehicle-{i}', 'fallbacks') == 0 for i in (1, 2, 3))
all(num(f'vehicle-{i}', 'plans run') == 0 for i in (1, 2, 3))
all(num(p, 'rejected') == 0 for p in ('coordinator', 'vehicle-1', 'vehicle-2', 'vehicle-3'))
num('coordinator', 'plans published') >= 2
sum(p['status'] == 0 for p in log['plans']) >= 2
all(sorted(p['rows']) == sorted(p['ids']) for p in log['plans'])
log['largest'] <= 1400
set(log['counts']) == {'COAVOID_INTENT', 'COAVOID_PLAN', 'COAVOID_STATUS', 'COAVOID_OBSTACLES', 'COAVOID_CONFLICTS', 'COAVOID_AGREEMENT'}
log['intents'] == {str(i): 41 for i in (1, 2, 3)}
all(len(log['statuses'][str(i)]) == 41 and set(log['statuses'][str(i)]) == {0} for i in (1, 2, 3))
len(log['statuses']['65001']) == 40 and log['counts']['COAVOID_CONFLICTS'] == 40
s is not None and s['loss_of_separation'] is False and s['steps'] == 40
s['replans'] == num('coordinator', 'plans run')
any(z != 100 for i in (1, 3) for z in $crossing)
"
}

# ---- b) the coordinator stopped mid-encounter, before it resolved it ----

# The same flight; SIGTERM at 12.6 s, after the coordinator resolved the head-on pair and
# before UAV 3's crossing has entered its horizon. The UAVs hear its heartbeat stop, fall
# back to planning for themselves (2.5 s later) and solve the crossing on their own.
section_stopped() {
speed=${SPEED:-4}
fly stopped "$late" centralised 40 12.6
check stopped "
rc == {'world': 0, 'coordinator': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'summary': 0}
'stopped by SIGTERM' in line['coordinator']
num('coordinator', 'plans published') >= 1
all(num(f'vehicle-{i}', 'fallbacks') >= 1 for i in (1, 2, 3))
sum(num(f'vehicle-{i}', 'plans run') for i in (1, 2, 3)) >= 1
all(log['statuses'][str(i)][0] == 0 and log['statuses'][str(i)][-1] == 1 for i in (1, 2, 3))
len(log['statuses']['65001']) in (12, 13)
s is not None and s['loss_of_separation'] is False
any(z != 100 for i in (1, 3) for z in $crossing)
"
}

# ---- c) decoupled, no coordinator ----

# The same closed loop as `coavoid sim`: each UAV waits for the intents of the higher
# priorities that pass near it before it decides, so the order of arrival does not matter
# -- once it has heard them. At cycle 0 nobody has: each UAV decides on whatever intents
# have arrived, in the order the processes happen to run (under load UAV 3 once planned
# around UAV 2's reference before UAV 1 had pushed UAV 2 up, and the flight cost 4350
# m^2 where sim's costs 3240: 1 run in 10 with two busy cores, at speed 4 and at speed 2
# alike). So the paper's flight gets a lead-in: every UAV starts 18 s further back along
# its route, the first conflict enters the 24 s horizon at cycle 2, after every UAV has
# heard the others, and the 48 cycles (2N, what summary judges) fly the paper's 30.
section_decoupled() {
speed=$speed_exact
fly decoupled "$tmp/paper_lead_in.json" decoupled 48 -
check decoupled "
rc == {'world': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'summary': 0}
'COAVOID_PLAN' not in log['counts'] and '65001' not in log['statuses']
all(num(f'vehicle-{i}', 'plans run') >= 1 for i in (1, 2, 3))
all(num(f'vehicle-{i}', 'fallbacks') == 0 for i in (1, 2, 3))
log['intents'] == {str(i): 49 for i in (1, 2, 3)}
all(set(log['statuses'][str(i)]) == {1} for i in (1, 2, 3))
s is not None and s['loss_of_separation'] is False and s['steps'] == 48
s['replans'] == sum(num(f'vehicle-{i}', 'plans run') for i in (1, 2, 3))
(lambda m: (s['deviation'], s['effort'], s['replans']) == (m['deviation'], m['effort'], m['replans']))(json.load(open(os.path.join(d, 'sim.json'))))
[v['flown'] for v in s['vehicles']] == [v['flown'] for v in json.load(open(os.path.join(d, 'sim.json')))['vehicles']]
"
}

# ---- d) an attacker on the group (tests/forge/forge.c, lcm-logplayer) ----

# Each flight of the paper's encounter ends with no loss of separation and the forgery
# reported in the heartbeats of the nodes it reached (their refusals, with the last
# refusal's code). Four attackers, one flight each, both modes:
#   stolen      the attacker holds vehicle 3's secret key and trust file (a stolen vehicle:
#               the fleet key with it) and signs and tags with them: an empty map with the world's id and the largest version (unsigned, it
#               would erase the terrain and lock the real map out as older); a plan for
#               UAV 1 from the coordinator's id flying it to UAV 2's altitude (centralised
#               only: decoupled vehicles take no plans); UAV 2's intents 300 m higher. All
#               refused: that key may not send them (-123), or, for an intent stamped
#               before vehicle 3's own last one under the same key, from its tail as not
#               newer (-124);
#   copy        UAV 2's real intents again with sequences 1000 higher: the fleet tag fails
#               (-126), before any signature check;
#   replay      every message heard sent again 1.5 s later: not newer than the last from
#               its key (-124);
#   replay-log  the log of flight (a), an earlier run with the same keys, played back with
#               lcm-logplayer.
# (test_node covers each refusal alone, unsigned messages included; a plan of the
# coordinator's own that flies a UAV into another is refused as such there too.)
# (the attacker: argument 3)
have_forge() {
    if [ -z "$forge" ] || [ ! -x "$forge" ]; then
        fail "no attacker program (argument 3: coavoid_test_forge): the attacks are not flown"
        return 1
    fi
}
survived="s is not None and s['loss_of_separation'] is False
rc['summary'] == 0 and rc['forge'] == 0"
forged="num('forge', 'forged') >= 5"
# reported CODE NODES: each node's heartbeats counted refusals, CODE among their codes.
reported() { echo "all(log['rejected'][str(i)] >= 1 and $1 in log['codes'][str(i)] for i in ($2,))"; }

# section_attacks MODE: the four attackers on flights in MODE. The log replayed is that of
# flight (a), centralised, with the same keys: an earlier run of the fleet.
section_attacks() {
    have_forge || return 0
    local mode=$1
    replay_log=$tmp/centralised/log.lcm
    if [ "$mode" = centralised ]; then
        speed=${SPEED:-4} all="1, 2, 3, 65001" stolen=map,collide,intent
    else
        speed=$speed_exact all="1, 2, 3" stolen=map,intent
    fi
    forge_args="--key $keys/vehicle-3.key --trust $keys/trust.txt" attack=$stolen \
        fly "attack-stolen-$mode" "$tmp/paper_lead_in.json" "$mode" 48 -
    for attack in copy replay replay-log; do
        # The log replayed is whole, and of an earlier run: its every stamp before this
        # run's epoch (with a second to spare). Replayed stamps inside the run would be
        # newer than the fleet's own, which the nodes refuse by their clock window, but
        # `coavoid summary`, which has no window (cli.md), would take.
        if [ "$attack" = replay-log ]; then
            landed centralised
            speed=1 sleep_until_cycle "$(($(cat "$tmp/centralised/end") - lead_us))" 1
        fi
        forge_args='' fly "attack-$attack-$mode" "$tmp/paper_lead_in.json" "$mode" 48 -
    done
    attack=
    # Decoupled, the attacked flights are `coavoid sim`'s to the step, as in (c): the
    # attacker changed nothing.
    same=True
    if [ "$mode" = decoupled ]; then
        same="[v['flown'] for v in s['vehicles']] == [v['flown'] for v in json.load(open('$tmp/decoupled/sim.json'))['vehicles']]"
    fi
    check "attack-stolen-$mode" "$survived
$same
$forged
$(reported -123 "$all")
set(log['codes']['1']) <= {0, -123, -124}"
    check "attack-copy-$mode" "$survived
$same
$forged
$(reported -126 "$all")"
    check "attack-replay-$mode" "$survived
$same
$forged
$(reported -124 "$all")"
    check "attack-replay-log-$mode" "$survived
$same
all(log['rejected'][str(i)] >= 1 for i in ($all,))"
}

# A stolen coordinator key (the dive).
section_dive() {
    have_forge || return 0

    # A stolen coordinator key: with it the attacker signs, for every intent of UAV 1, a
    # plan of that cycle that dives it 4 m a second for the whole horizon, and the plan's
    # COMMIT (forge.c's dive). Signature and role pass; the UAV's floor (the scenario's
    # min_altitude, 85 m: 10 m under its volume's bottom) does not: it refuses every such
    # plan (-102, COAVOID_LCM_ERR_VALUE) and its flown volume stays at or above the floor.
    python3 - "$late" "$tmp/late_floor.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["min_altitude"] = 85
json.dump(s, open(sys.argv[2], "w"))
PY
    speed=${SPEED:-4}
    forge_args="--key $keys/coordinator.key --trust $keys/trust.txt" attack=dive \
        fly attack-dive "$tmp/late_floor.json" centralised 24 -
    attack=
    check attack-dive "$survived
$forged
$(reported -102 1)
min(p[3] for v in s['vehicles'] if v['id'] == 1 for p in v['flown']) - 5 >= 85"
}

# ---- e) a path that drops every datagram over 1,500 bytes ----

# Every message fits one datagram (docs/messages.md, "One datagram"): a message over
# about 1,470 bytes would leave as one large UDP datagram for the kernel to fragment, and
# a path with a 1,500-byte MTU that does not fragment (or loses a fragment) drops it. The
# namespace's own rule does that to everything its processes receive (the senders do not
# notice, as on such a path): the paper's flight, centralised and decoupled, must be the
# flight of `coavoid sim`, with and without the rule, every plan whole and the map in use
# everywhere (no REASON_NO_MAP, 64, in the last heartbeats).
section_paths() {
if [ -z "$netns" ]; then
    echo "note: no private network namespace: the case of a path that drops large datagrams is not flown"
elif ! command -v nft >/dev/null; then
    fail "no nft (install nftables): the case of a path that drops large datagrams is not flown"
else
    speed=$speed_exact
    "$bin" sim "$tmp/paper_lead_in.json" --mode centralised --steps 48 --json >"$tmp/sim-centralised.json"
    same_as_sim="rc == {'world': 0, 'coordinator': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'summary': 0}
all(num(p, 'rejected') == 0 for p in ('coordinator', 'vehicle-1', 'vehicle-2', 'vehicle-3'))
all(num(f'vehicle-{i}', 'fallbacks') == 0 for i in (1, 2, 3))
log['intents'] == {str(i): 49 for i in (1, 2, 3)}
sum(p['status'] == 0 for p in log['plans']) >= 1
all(sorted(p['rows']) == sorted(p['ids']) for p in log['plans'])
all(log['reasons'][str(i)] & 64 == 0 for i in (1, 2, 3, 65001))
log['largest'] <= 1400
s is not None and s['loss_of_separation'] is False and s['steps'] == 48
(lambda m: (s['deviation'], s['effort'], s['replans']) == (m['deviation'], m['effort'], m['replans']))(json.load(open('$tmp/sim-centralised.json')))
[v['flown'] for v in s['vehicles']] == [v['flown'] for v in json.load(open('$tmp/sim-centralised.json'))['vehicles']]"
    fly lossless "$tmp/paper_lead_in.json" centralised 48 -
    check lossless "$same_as_sim"
    # The rule holds for the whole namespace: the fleets flying without it land first.
    land_all
    if ! nft add table inet coavoid_mtu ||
        ! nft add chain inet coavoid_mtu in '{ type filter hook input priority 0; }' ||
        ! nft add rule inet coavoid_mtu in meta length gt 1500 counter drop; then
        fail "cannot install the nftables rule that drops datagrams over 1,500 bytes"
    else
        # The rule does drop: of two datagrams to the group, 2,000 and 1,000 bytes, only the
        # second arrives (and the rule counts the first).
        if python3 - <<'PY' >"$tmp/probe.out" 2>&1; then
import socket, struct, sys
group, port = "239.255.76.67", 7699
rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
rx.bind(("", port))
rx.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
              struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("0.0.0.0")))
rx.settimeout(0.5)
tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
tx.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
for size in (2000, 1000):
    tx.sendto(b"x" * size, (group, port))
got = []
try:
    while True:
        got.append(len(rx.recv(4000)))
except socket.timeout:
    pass
sys.exit(0 if got == [1000] else f"received {got}, expected [1000]")
PY
            pass
        else
            fail "the rule does not drop large datagrams: $(cat "$tmp/probe.out")"
        fi
        # Centralised and decoupled (the flight of (c), `coavoid sim`'s), side by side
        # through the rule. It drops the probe's datagram and none of theirs.
        fly dropping "$tmp/paper_lead_in.json" centralised 48 -
        check dropping "$same_as_sim
int(re.search(r'packets (\\d+)', open(os.path.join(d, '..', 'rule.txt')).read()).group(1)) == 1"
        fly dropping-decoupled "$tmp/paper_lead_in.json" decoupled 48 -
        check dropping-decoupled "rc == {'world': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'summary': 0}
all(num(f'vehicle-{i}', 'rejected') == 0 for i in (1, 2, 3))
log['intents'] == {str(i): 49 for i in (1, 2, 3)}
all(log['reasons'][str(i)] & 64 == 0 for i in (1, 2, 3))
log['largest'] <= 1400
s is not None and s['loss_of_separation'] is False and s['steps'] == 48
[v['flown'] for v in s['vehicles']] == [v['flown'] for v in json.load(open('$tmp/decoupled/sim.json'))['vehicles']]"
        landed dropping
        landed dropping-decoupled
        nft list table inet coavoid_mtu >"$tmp/rule.txt" 2>&1
        nft delete table inet coavoid_mtu
    fi
fi
}

# ---- f) no coordinator at all: the vehicles plan their group jointly ----

# 4-UAV encounter 220 of the Monte Carlo set (tests/encounters/joint_plan_220.json),
# flown by vehicles that follow a coordinator that never speaks: each plans for itself
# once its timeout passes, and no priority order solves the group, so each plans the
# group jointly from the same intents, finds the same plan and flies its row
# (docs/protocol.md, "Priority negotiation", step 5): separation kept, as in
# test_protocol's simulation of it. With --joint-members 0 they have only the greedy
# raise, and lose it: the option reaches the node.
section_leaderless() {
keys220=$tmp/keys220
mkdir -p "$keys220"
joint=$src/tests/encounters/joint_plan_220.json
if ! "$bin" keygen "$joint" --dir "$keys220" >"$tmp/keygen220.out" 2>&1; then
    fail "coavoid keygen (220): $(cat "$tmp/keygen220.out")"
fi
speed=${SPEED:-4}
keys=$keys220 fly leaderless "$joint" leaderless 24 -
check leaderless "
rc == {'world': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'vehicle-4': 0, 'summary': 0}
all(num(f'vehicle-{i}', 'rejected') == 0 for i in (1, 2, 3, 4))
log['plans'] == [] and 'COAVOID_PLAN' not in log['counts']
all(num(f'vehicle-{i}', 'joint plans') >= 1 for i in (1, 2, 3, 4))
s is not None and s['loss_of_separation'] is False and s['steps'] == 24"
keys=$keys220 vehicle_args="--joint-members 0" fly leaderless-alone "$joint" leaderless 24 -
check leaderless-alone "
rc == {'world': 0, 'vehicle-1': 0, 'vehicle-2': 0, 'vehicle-3': 0, 'vehicle-4': 0, 'summary': 1}
all(num(f'vehicle-{i}', 'joint plans') == 0 for i in (1, 2, 3, 4))
s is not None and s['loss_of_separation'] is True"
}

# ---- the parts: each a ctest of its own, so that they fly side by side ----
# PART (argument 4; default all): centralised (the bad inputs, a, b, the centralised
# attacks and the dive), decoupled (a, whose log the attacks replay, c and the decoupled
# attacks) or paths (f, and e: its flight without the rule beside f's, its flights
# through the rule once those have landed). Within a part the fleets fly side by side
# (fly), and every check is judged once all have landed (settle).
case $part in
all)
    section_bad_inputs
    section_centralised
    section_stopped
    section_decoupled
    section_attacks centralised
    section_attacks decoupled
    section_dive
    section_leaderless
    section_paths
    ;;
centralised)
    section_bad_inputs
    section_centralised
    section_stopped
    section_attacks centralised
    section_dive
    ;;
decoupled)
    section_centralised
    section_decoupled
    section_attacks decoupled
    ;;
paths)
    section_leaderless
    section_paths
    ;;
*)
    fail "unknown part '$part' (all, centralised, decoupled or paths)"
    ;;
esac
settle
finish
