#!/bin/sh
# loop-profile.sh: the emitted evaluation alone in its two forms, straight-line
# (MBCC_LOOP_MIN=1000000000) and the loop form (MBCC_LOOP_MIN=0), on pendulum
# chains of a few lengths (scripts/chain.sh; a chain of N links has a group of
# N rigid bodies and one of N - 1 joints): the C compile time of the whole
# generated model (cc -O2 -c of each of its files, user + system CPU; the
# LDL^T is the same in both forms), cachegrind's instructions per evaluation
# ((1200 calls - 200 calls) / 1000) and the median and fastest per-call times
# of 31 rounds (bench/loops/eval_harness.c), the forms' harnesses run in turn.
# Prints a Markdown table.  Not part of make test.
# Environment: MBCC (build/mbcc), CC (cc), LOOP_PROFILE_LINKS ("4 8 16 32 64"),
# LOOP_PROFILE_DIR (build/loop-profile), LOOP_PROFILE_CACHEGRIND (1).
set -eu
export LC_ALL=C
cd "$(dirname "$0")/.."
ROOT=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC=$ROOT/$MBCC ;; esac
RTLIB=$(dirname "$MBCC")/libmbrt.a
CC=${CC:-cc}
LINKS=${LOOP_PROFILE_LINKS:-"4 8 16 32 64"}
W=${LOOP_PROFILE_DIR:-$ROOT/build/loop-profile}
CG=${LOOP_PROFILE_CACHEGRIND:-1}
die() { echo "loop-profile: error: $*" >&2; exit 1; }
[ -x "$MBCC" ] || die "$MBCC not found: run 'make all' first"
if [ "$CG" = 1 ] && ! command -v valgrind >/dev/null; then echo "loop-profile: no valgrind: no instruction counts" >&2; CG=0; fi
rm -rf "$W"
mkdir -p "$W"

minimum() { case $1 in straight) echo 1000000000 ;; *) echo 0 ;; esac; }

# build DIR MODEL FORM: the model in that form, its C compile time, the harness
build() {
  d=$1
  mkdir -p "$d"
  MBCC_LOOP_MIN=$(minimum "$3") "$MBCC" compile "$2" -o "$d/g" --quiet >"$d/compile.log" 2>&1 ||
    { cat "$d/compile.log" >&2; die "mbcc compile $2 failed"; }
  nm=$(basename "$2" .yaml)
  printf '#include "%s.h"\nconst mb_model *const eval_model = &%s_model;\n' "$nm" "$nm" >"$d/eval_model.c"
  : >"$d/cctime"
  objs=""
  for c in "$d"/g/*.c; do
    case $c in */main.c) continue ;; esac
    o=$d/$(basename "$c" .c).o
    /usr/bin/time -f "%U %S" -a -o "$d/cctime" "$CC" -std=c11 -O2 -Iruntime/core -Iruntime/hosted -I"$d/g" \
      -c "$c" -o "$o" || die "cc failed on $c"
    objs="$objs $o"
  done
  awk '{ t += $1 + $2 } END { printf "%.1f\n", t }' "$d/cctime" >"$d/cctime.sum" && mv "$d/cctime.sum" "$d/cctime"
  # shellcheck disable=SC2086
  "$CC" -std=c11 -O2 -Iruntime/core -Iruntime/hosted -I"$d/g" bench/loops/eval_harness.c \
    $objs "$d/eval_model.c" "$RTLIB" -lm -o "$d/harness" || die "building the harness of $d failed"
}

instructions() {
  for c in 200 1200; do
    valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$1/cg.$c" "$1/harness" calls $c >/dev/null 2>&1 ||
      die "cachegrind failed on $1"
  done
  a=$(awk '/^summary:/ { print $2 }' "$1/cg.200")
  b=$(awk '/^summary:/ { print $2 }' "$1/cg.1200")
  echo "$a $b" | awk '{ printf "%.0f\n", ($2 - $1) / 1000 }'
}

echo "| links | form | C compile, CPU [s] | instructions / eval | median [us] | fastest [us] |"
echo "|--:|---|--:|--:|--:|--:|"
for n in $LINKS; do
  bash scripts/chain.sh "$n" >"$W/chain$n.yaml"
  for form in straight loop; do build "$W/$n-$form" "$W/chain$n.yaml" "$form"; done
  # the two forms' timings in turn, so that the machine's load falls on both
  for form in straight loop; do "$W/$n-$form/harness" time >"$W/$n-$form/time"; done
  for form in loop straight; do "$W/$n-$form/harness" time >>"$W/$n-$form/time"; done
  for form in straight loop; do
    d=$W/$n-$form
    ir=-
    [ "$CG" = 1 ] && ir=$(instructions "$d")
    med=$(awk '{ print $1 }' "$d/time" | sort -n | head -1)
    fast=$(awk '{ print $2 }' "$d/time" | sort -n | head -1)
    echo "| $n | $form | $(cat "$d/cctime") | $ir | $med | $fast |"
  done
done
