#!/bin/sh
# ldl-profile.sh: the emitted LDL^T's factor + solve alone, in each code form,
# on a few models (bench/ldl/ldl_harness.c): for every model and form
# (straight-line: MBCC_LDL_BUDGET=1e12; looped: MBCC_LDL_BUDGET=0; default:
# the compiler's choice) the C compile time of the generated model (cc $GEN_CFLAGS,
# user + system CPU), cachegrind's instructions and I1 misses per call
# ((1200 calls - 200 calls) / 1000, simulated 32 kB 8-way I1), and the
# median and fastest per-call times of 31 rounds, the forms' harnesses run in
# turn (interleaved) LDL_PROFILE_ROUNDS times (median of their medians); then
# the ordering's nnz(L) and flops beside SuiteSparse AMD without constraint
# sets on the same pattern.  Prints a Markdown table.  Not part of make test.
# Environment: MBCC (build/mbcc), CC (cc), LDL_PROFILE_MODELS ("MODEL.yaml[:SCENE] ..."),
# LDL_PROFILE_FORMS ("straight looped"), LDL_PROFILE_ROUNDS (3), LDL_PROFILE_DIR
# (build/ldl-profile), LDL_PROFILE_CACHEGRIND (1), GEN_CFLAGS (-O2; make ldl-profile:
# the Makefile's CFLAGS less -g, as mbcc builds generated code).
TOOL=ldl-profile
. "$(dirname "$0")/lib.sh"
# valgrind 3.19 decodes no AVX-512: the harness (timed and counted) is built
# without it and on the portable runtime
RTLIB=$(dirname "$MBCC")/libmbrt_portable.a
CC=${CC:-cc}
# the flags mbcc builds generated code with (make passes them)
GEN_FLAGS="${GEN_CFLAGS:--O2} -ffp-contract=off"
case " $GEN_FLAGS " in *" -march=native "*) GEN_FLAGS="$GEN_FLAGS -mno-avx512f" ;; esac
MODELS=${LDL_PROFILE_MODELS:-"models/sports_car.yaml:rigid models/sports_car.yaml:flexible models/sports_car.yaml:flexible_virtual models/slider_crank.yaml tests/models/hinged_chain20_rigid.yaml"}
FORMS=${LDL_PROFILE_FORMS:-"straight looped"}
ROUNDS=${LDL_PROFILE_ROUNDS:-3}
W=${LDL_PROFILE_DIR:-$ROOT/build/ldl-profile}
CG=${LDL_PROFILE_CACHEGRIND:-1}
need_mbcc
if [ "$CG" = 1 ] && ! command -v valgrind >/dev/null; then echo "ldl-profile: no valgrind: no instruction counts" >&2; CG=0; fi
fresh_dir "$W"
LIBS="-lamd -lklu -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm"

budget() { case $1 in straight) echo 1e12 ;; looped) echo 0 ;; *) echo "" ;; esac; }

# build DIR MODEL SCENE FORM: compile the model in that form, its C compile time, the harness
build() {
  d=$1
  mkdir -p "$d"
  set -- "$2" "$3" "$4"
  sc=""
  [ -z "$2" ] || sc="--scene $2"
  # shellcheck disable=SC2086
  MBCC_LDL_BUDGET=$(budget "$3") "$MBCC" compile "$1" $sc -o "$d/g" --quiet >"$d/compile.log" 2>&1 ||
    { cat "$d/compile.log" >&2; die "mbcc compile $1 $sc failed"; }
  nm=""
  for h in "$d"/g/*.h; do
    case $h in */main.h) ;; *) nm=$(basename "$h" .h) ;; esac
  done
  printf '#include "%s.h"\nconst mb_model *const ldl_model = &%s_model;\n' "$nm" "$nm" >"$d/ldl_model.c"
  # every C file of the model (a large one is written as several: NAME.sources), CPU summed
  : >"$d/cctime"
  objs=""
  for c in "$d"/g/*.c; do
    case $c in */main.c) continue ;; esac
    o=$d/$(basename "$c" .c).o
    /usr/bin/time -f "%U %S" -a -o "$d/cctime" "$CC" -std=c11 $GEN_FLAGS -Iruntime/core -Iruntime/hosted -I"$d/g" \
      -c "$c" -o "$o" || die "cc failed on $c"
    objs="$objs $o"
  done
  awk '{ u += $1; s += $2 } END { print u, s }' "$d/cctime" >"$d/cctime.sum" && mv "$d/cctime.sum" "$d/cctime"
  # shellcheck disable=SC2086
  "$CC" -std=c11 $GEN_FLAGS -Iruntime/core -Iruntime/hosted -I/usr/include/suitesparse -I"$d/g" bench/ldl/ldl_harness.c \
    $objs "$d/ldl_model.c" "$RTLIB" $LIBS -o "$d/harness" || die "building the harness of $d failed"
  grep -q 'define [A-Z_0-9]*_LDL_STRAIGHT 1' "$d"/g/"$nm".h && echo straight-line >"$d/form" || echo looped >"$d/form"
}

