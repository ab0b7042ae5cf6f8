#!/usr/bin/env bash
# run_tests.sh: builds and runs every test; ends with "N passed, N failed".
#   tests/test_*.c   cmocka programs.  A line "// models: a b" names the models
#                    (models/a.yaml or tests/models/a.yaml) whose generated code
#                    the test links; each is compiled by mbcc into $B/gen/<model>/.
#   tests/test_*.sh  shell tests: exit 0 passes (counted as one test).
# Environment: B (build dir, default build), CFLAGS (e.g. sanitizers).
set -u
cd "$(dirname "$0")/.."
B=${B:-build}
CFLAGS=${CFLAGS:--O2 -g}
CC=${CC:-cc}
LIBS="-lcmocka -lsundials_ida -lsundials_nvecserial -lyaml -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm"
mkdir -p "$B/gen" "$B/tests"
export MBCC="$B/mbcc" B
passed=0; failed=0

model_path() {
  if [ -f "models/$1.yaml" ]; then echo "models/$1.yaml"; else echo "tests/models/$1.yaml"; fi
}

declare -A compiled
# "model" or "model@scene"; the generated code is named model or model_scene
gen_name() { if [[ $1 == *@* ]]; then echo "${1%@*}_${1#*@}"; else echo "$1"; fi; }
compile_model() {
  local m=$1 base=${1%@*} g
  g=$(gen_name "$m")
  [ -n "${compiled[$g]:-}" ] && return 0
  local scene=()
  [[ $m == *@* ]] && scene=(--scene "${m#*@}")
  "$B/mbcc" compile "$(model_path "$base")" "${scene[@]}" -o "$B/gen/$g" >/dev/null || return 1
  compiled[$g]=1
}

for t in tests/test_*.c; do
  name=$(basename "$t" .c)
  models=$(sed -n 's|^// models: *||p' "$t" | head -1)
  srcs=(); incs=()
  ok=1
  for m in $models; do
    if ! compile_model "$m"; then echo "FAIL $name: mbcc could not compile model $m"; ok=0; fi
    g=$(gen_name "$m")
    srcs+=("$B/gen/$g/$g.c"); incs+=("-I$B/gen/$g")
  done
  if [ $ok = 1 ] && ! $CC -std=c11 -Wall -Wextra -Werror $CFLAGS -Iruntime -Icompiler -Itests "${incs[@]}" \
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
  if out=$(bash "$t" 2>&1); then
    echo "$name: ok"; passed=$((passed + 1))
  else
    echo "$out" | tail -20 | sed "s|^|$name: |"; echo "FAIL $name"; failed=$((failed + 1))
  fi
done
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
