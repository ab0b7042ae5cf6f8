#!/usr/bin/env bash
# test_peers.sh: make bench's MuJoCo peer is modelled identically (quick; the
# timing itself is only in make bench / make peers).  On the 4-revolute
# four-bar (bench/peers/four_bar_4r.yaml) through scripts/peers.sh, 3 rounds:
#  1. MuJoCo's body velocities equal mbcc's at the mapped state (1e-12);
#  2. every body's acceleration at rest agrees with mbcc's within 1e-3 of the
#     largest (measured 5.6e-5: MuJoCo's constraint softness);
#  3. the check can fail: with the coupler's mass changed by 1 % in the MJCF
#     the peer reports DISAGREE and exits 1.
# Skipped (passes with a note) when MuJoCo (libmujoco-dev) is not installed.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
if [ ! -e /usr/include/mujoco/mujoco.h ]; then
  echo "test_peers: skipped: MuJoCo (libmujoco-dev) is not installed"
  exit 0
fi
P=$tmp/peers
# GEN_CFLAGS: make sanitize's CFLAGS, which its libmbrt.a needs at the link
PEER_DIR=$P PEER_MODELS=bench/peers/four_bar_4r.yaml PEER_ROUNDS=3 PEER_CACHEGRIND=0 MBCC=$MBCC GEN_CFLAGS="${CFLAGS:--O2}" \
  sh "$root/scripts/peers.sh" >peers.out 2>&1 || { cat peers.out; err "scripts/peers.sh failed"; }
T=$P/four_bar_4r.txt
if [ -s "$T" ]; then
  awk '/^state mapping/ { if ($7 + 0 > 1e-12 || $7 !~ /e/) { print "FAIL: velocities differ by " $7; bad = 1 } n++ }
       /^accelerations at rest/ { if ($6 + 0 > 1e-3) { print "FAIL: accelerations at rest differ by " $6; bad = 1 } n++ }
       END { if (n != 2) { print "FAIL: no comparison lines"; bad = 1 } exit bad }' "$T" || fail=1
  grep -E "^(state|accelerations)" "$T"
  # 3. a 1 % heavier coupler must be caught
  sed 's/mass="1.0"/mass="1.01"/' "$P/four_bar_4r.xml" >heavy.xml
  cmp -s heavy.xml "$P/four_bar_4r.xml" && err "the mass edit did not apply"
  "$P/four_bar_4r_peer" heavy.xml --rounds 1 --reps 1 --tol 1e-3 >heavy.txt 2>&1
  rc=$?
  [ "$rc" = 1 ] || { cat heavy.txt; err "a 1 % heavier coupler was not caught (exit $rc)"; }
  grep -q DISAGREE heavy.txt || err "no DISAGREE for the heavier coupler"
else
  err "no output from the four-bar peer"
fi
[ "$fail" = 0 ] && echo "test_peers: ok"
exit "$fail"
