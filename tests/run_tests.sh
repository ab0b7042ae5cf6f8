#!/usr/bin/env bash
# run_tests.sh: builds and runs every test; ends with "N passed, N failed".
#   tests/test_*.c   cmocka programs.  A line "// models: a b" names the models
#                    (models/a.yaml or tests/models/a.yaml) whose generated code
#                    the test links (all its C files); each is compiled by mbcc
#                    into $B/gen/<model>/.
#   tests/test_*.sh  shell tests: exit 0 passes (counted as one test).
# Environment: B (build dir, default build), CFLAGS (e.g. sanitizers).
set -u
cd "$(dirname "$0")/.."
B=${B:-build}
CFLAGS=${CFLAGS:--O2 -g}
CC=${CC:-cc}
LIBS="-lcholmod -larpack -lcmocka -lsundials_ida -lsundials_nvecserial -lsundials_sunlinsolklu -lsundials_sunmatrixsparse -lyaml -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm"
mkdir -p "$B/gen" "$B/tests"
export MBCC="$B/mbcc" B
passed=0; failed=0

model_path() {
  if [ -f "models/$1.yaml" ]; then echo "models/$1.yaml"; else echo "tests/models/$1.yaml"; fi
}

declare -A compiled
# "model" or "model@scene", optionally with "+looped" (the emitted LDL^T as
# loops over tables whatever its size: MBCC_LDL_BUDGET=0), "+loops" (the
# evaluation in the loop form whatever its groups' sizes: MBCC_LOOP_MIN=0) or
# "+tail" (the straight-line LDL^T with a dense tail of 12 rows: MBCC_LDL_TAIL=12);
# the generated code is named model or model_scene, in
# $B/gen/<that name>[_looped|_loops]
gen_name() { local m=${1%+looped}; m=${m%+loops}; m=${m%+tail}; if [[ $m == *@* ]]; then echo "${m%@*}_${m#*@}"; else echo "$m"; fi; }
gen_dir() {
  if [[ $1 == *+looped ]]; then echo "$B/gen/$(gen_name "$1")_looped"
  elif [[ $1 == *+loops ]]; then echo "$B/gen/$(gen_name "$1")_loops"
  elif [[ $1 == *+tail ]]; then echo "$B/gen/$(gen_name "$1")_tail"
  else echo "$B/gen/$(gen_name "$1")"; fi
}
compile_model() {
  local m=${1%+looped} base d budget=()
  m=${m%+loops}
  m=${m%+tail}
  base=${m%@*}
  d=$(gen_dir "$1")
  [ -n "${compiled[$d]:-}" ] && return 0
  local scene=()
  [[ $m == *@* ]] && scene=(--scene "${m#*@}")
  [[ $1 == *+looped ]] && budget=(env MBCC_LDL_BUDGET=0)
  [[ $1 == *+loops ]] && budget=(env MBCC_LOOP_MIN=0)
  [[ $1 == *+tail ]] && budget=(env MBCC_LDL_TAIL=12)
  "${budget[@]}" "$B/mbcc" compile "$(model_path "$base")" "${scene[@]}" -o "$d" >/dev/null || return 1
  compiled[$d]=1
}

for t in tests/test_*.c; do
  name=$(basename "$t" .c)
  [[ -n ${ONLY:-} && $name != $ONLY ]] && continue # ONLY=test_ldl: one test (or a glob)
  models=$(sed -n 's|^// models: *||p' "$t" | head -1)
  srcs=(); incs=()
  ok=1
  for m in $models; do
    if ! compile_model "$m"; then echo "FAIL $name: mbcc could not compile model $m"; ok=0; fi
    g=$(gen_name "$m"); d=$(gen_dir "$m")
    # a large model is several C files, listed in <name>.sources (docs/pipeline.md)
    if [ -f "$d/$g.sources" ]; then
      while read -r f; do srcs+=("$d/$f"); done < "$d/$g.sources"
    else
      srcs+=("$d/$g.c")
    fi
    incs+=("-I$d")
  done
  if [ $ok = 1 ] && ! $CC -std=c11 -Wall -Wextra -Werror $CFLAGS -Iruntime/core -Iruntime/hosted -Icompiler/front -Icompiler/flex -Icompiler/lower -Icompiler/back -Itests "${incs[@]}" \
        "$t" "${srcs[@]}" tests/support.c "$B/libmbrt.a" $LIBS -o "$B/tests/$name" 2> "$B/tests/$name.build.log"; then
    cat "$B/tests/$name.build.log"; echo "FAIL $name: does not build"; ok=0
  fi
  if [ $ok = 0 ]; then failed=$((failed + 1)); continue; fi
  out=$("$B/tests/$name" 2>&1); rc=$?
  echo "$out" | grep -E '^\[ +(OK|FAILED|PASSED|RUN|  ERROR) |^\[  ERROR|error|assert|Failure' | grep -v '^\[ RUN' | sed "s|^|$name: |"
  p=$(echo "$out" | sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' | tail -1)
  f=$(echo "$out" | sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' | tail -1)
  p=${p:-0}; f=${f:-0}
  if [ "$rc" != 0 ] && [ "$f" = 0 ]; then f=1; echo "FAIL $name: exit status $rc"; echo "$out" | tail -20; fi
  passed=$((passed + p)); failed=$((failed + f))
done

for t in tests/test_*.sh; do
  [ -e "$t" ] || continue
  name=$(basename "$t" .sh)
  [[ -n ${ONLY:-} && $name != $ONLY ]] && continue
  if out=$(bash "$t" 2>&1); then
    echo "$name: ok"; passed=$((passed + 1))
  else
    echo "$out" | tail -20 | sed "s|^|$name: |"; echo "FAIL $name"; failed=$((failed + 1))
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
