# shell_setup.sh: sourced by the shell tests (tests/test_*.sh) after
# `cd "$(dirname "$0")/.."`: sets root (the repository), MBCC (absolute),
# tmp (a scratch directory, removed on exit, made the working directory so
# that nothing lands in the source tree), fail=0 and err() (records a
# failure with its message).
root=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC="$root/$MBCC" ;; esac
[ -x "$MBCC" ] || { echo "no mbcc at $MBCC"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
err() { echo "FAIL: $*"; fail=1; }
