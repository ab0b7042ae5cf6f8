# lib.sh: the preamble shared by the measuring scripts (bench.sh, peers.sh,
# ldl-profile.sh, loop-profile.sh, results.sh, trade.sh, vehicle.sh, sweeps.sh, scaling.sh,
# rigid_chassis.sh).  Each sets TOOL (its name in
# messages) and sources this file first:
#   TOOL=bench; . "$(dirname "$0")/lib.sh"
# Then: strict mode, the C locale (awk's numbers), the repository as the
# working directory (ROOT), MBCC absolute (default build/mbcc), and:
#   say MSG / die MSG   "TOOL: MSG" / "TOOL: error: MSG" on stderr (die exits 1)
#   show CMD...         a command line with the repository's path left out (for pages)
#   need_mbcc           dies unless mbcc is built
#   fresh_dir DIR       an empty work directory
#   load_average        the 1, 5 and 15 min load averages (pages note them)
# POSIX sh.
set -eu
export LC_ALL=C
cd "$(dirname "$0")/.."
ROOT=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC=$ROOT/$MBCC ;; esac
say() { echo "$TOOL: $*" >&2; }
die() { echo "$TOOL: error: $*" >&2; exit 1; }
show() { echo "$*" | sed "s|$ROOT/||g"; }
need_mbcc() { [ -x "$MBCC" ] || die "$MBCC not found: run 'make all' first"; }
fresh_dir() { rm -rf "$1" && mkdir -p "$1"; }
load_average() { cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo unknown; }
