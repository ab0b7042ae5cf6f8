#!/usr/bin/env bash
# test_fuzz_regressions.sh: hostile inputs end fast in a result or located
# errors (exit 0 or 2, never a crash, a hang or a sanitizer report):
#   - every file of tests/fuzz_regressions/ (findings of make fuzz);
#   - a 2 MB file of nested brackets (once ~2 hours: libyaml is quadratic in
#     the depth), /dev/zero (once read to 8 GB), a 500-body chain (once 36 s of
#     dense analysis) and a 2000-element beam solved densely (once > 180 s and
#     5.5 GB): each
#     refused within seconds, the limit named in the message.
# Exit 0 = pass.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

check() { # file, expected message ('' for any): exit 0 or 2 within 10 s
  local start=$SECONDS rc
  timeout 10 "$MBCC" check "$1" > out.log 2>&1
  rc=$?
  case $rc in
    0|2) ;;
    124) err "$1: still running after 10 s"; return ;;
    *) err "$1: exit $rc: $(tail -5 out.log)"; return ;;
  esac
  [ -z "$2" ] || grep -q -- "$2" out.log || err "$1: no '$2' in: $(head -3 out.log)"
  [ $((SECONDS - start)) -le 5 ] || err "$1: took $((SECONDS - start)) s"
}
n=0
for f in "$root"/tests/fuzz_regressions/*; do
  [ -f "$f" ] || continue
  case $f in *.keep) continue;; esac
  check "$f" ''; n=$((n + 1))
done
python3 -c "import sys; sys.stdout.write('a: ' + '[' * 1000000 + ']' * 1000000 + '\n')" > brackets.yaml
check brackets.yaml 'nested more than 64 deep'
check /dev/zero 'larger than the limit'
# a results CSV that streams forever: plot and animate refuse it at once
for cmd in plot animate; do
  timeout 10 "$MBCC" $cmd /dev/zero -o zero.out > zero.log 2>&1
  rc=$?
  [ $rc = 2 ] && grep -q "not a regular file" zero.log && [ ! -e zero.out ] ||
    err "mbcc $cmd /dev/zero: exit $rc: $(head -2 zero.log)"
done
awk 'BEGIN { print "name: chain\nbodies:"; for (i = 1; i <= 10001; i++) printf "  b%d: {type: rigid, mass: 1, inertia: [1, 1, 1], position: [%d, 0, 0]}\n", i, i
             print "joints:"; for (i = 1; i <= 10001; i++) printf "  j%d: {type: revolute, bodies: [%s, b%d], point: [%d, 0, 0], axis: [0, 0, 1]}\n", i, i == 1 ? "ground" : "b" i - 1, i, i - 1 }' > chain.yaml
check chain.yaml 'more than the limit 10000'
MBCC_MAX_BODIES=20000 timeout 20 "$MBCC" check chain.yaml > lifted.log 2>&1
rc=$? # 0: the sparse analysis takes seconds; 124: still busy, as asked
[ $rc = 124 ] || [ $rc = 0 ] || err "MBCC_MAX_BODIES=20000 did not lift the limit: $(head -2 lifted.log)"
cat > beam.yaml <<'EOS'
name: beam
bodies:
  rod:
    type: flexible
    line: {from: [0, 0, 0], to: [1, 0, 0], elements: 2000}
    section: {area: 1.0e-4}
    material: {E: 2.0e11, nu: 0.3, density: 7800}
    modes: {count: 4}
    eigensolver: dense
joints:
  clamp: {type: fixed, bodies: [ground, rod], node: 0}
EOS
check beam.yaml 'MBCC_MAX_FE_DOFS'
echo "  $n fuzz regressions replayed; brackets, /dev/zero, 500 bodies, 2000 elements refused"
exit $fail
