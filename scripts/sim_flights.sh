#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Flies every scenario given with `coavoid sim` in six ways (centralised, decoupled, the
# coordinator stopped before cycle 2 and after 2 messages of cycle 3, 30% loss in both
# modes) and writes each JSON result and exit status to OUT_DIR/NAME.WAY. Two builds'
# directories compared with `diff -r` show whether a change to the nodes altered any
# flight (docs/protocol.md, "The protocol library"):
#   coavoid montecarlo --vehicles 2,3,4,5 --count 100 --seed 1 --save ENC --quiet
#   scripts/sim_flights.sh OLD/coavoid A scenarios/*.json ENC/*.json
#   scripts/sim_flights.sh NEW/coavoid B scenarios/*.json ENC/*.json
#   diff -r A B
# Usage: sim_flights.sh COAVOID OUT_DIR SCENARIO.json... (JOBS=n for n at once; default
# the number of CPUs).
set -euo pipefail
bin=${1:?usage: sim_flights.sh COAVOID OUT_DIR SCENARIO.json...}
out=${2:?usage: sim_flights.sh COAVOID OUT_DIR SCENARIO.json...}
shift 2
[ $# -gt 0 ] || { echo "sim_flights: no scenario given" >&2; exit 2; }
[ -x "$bin" ] || { echo "sim_flights: $bin is not an executable" >&2; exit 2; }
mkdir -p "$out"

fly() { # BIN OUT SCENARIO
  local name way args
  name=$(basename "$3" .json)
  while IFS='|' read -r way args; do
    # shellcheck disable=SC2086 # args are words on purpose
    set +e
    "$1" sim "$3" --json $args >"$2/$name.$way" 2>&1
    echo "exit $?" >>"$2/$name.$way"
    set -e
  done <<'WAYS'
centralised|--mode centralised
decoupled|--mode decoupled
stop2|--mode centralised --coordinator-stops 2
stop3-2|--mode centralised --coordinator-stops 3:2
loss-c|--mode centralised --loss 0.3 --net-seed 7
loss-d|--mode decoupled --loss 0.3 --net-seed 7
WAYS
}
export -f fly
printf '%s\0' "$@" | xargs -0 -n 1 -P "${JOBS:-$(nproc)}" bash -c 'fly "$0" "$1" "$2"' "$bin" "$out"
echo "sim_flights: $(find "$out" -type f | wc -l) flights in $out"
