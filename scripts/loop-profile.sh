#!/bin/sh
# loop-profile.sh: the emitted evaluation alone in its two forms, straight-line
# (MBCC_LOOP_MIN=1000000000) and the loop form (MBCC_LOOP_MIN=0), on pendulum
# chains of a few lengths (scripts/chain.sh; a chain of N links has a group of
# N rigid bodies and one of N - 1 joints).  For each: the C compile time of the
# whole generated model (one cc -O2 -c of all its files, user + system CPU;
# the LDL^T is the same in both forms), cachegrind's instructions per
# evaluation ((1200 - 200 calls) / 1000) and the median and fastest per-call
# times of 31 rounds (bench/ldl/ldl_harness.c evaltime; the two forms'
# harnesses run in turn, twice, the lower of each kept).  Prints a Markdown
# table.  Not part of make test.
# Environment: MBCC (build/mbcc), CC (cc), LOOP_PROFILE_LINKS ("8 16 24 32 64"),
# LOOP_PROFILE_DIR (build/loop-profile).
TOOL=loop-profile
. "$(dirname "$0")/lib.sh"
need_mbcc
here=$ROOT
mbcc=$MBCC
out=${LOOP_PROFILE_DIR:-$here/build/loop-profile}
cc=${CC:-cc}
command -v valgrind >/dev/null || die "valgrind is needed (instruction counts)"
fresh_dir "$out"
flags="-std=c11 -O2 -I$here/runtime/core -I$here/runtime/hosted"
# the portable runtime: valgrind (3.19) decodes no AVX-512, which the native one may hold
libs="$(dirname "$mbcc")/libmbrt_portable.a -lamd -lklu -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm"

# form_dir LINKS FORM: the model compiled in that form with its harness; the
# C compile's CPU seconds in DIR/cpu
form_dir() {
  dir=$out/$1-$2 && mkdir -p "$dir/o" && cd "$dir"
  lim=0 && [ "$2" = straight ] && lim=1000000000
  MBCC_LOOP_MIN=$lim "$mbcc" compile "$out/chain$1.yaml" -o g --quiet >log 2>&1 || { cat log >&2; exit 1; }
  printf '#include "chain%s.h"\nconst mb_model *const ldl_model = &chain%s_model;\n' "$1" "$1" >model.c
  # shellcheck disable=SC2086
  (cd o && /usr/bin/time -f "%U %S" -o ../cpu.txt "$cc" $flags -I../g -c $(ls ../g/*.c | grep -v '/main\.c$'))
  awk '{ printf "%.1f\n", $1 + $2 }' cpu.txt >cpu
  # shellcheck disable=SC2086
  "$cc" $flags -I/usr/include/suitesparse -Ig "$here/bench/ldl/ldl_harness.c" o/*.o model.c $libs -o harness
  cd "$here"
}

# ir DIR: instructions per evaluation
ir() {
  for k in 200 1200; do
    valgrind --tool=cachegrind --cache-sim=no --cachegrind-out-file="$1/cg$k" "$1/harness" eval $k >/dev/null 2>&1
  done
  echo "$(sed -n 's/^summary: *//p' "$1/cg200") $(sed -n 's/^summary: *//p' "$1/cg1200")" |
    awk '{ printf "%.0f\n", ($2 - $1) / 1000 }'
}

echo "| links | form | C compile, CPU [s] | instructions / eval | median [us] | fastest [us] |"
echo "|--:|---|--:|--:|--:|--:|"
for n in ${LOOP_PROFILE_LINKS:-8 16 24 32 64}; do
  bash scripts/chain.sh "$n" >"$out/chain$n.yaml"
  form_dir "$n" straight
  form_dir "$n" loop
  for round in 1 2; do
    for f in straight loop; do "$out/$n-$f/harness" evaltime >>"$out/$n-$f/times"; done
  done
  for f in straight loop; do
    d=$out/$n-$f
    printf '| %s | %s | %s | %s | %s | %s |\n' "$n" "$f" "$(cat "$d/cpu")" "$(ir "$d")" \
      "$(awk '{ print $1 }' "$d/times" | sort -g | head -1)" "$(awk '{ print $2 }' "$d/times" | sort -g | head -1)"
  done
done
