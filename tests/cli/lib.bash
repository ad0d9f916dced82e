# SPDX-License-Identifier: MIT
# Shared set-up of the command-line tests, sourced by tests/cli/*.sh as
#   . "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"
# It is named .bash, not .sh, because tests/CMakeLists.txt runs every tests/cli/*.sh as a
# test of its own.
#
# Sets bin (the coavoid binary, argument 1), src (the source tree, argument 2, may be
# empty), tmp (a scratch directory removed on exit), and the counters behind pass, fail
# and finish.

# shellcheck disable=SC2034  # bin and src are for the scripts that source this
bin=${1:?usage: $(basename "$0") COAVOID SOURCE_DIR}
# shellcheck disable=SC2034
src=${2:-}
tmp=$(mktemp -d)
# KEEP_TMP=1 keeps the scratch directory (its path is printed) to look into a failure.
if [ -n "${KEEP_TMP:-}" ]; then
    echo "scratch: $tmp" >&2
else
    trap 'rm -rf "$tmp"' EXIT
fi
passed=0
failed=0

pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# The summary line; returns non-zero when any check failed (the script's exit status when
# called last).
finish() {
    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}

# expect_status DESCRIPTION STATUS ARGS...: coavoid ARGS exits STATUS with nothing on
# stderr; its stdout is left in $tmp/out. Counts a pass, or a failure and returns 1, so
# `if expect_status ...; then check ...` reads the output only when there is one to read.
expect_status() {
    local what=$1 want=$2
    shift 2
    "$bin" "$@" >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    if [ "$rc" -ne "$want" ]; then
        fail "$what: exit $rc, expected $want (stderr: $(head -c 300 "$tmp/err"))"
        return 1
    elif [ -s "$tmp/err" ]; then
        fail "$what: stderr not empty: $(head -c 300 "$tmp/err")"
        return 1
    fi
    pass
}

# expect_ok DESCRIPTION ARGS...: expect_status with exit 0.
expect_ok() {
    local what=$1
    shift
    expect_status "$what" 0 "$@"
}

# expect_bad DESCRIPTION PATTERN ARGS...: coavoid ARGS exits 2, prints nothing on stdout
# and exactly one stderr line that starts with "coavoid: " and contains PATTERN (and the
# text in $also, when set).
also=
expect_bad() {
    local what=$1 pattern=$2
    shift 2
    "$bin" "$@" >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    local lines
    lines=$(wc -l <"$tmp/err")
    if [ -n "${VERBOSE:-}" ]; then sed "s|$tmp/||" "$tmp/err"; fi
    if [ "$rc" -ne 2 ]; then
        fail "$what: exit $rc, expected 2 (stderr: $(head -c 300 "$tmp/err"))"
    elif [ "$lines" -ne 1 ]; then
        fail "$what: $lines lines on stderr, expected 1: $(head -c 600 "$tmp/err")"
    elif ! grep -q '^coavoid: ' "$tmp/err"; then
        fail "$what: stderr does not start with 'coavoid: ': $(cat "$tmp/err")"
    elif ! grep -qF -- "$pattern" "$tmp/err"; then
        fail "$what: stderr does not name '$pattern': $(cat "$tmp/err")"
    elif [ -n "$also" ] && ! grep -qF -- "$also" "$tmp/err"; then
        fail "$what: stderr does not say '$also': $(cat "$tmp/err")"
    elif [ -s "$tmp/out" ]; then
        fail "$what: stdout is not empty"
    else
        pass
    fi
}

# in_multicast_netns ARGS...: runs the calling script in a private network namespace whose
# loopback carries multicast (lo up with multicast on, 224.0.0.0/4 routed to it), so that
# LCM's UDP multicast works where the host has no multicast route, and the test's traffic
# never meets the host's network or another test's. Call it right after sourcing this
# file, with the script's own arguments: outside a namespace it re-runs the script inside
# one (`unshare --net` as root, `unshare -rn` otherwise: a user namespace) and exits with
# its status; inside, it sets up lo and returns 0. Returns 1 after a message when it cannot
# (no unshare permission, or no ip from iproute2).
in_multicast_netns() {
    if [ -n "${COAVOID_TEST_IN_NETNS:-}" ]; then
        if ! ip link set lo up multicast on || ! ip route add 224.0.0.0/4 dev lo; then
            echo "in_multicast_netns: cannot set up lo for multicast in the namespace"
            return 1
        fi
        return 0
    fi
    if ! command -v ip >/dev/null; then
        echo "in_multicast_netns: no 'ip' command (install iproute2)"
        return 1
    fi
    local how=-rn
    if [ "$(id -u)" -eq 0 ]; then how=--net; fi
    if ! unshare "$how" true 2>/dev/null; then
        echo "in_multicast_netns: 'unshare $how' is not permitted here"
        return 1
    fi
    rm -rf "$tmp"
    exec env COAVOID_TEST_IN_NETNS=1 unshare "$how" bash "$0" "$@"
}

# lead_in SCENARIO OUT SECONDS: SCENARIO with every UAV starting SECONDS further back
# along its route's first leg (at its cruise speed), written to OUT: an encounter whose
# first conflict enters the horizon only after every UAV has heard the others.
lead_in() {
    python3 - "$1" "$2" "$3" <<'PY'
import json, math, sys
s = json.load(open(sys.argv[1]))
for v in s["vehicles"]:
    a, b = v["route"][0], v["route"][1]
    back = v["cruise_speed"] * float(sys.argv[3]) / math.hypot(b[0] - a[0], b[1] - a[1])
    v["route"][0] = [a[j] - (b[j] - a[j]) * back for j in range(3)]
json.dump(s, open(sys.argv[2], "w"))
PY
}
