#!/usr/bin/env bash
# test_faults.sh: the fault suite (issue 23): an unlucky environment must
# neither destroy nor half-write a file, and exit codes must tell the truth.
#   1. four `mbcc run` of one model at once: all exit 0, one complete CSV,
#      no temporary file left;
#   2. mbcc killed (SIGTERM) while the C compiler runs, while the simulator
#      runs, and while gnuplot draws: mbcc dies of the signal, its children
#      die with it, the previous CSV and PNG are untouched, nothing is left;
#   3. a full disk (a 64 KiB tmpfs in a private mount namespace, or else a
#      file-size limit): exit 2, the previous CSV and PNG untouched;
#   4. a read-only output directory: exit 2, nothing written.
# Exit 0 = pass.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
wheel="$root/tests/trust/wheel.yaml"
pendulum="$root/models/pendulum.yaml"

# the first child of $1 whose command is $2, within 20 s (else empty)
child_of() {
  local i c
  for i in $(seq 200); do
    for c in $(pgrep -P "$1" 2> /dev/null); do
      case $(cat /proc/"$c"/comm 2> /dev/null) in $2) echo "$c"; return;; esac
    done
    sleep 0.1
  done
}
# (NAME.csv.units is a result of its own, the columns' units; NAME_sim.stamp
# the simulator's rebuild stamp)
leftovers() { find . -name '*.XXXXXX' -o -name '*.tmp.*' -o -name '*.csv.*' -o -name '*.png.*' -o -name '*_sim.*' | grep -v '\.log$\|\.csv\.units$\|_sim\.stamp$'; }

# 1. concurrent runs
mkdir c && cd c || exit 1
for i in 1 2 3 4; do "$MBCC" run "$wheel" --plot none --quiet > "run$i.log" 2>&1 & pids[$i]=$!; done
for i in 1 2 3 4; do wait "${pids[$i]}" || err "concurrent run $i: exit $?: $(cat "run$i.log")"; done
rows=$(wc -l < results/wheel.csv)
[ "$rows" = 22 ] || err "concurrent runs: results/wheel.csv has $rows lines, expected 22"
awk -F, 'NR > 1 && NF != 4 { exit 1 }' results/wheel.csv || err "concurrent runs: a broken row"
[ -z "$(leftovers)" ] || err "concurrent runs left: $(leftovers)"
cd "$tmp" || exit 1

# 2. a kill during compile, run and plot: the old results stay
mkdir k && cd k && mkdir results || exit 1
echo "old csv" > results/pendulum.csv
echo "old png" > results/pendulum.png
kill_during() { # what, child command pattern, mbcc arguments...
  local what=$1 pattern=$2; shift 2
  "$MBCC" "$@" > "kill_$what.log" 2>&1 &
  local pid=$! child
  child=$(child_of "$pid" "$pattern")
  if [ -z "$child" ]; then err "kill during $what: no '$pattern' child seen"; kill "$pid"; wait "$pid"; return; fi
  kill -TERM "$pid"
  wait "$pid"; local rc=$?
  [ "$rc" = 143 ] || err "kill during $what: mbcc exit $rc, expected 143 (SIGTERM)"
  sleep 0.2
  kill -0 "$child" 2> /dev/null && { err "kill during $what: its child $child ($pattern) outlived mbcc"; kill -9 "$child"; }
  [ "$(cat results/pendulum.csv)" = "old csv" ] || err "kill during $what: the old CSV was replaced"
  [ "$(cat results/pendulum.png)" = "old png" ] || err "kill during $what: the old PNG was replaced"
  [ -z "$(leftovers)" ] || err "kill during $what left: $(leftovers)"
}
kill_during compile 'cc*' run "$pendulum" --quiet --end 2000
kill_during run 'pendulum_sim*' run "$pendulum" --quiet --end 2000
# a plot of many rows takes gnuplot a while
awk 'BEGIN { print "t,a,b,c"; for (i = 0; i < 400000; i++) print i * 1e-3 "," sin(i) "," cos(i) "," i }' > big.csv
kill_during plot gnuplot plot big.csv -o results/pendulum.png
cd "$tmp" || exit 1

# 3. a full disk
mkdir d && cd d || exit 1
"$MBCC" compile "$wheel" -o gen > compile.log 2>&1 || err "compile for the full disk: $(cat compile.log)"
# CFLAGS: make sanitize's (its libmbrt.a needs the sanitizer runtime at the link)
# shellcheck disable=SC2086
cc_out=$(cd gen && cc -std=c99 ${CFLAGS:-} -I"$root/runtime/core" -I"$root/runtime/hosted" -o wheel_sim wheel.c main.c \
  "$root/${B:-build}/libmbrt.a" -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm 2>&1) ||
  err "cannot build the wheel simulator: $cc_out"
full_disk() { # a command run against a full output directory 'out' holding old.csv and old.png
  cat > full.sh <<EOS
set -u
cd "\$1"
echo "old csv" > out/old.csv; echo "old png" > out/old.png
dd if=/dev/zero of=out/fill bs=1k count=100000 2> /dev/null
"$MBCC" plot "$root/tests/trust/wheel_rows.csv" -o out/old.png > plot.log 2>&1; echo "plot \$?" > rc
gen/wheel_sim -o out/old.csv --quiet > sim.log 2>&1; echo "sim \$?" >> rc
cat out/old.csv out/old.png > old.txt; ls out > ls.txt
EOS
  "$@" bash full.sh "$PWD"
}
mkdir out
if unshare -m true 2> /dev/null; then
  full_disk unshare -m bash -c 'mount -t tmpfs -o size=64k tmpfs "$1/out" && exec "${@:2}"' mount "$PWD"
else
  # no mount namespace here: a file-size limit makes every write fail the same way
  full_disk bash -c 'trap "" XFSZ; ulimit -f 0; exec "$@"' limit
fi
[ "$(cat rc 2> /dev/null | tr '\n' ' ')" = "plot 2 sim 2 " ] || err "full disk: exit codes '$(cat rc 2> /dev/null | tr '\n' ' ')', expected plot 2 sim 2 ($(cat plot.log sim.log))"
[ "$(cat old.txt 2> /dev/null)" = "old csv
old png" ] || err "full disk: the old CSV or PNG changed"
[ "$(grep -v '^fill$' ls.txt | tr '\n' ' ')" = "old.csv old.png " ] || err "full disk left: $(cat ls.txt)"
grep -q 'cannot write\|no complete picture' sim.log plot.log || err "full disk: no error message"

# 4. a read-only output directory (the simulator built above)
mkdir r || exit 1
ro_run() { cat > ro.sh <<EOS
cd "\$1"
gen/wheel_sim -o r/w.csv --quiet > ro.log 2>&1; echo \$? > ro.rc
EOS
"$@" bash ro.sh "$PWD"; }
if [ "$(id -u)" != 0 ]; then
  chmod a-w r && ro_run env
elif unshare -m true 2> /dev/null; then
  ro_run unshare -m bash -c 'mount -t tmpfs -o ro tmpfs "$1/r" && exec "${@:2}"' mount "$PWD"
fi
if [ -e ro.rc ]; then
  [ "$(cat ro.rc)" = 2 ] || err "read-only directory: exit $(cat ro.rc), expected 2: $(cat ro.log)"
  grep -q "cannot write 'r/w.csv'" ro.log || err "read-only directory: message: $(cat ro.log)"
  [ -z "$(ls r)" ] || err "read-only directory: written: $(ls r)"
else
  echo "note: read-only directory not tested (root without mount namespaces)"
fi
exit $fail