cachegrind() {
  for c in 200 1200; do
    valgrind --tool=cachegrind --cache-sim=yes --I1=32768,8,64 --D1=32768,8,64 --LL=1048576,16,64 \
      --cachegrind-out-file="$1/cg.$c" "$1/harness" ldl $c >/dev/null 2>&1 || die "cachegrind failed on $1"
  done
  a=$(awk '/^events:/ { for (i = 2; i <= NF; i++) e[$i] = i } /^summary:/ { print $e["Ir"], $e["I1mr"] }' "$1/cg.200")
  b=$(awk '/^events:/ { for (i = 2; i <= NF; i++) e[$i] = i } /^summary:/ { print $e["Ir"], $e["I1mr"] }' "$1/cg.1200")
  echo "$a $b" | awk '{ printf "%.0f %.0f\n", ($3 - $1) / 1000, ($4 - $2) / 1000 }'
}

median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

echo "| model | form | flops (factor + solve) | C compile, CPU [s] | instructions / call | I1 misses / call | median [µs] | fastest [µs] |"
echo "|---|---|--:|--:|--:|--:|--:|--:|"
for spec in $MODELS; do
  model=${spec%%:*}
  scene=""
  case $spec in *:*) scene=${spec#*:} ;; esac
  tag=$(basename "$model" .yaml)${scene:+_$scene}
  for form in $FORMS; do build "$W/$tag.$form" "$model" "$scene" "$form"; done
  # interleaved timing: the forms in turn, ROUNDS times
  r=0
  while [ "$r" -lt "$ROUNDS" ]; do
    for form in $FORMS; do "$W/$tag.$form/harness" time >>"$W/$tag.$form/times"; done
    r=$((r + 1))
  done
  for form in $FORMS; do
    d=$W/$tag.$form
    cgi="-"; cgm="-"
    if [ "$CG" = 1 ]; then read -r cgi cgm <<EOT
$(cachegrind "$d")
EOT
    fi
    fl=$(awk '/_LDL_FLOPS/ { print $3 }' "$d"/g/*.h | head -1)
    fs=$(grep -ho '[0-9]* per solve' "$d"/g/*.c | head -1 | awk '{ print $1 }')
    printf '| %s | %s | %s + %s | %s | %s | %s | %s | %s |\n' "$tag" "$(cat "$d/form")" "${fl%.0}" "$fs" \
      "$(awk '{ printf "%.1f", $1 + $2 }' "$d/cctime")" "$cgi" "$cgm" \
      "$(awk '{ print $1 }' "$d/times" | median)" "$(awk '{ print $2 }' "$d/times" | sort -n | head -1)"
  done
done
echo
echo "Orderings (nnz(L) and flops of the factorization):"
echo
for spec in $MODELS; do
  model=${spec%%:*}
  scene=""
  case $spec in *:*) scene=${spec#*:} ;; esac
  tag=$(basename "$model" .yaml)${scene:+_$scene}
  first=${FORMS%% *}
  echo "- $("$W/$tag.$first/harness" amd)"
done
echo
echo "load average: $(load_average)"
