#!/usr/bin/env bash
# test_cli.sh: the mbcc command line, end to end (exit 0 = pass).
#   - `mbcc run` on the slider-crank writes a CSV with a row per output time
#     (0 .. 0.1 s every 2e-4 s: 501 rows) and a non-empty PNG plot;
#   - `mbcc check` accepts every shipped model (models/_*.yaml are examples
#     of the reader, not meant to assemble);
#   - the generic path (in-process) and the generated path (compiled) give
#     the same CSV for the pendulum, to ~1e-9 (both print 12 digits; the two
#     paths agree to round-off);
#   - `mbcc compile` is reproducible: twice the same bytes.
# Runs mbcc from a scratch directory, so that nothing lands in the source tree.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

# 1. run + plot
if "$MBCC" run "$root/models/slider_crank.yaml" -o "$tmp/sc.csv" --plot "$tmp/sc.png" --quiet > run.log 2>&1; then
  rows=$(($(wc -l < "$tmp/sc.csv") - 1))
  [ "$rows" = 501 ] || err "slider_crank CSV has $rows data rows, expected 501"
  head -1 "$tmp/sc.csv" | grep -q '^t,crank_angle,slider_x,' || err "slider_crank CSV header: $(head -1 "$tmp/sc.csv")"
  # the last row is at t = 0.1
  last=$(tail -1 "$tmp/sc.csv" | cut -d, -f1)
  awk -v t="$last" 'BEGIN { exit !(t - 0.1 < 1e-12 && 0.1 - t < 1e-12) }' || err "last output time $last, expected 0.1"
  [ -s "$tmp/sc.png" ] || err "no plot (or an empty one) at sc.png"
  head -c 8 "$tmp/sc.png" | od -An -c | grep -q 'P   N   G' || err "sc.png is not a PNG file"
  [ -s run.log ] && err "--quiet run printed: $(head -5 run.log)"
else
  err "mbcc run models/slider_crank.yaml failed: $(tail -5 run.log)"
fi

# 2. check every shipped model
for f in "$root"/models/*.yaml; do
  case $(basename "$f") in _*|*.fe.yaml) continue ;; esac  # examples; FE files (fe_file)
  "$MBCC" check "$f" > check.log 2>&1 || err "mbcc check $(basename "$f") exited $?: $(tail -3 check.log)"
done

# 3. generic path == generated path (pendulum)
"$MBCC" run "$root/models/pendulum.yaml" --path generic -o "$tmp/g.csv" --plot none --quiet > g.log 2>&1 \
  || err "generic run failed: $(tail -3 g.log)"
"$MBCC" run "$root/models/pendulum.yaml" -o "$tmp/c.csv" --plot none --quiet > c.log 2>&1 \
  || err "generated run failed: $(tail -3 c.log)"
[ -e "$tmp/g.png" ] || [ -e "$tmp/c.png" ] && err "--plot none wrote a plot"
if [ -s "$tmp/g.csv" ] && [ -s "$tmp/c.csv" ]; then
  # same header, same number of rows, every value equal to 1e-9 (relative,
  # with an absolute floor of 1e-9 for values near zero)
  cmp -s <(head -1 "$tmp/g.csv") <(head -1 "$tmp/c.csv") || err "generic and generated CSV headers differ"
  out=$(awk -F, 'NR == FNR { a[FNR] = $0; n = FNR; next }
    { if (!(FNR in a)) { print "extra row " FNR; bad = 1; exit }
      split(a[FNR], x, ",")
      if (FNR > 1) for (i = 1; i <= NF; i++) {
        d = x[i] - $i; if (d < 0) d = -d
        s = x[i] < 0 ? -x[i] : x[i]; if (s < 1) s = 1
        if (d > 1e-9 * s) { print "row " FNR " column " i ": " x[i] " vs " $i; bad = 1; exit }
      }
      m = FNR }
    END { if (!bad && m != n) print "row counts differ: " n " vs " m
          if (!bad && m < 1001) print "only " m " lines" }' "$tmp/g.csv" "$tmp/c.csv")
  [ -z "$out" ] || err "generic vs generated pendulum CSV: $out"
else
  err "missing pendulum CSV files"
fi

# 4. reproducible code generation (mbcc creates the last directory of -o only)
mkdir -p "$tmp/c1" "$tmp/c2"
for f in "$root"/models/*.yaml; do
  case $(basename "$f") in _*|*.fe.yaml) continue ;; esac  # examples; FE files (fe_file)
  n=$(basename "$f" .yaml)
  "$MBCC" compile "$f" -o "$tmp/c1/$n" > /dev/null 2>&1 || { err "mbcc compile $n failed"; continue; }
  "$MBCC" compile "$f" -o "$tmp/c2/$n" > /dev/null 2>&1 || { err "mbcc compile $n failed (2nd)"; continue; }
  [ -s "$tmp/c1/$n/$n.c" ] && [ -s "$tmp/c1/$n/$n.h" ] && [ -s "$tmp/c1/$n/main.c" ] || err "mbcc compile $n: missing files"
  diff -r "$tmp/c1/$n" "$tmp/c2/$n" > /dev/null || err "mbcc compile $n is not reproducible"
done

exit $fail
