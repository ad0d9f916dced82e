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
trap 'rm -rf "$tmp"' EXIT
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
