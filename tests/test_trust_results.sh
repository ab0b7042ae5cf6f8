#!/usr/bin/env bash
# test_trust_results.sh: results that must not depend on how they are sampled
# (issue 23, silent wrong results).  Exit 0 = pass.
#   - angle outputs are unwrapped at every accepted step, then scaled: a wheel
#     turning at 100 rad/s sampled every 0.05 s (5 rad between rows) reads
#     100 t, in radians, in degrees (scale 180/pi) and with scale -1;
#   - Dormand-Prince's dense output: the output grid neither caps nor changes
#     the steps, so the pendulum at a loose tolerance gives the same values at
#     the times two output grids share, to round-off (the steps alone decide
#     the error: the grid changing the steps showed as 1.3e-7 here);
#   - finite but absurd time spans (--end 1e308, --output-step 1e-300) are
#     refused with the limit named, exit 2, nothing written;
#   - free text reaching the generated C (a scene name with '*/' and a line
#     break, a file path) stays inside its comment: the code compiles and
#     holds no injected declaration; a scene that would name the code
#     'bench_main' is refused;
#   - a LAPACK argument error (xerbla_) stops the process with exit 1 and a
#     message, not garbage and exit 0.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

# 1. the wheel: angle = 100 t
if "$MBCC" run "$root/tests/trust/wheel.yaml" -o wheel.csv --plot none --quiet > wheel.log 2>&1; then
  awk -F, 'NR > 1 { e = 100 * $1; d = e * 57.29577951308232
             if ((($2 - e) ^ 2) > 1e-12 || (($3 - d) ^ 2) > 1e-8 || (($4 + e) ^ 2) > 1e-12) {
               printf "t = %s: angle %s, degrees %s, minus %s; expected %.12g\n", $1, $2, $3, $4, e; bad = 1 } }
           END { exit bad }' wheel.csv || err "wheel angles are not 100 t"
  [ "$(awk -F, '$1 == 0.5 { print $2 }' wheel.csv)" != "" ] || err "no row at t = 0.5"
else
  err "mbcc run wheel.yaml failed: $(tail -3 wheel.log)"
fi

# 2. two output grids, one solution
for h in 0.01 0.025; do
  "$MBCC" run "$root/models/pendulum.yaml" --rtol 1e-3 --atol 1e-6 --end 1 --output-step $h \
    -o "p$h.csv" --plot none --quiet > "p$h.log" 2>&1 || err "pendulum at output step $h failed: $(tail -3 "p$h.log")"
done
if [ -s p0.01.csv ] && [ -s p0.025.csv ]; then
  awk -F, 'NR == FNR { if (FNR > 1) row[sprintf("%.6f", $1)] = $0; next }
           FNR > 1 { k = sprintf("%.6f", $1); if (!(k in row)) next; n++
             split(row[k], a, ","); for (j = 2; j <= NF; j++) { d = a[j] - $j; if (d < 0) d = -d
               s = ($j < 0 ? -$j : $j) + 1; if (d > 1e-9 * s) { printf "t = %s column %d: %s vs %s\n", $1, j, a[j], $j; bad = 1; next } } }
           END { if (n < 20) { print "only " n " shared rows"; bad = 1 } exit bad }' p0.01.csv p0.025.csv ||
    err "the output grid changed the solution"
fi

# 3. absurd time spans
for args in "--end 1e308" "--end 1e300 --output-step 1e-300" "--end 1e12 --output-step 1e5"; do
  # shellcheck disable=SC2086
  "$MBCC" run "$root/models/pendulum.yaml" $args -o span.csv --plot none --quiet > span.log 2>&1
  rc=$?
  [ $rc = 2 ] || err "'$args': exit $rc, expected 2"
  grep -q 'limit\|at most' span.log || err "'$args': the message names no limit: $(cat span.log)"
  [ -e span.csv ] && err "'$args': a CSV was written"
  ls span.csv.* > /dev/null 2>&1 && err "'$args': a temporary file was left"
done
# 4. free text in the generated code
evil='x */ int injected_by_scene; /*
'
{ cat "$root/tests/trust/wheel.yaml"; printf 'scenes:\n  "x */ int injected_by_scene; /*\\n": {}\n'; } > 'we*ird.yaml'
if "$MBCC" compile 'we*ird.yaml' --scene "$evil" -o gen > gen.log 2>&1; then
  c=$(ls gen/wheel_*.c | grep -v main.c)
  cc -std=c99 -Wall -Werror -c -I"$root/runtime/core" "$c" -o evil.o 2> cc.log || err "the scene's code does not compile: $(head -5 cc.log)"
  nm evil.o 2> /dev/null | grep -qw injected_by_scene && err "the scene name injected a symbol"
else
  err "compile with an odd scene name: $(cat gen.log)"
fi
{ sed 's/^name: wheel/name: bench/' "$root/tests/trust/wheel.yaml"; printf 'scenes:\n  main: {}\n'; } > bench.yaml
"$MBCC" check bench.yaml --scene main > bench.log 2>&1
[ $? = 2 ] && grep -q "bench.yaml:[0-9]*:[0-9]*: error: scene 'main' would name the code 'bench_main'" bench.log ||
  err "scene naming the code bench_main: $(cat bench.log)"

# 5. LAPACK's argument errors
cat > xerbla.c <<'EOS'
#include <stdio.h>
void dgesv_(const int *n, const int *nrhs, double *a, const int *lda, int *ipiv, double *b,
            const int *ldb, int *info);
int main(void) {
  int n = -1, one = 1, ipiv[1], info = 0;
  double a[1] = {1}, b[1] = {1};
  dgesv_(&n, &one, a, &one, ipiv, b, &one, &info);
  printf("returned with info %d\n", info);
  return 0;
}
EOS
# CFLAGS: make sanitize's (its libmbrt.a needs the sanitizer runtime at the link)
# shellcheck disable=SC2086
if cc ${CFLAGS:-} -I"$root/runtime/core" -I"$root/runtime/hosted" xerbla.c -Wl,--undefined=xerbla_ "$root/${B:-build}/libmbrt.a" \
     -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm -o xerbla 2> cc.log; then
  ./xerbla > xerbla.log 2>&1
  rc=$?
  [ $rc = 1 ] || err "LAPACK argument error: exit $rc, expected 1: $(cat xerbla.log)"
  grep -q "error: LAPACK routine DGESV got an illegal value in argument 1" xerbla.log || err "xerbla_ message: $(cat xerbla.log)"
else
  err "cannot build the xerbla_ check: $(cat cc.log)"
fi
exit $fail
