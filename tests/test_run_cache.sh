#!/usr/bin/env bash
# test_run_cache.sh: `mbcc run` reuses the compiled simulator when the
# generated code, the compiler, its flags and the runtime are unchanged, and
# checks its options before compiling anything:
#   - a first run compiles; a second with another --end and --rtol does not
#     (no "compiling", the executable untouched) and runs to the new end; its
#     results are right: the small pendulum's bob crosses x = 0 at a quarter
#     period, T/4 = (pi/2) sqrt(L_eq/g) (1 + theta0^2/16), to 1e-3, energy
#     conserved to 1e-8, and it agrees with the first run to 1e-6;
#   - a bad option is refused (exit 2) before anything is compiled;
#   - an edited model (g = 9.81 -> 4) recompiles, and its quarter period
#     follows the new g.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
cp "$root/tests/models/pendulum_small.yaml" p.yaml
exe=generated/pendulum_small/pendulum_small_sim

# quarter_period CSV G: the first time bob_position.x (column 3) reaches 0,
# interpolated, against the closed form for gravity G
quarter_period() {
  awk -F, -v g="$2" 'NR > 2 && !done && $3 <= 0 && px > 0 {
      t = pt + (t1 = $1 - pt) * px / (px - $3); done = 1 }
    NR > 1 { pt = $1; px = $3 }
    END {
      th0 = atan2(0.08715574274765817, 0.9961946980917455); L = 1 + 1e-4   # L_eq = (m L^2 + I) / (m L)
      ref = atan2(1, 0) * sqrt(L / g) * (1 + th0 * th0 / 16)              # (pi/2) sqrt(L/g) (...)
      e = (t - ref) / ref; if (e < 0) e = -e
      printf "%.6f %.6f %.1e\n", t, ref, e; exit !(done && e < 1e-3) }' "$1"
}

"$MBCC" run p.yaml --end 0.5 --plot none -o a.csv > a.log 2>&1 || err "first run: $(cat a.log)"
grep -q "mbcc: compiling" a.log || err "the first run did not compile: $(cat a.log)"
[ -x "$exe" ] || err "no simulator at $exe"
touch -d '2000-01-01' "$exe" # an old time: a rebuild would renew it
"$MBCC" run p.yaml --end 1 --rtol 1e-9 --plot none -o b.csv > b.log 2>&1 || err "second run: $(cat b.log)"
grep -q "mbcc: compiling" b.log && err "the second run recompiled: $(cat b.log)"
grep -q "up to date" b.log || err "the second run does not say it reused the simulator: $(cat b.log)"
[ "$(date -r "$exe" +%Y)" = 2000 ] || err "the simulator was rebuilt by the second run"
last=$(tail -n 1 b.csv | cut -d, -f1)
awk -v t="$last" 'BEGIN { exit !(t == 1) }' || err "the second run ended at t = $last, not 1"
q=$(quarter_period b.csv 9.81) || err "quarter period (t, closed form, error): $q"
echo "  reused simulator: quarter period $q"
awk -F, 'NR == 2 { e0 = $7 } NR > 1 { d = $7 - e0; if (d < 0) d = -d; if (d > m) m = d }
  END { exit !(m / (e0 < 0 ? -e0 : e0) < 1e-8) }' b.csv || err "energy not conserved in the reused run"
paste -d, a.csv <(head -n "$(wc -l < a.csv)" b.csv) | awk -F, 'NR > 1 {
    n = NF / 2; if ($1 != $(n + 1)) bad = 1
    for (k = 2; k <= n; k++) { d = $k - $(n + k); if (d < 0) d = -d; if (d > m) m = d } }
  END { exit !(!bad && m < 1e-6) }' || err "the reused run disagrees with the first"

sed -i 's/gravity: \[0, -9.81, 0\]/gravity: [0, -4, 0]/' p.yaml
"$MBCC" run p.yaml --end -1 --plot none -o c.csv > c.log 2>&1
rc=$?
[ $rc = 2 ] || err "--end -1: exit $rc, expected 2"
grep -q "error: '--end' needs a positive number" c.log || err "--end -1: $(cat c.log)"
grep -q "compiling" c.log && err "--end -1: compiled before refusing the option"
[ "$(date -r "$exe" +%Y)" = 2000 ] || err "the bad option rebuilt the simulator"
"$MBCC" run p.yaml --end 1 --plot none -o d.csv > d.log 2>&1 || err "edited model: $(cat d.log)"
grep -q "mbcc: compiling" d.log || err "the edited model was not recompiled: $(cat d.log)"
q=$(quarter_period d.csv 4) || err "edited model: quarter period (t, closed form, error): $q"
echo "  edited model (g = 4): recompiled, quarter period $q"
exit $fail
