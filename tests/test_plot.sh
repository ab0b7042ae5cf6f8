#!/usr/bin/env bash
# test_plot.sh: mbcc plot (exit 0 = pass), on CSV files made here with known
# columns (N: a = 100 sin 6t, b = 1e-30 sin 50t; m: c = 1e-9 sin 6t; J:
# d = 5 + 1e-9 sin 40t, e = 7 + 1e-14 sin 40t) and a units file:
#   - round-off: b (below 1e-12 of a, its kin in N) is drawn as 0 and its
#     title says so; e (varies 1e-14 of 7) is drawn constant and says so;
#     c (tiny, but alone in m) and d (varies 2e-10 of 5) are drawn as data;
#   - units on the axes ([N], [m], t [s]);
#   - overlay: two files and a+c give four curves in one panel, with a legend;
#   - 11 panels: two pages, out.png and out-2.png, both PNG;
#   - an unknown column: exit 2, the known ones listed, no plot written;
#   - nothing from gnuplot on the terminal (flat columns make it warn).
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
command -v gnuplot > /dev/null || { echo "FAIL: no gnuplot"; exit 1; }

mk() { # mk FILE PHASE
  awk -v ph="$2" 'BEGIN { print "t,a,b,c,d,e"
    for (i = 0; i <= 200; i++) { t = i * 0.005
      printf "%.10g,%.12g,%.12g,%.12g,%.12g,%.17g\n", t, 100 * sin(6 * t + ph), 1e-30 * sin(50 * t), 1e-9 * sin(6 * t),
        5 + 1e-9 * sin(40 * t), 7 + 1e-14 * sin(40 * t) } }' > "$1"
  printf 'column,unit\nt,s\na,N\nb,N\nc,m\nd,J\ne,J\n' > "$1.units"
}
mk s.csv 0
mk r.csv 0.3

"$MBCC" plot s.csv --gnuplot s.gp > out.txt 2> err.txt || err "mbcc plot s.csv exited $?: $(cat err.txt)"
[ -s err.txt ] && err "mbcc plot wrote to stderr (gnuplot noise?): $(head -3 err.txt)"
[ "$(cat out.txt)" = "wrote s.png" ] || err "mbcc plot printed: $(cat out.txt)"
head -c 8 s.png | od -An -c | grep -q 'P   N   G' || err "s.png is not a PNG file"
grep -q "^set title 'b = 0 (drawn so: |y| <= 1e-30 is round-off)'" s.gp || err "b is not labelled round-off: $(grep "title 'b" s.gp)"
grep -q "using 1:(0) " s.gp || err "b is not drawn as exactly zero"
grep -q "^set title 'e = 7 (drawn constant: its variation .* is round-off)'" s.gp || err "e is not labelled constant: $(grep "title 'e" s.gp)"
grep -q "using 1:(7) " s.gp || err "e is not drawn as a constant"
grep -q "using 1:4 .*title 'c'" s.gp || err "c (small but real) is not drawn as data"
grep -q "using 1:5 .*title 'd'" s.gp || err "d (a real variation of 2e-10 of its size) is not drawn as data"
grep -q "set ylabel '\[N\]'" s.gp && grep -q "set ylabel '\[m\]'" s.gp && grep -q "set xlabel 't \[s\]'" s.gp ||
  err "units missing on the axes"

# overlay: two files, two columns in one panel
"$MBCC" plot s.csv r.csv --columns a+c -o ov.png --gnuplot ov.gp > out.txt 2> err.txt || err "overlay exited $?: $(cat err.txt)"
[ -s err.txt ] && err "overlay wrote to stderr: $(head -3 err.txt)"
n=$(grep -c "title '[ac] [sr].csv'" ov.gp)
[ "$n" = 4 ] || err "overlay of a+c from two files: $n curves, expected 4: $(cat ov.gp)"
grep -q '^set key' ov.gp || err "overlay without a legend"
[ -s ov.png ] || err "no overlay plot"

# pages: 11 panels, 8 a page
"$MBCC" plot s.csv --columns a,b,c,d,e,a,b,c,d,e,a -o many.png > out.txt 2> err.txt || err "11 panels exited $?: $(cat err.txt)"
for f in many.png many-2.png; do
  head -c 8 "$f" 2> /dev/null | od -An -c | grep -q 'P   N   G' || err "11 panels: no page $f"
done
[ -e many-3.png ] && err "11 panels made a third page"
grep -qx "wrote many-2.png" out.txt || err "the second page is not reported: $(cat out.txt)"

# an unknown column
"$MBCC" plot s.csv --columns a,nosuch -o bad.png > out.txt 2> err.txt
[ $? = 2 ] || err "an unknown column did not exit 2"
grep -q "nosuch" err.txt && grep -q "a, b, c, d, e" err.txt || err "the unknown-column error does not list the known ones: $(cat err.txt)"
[ -e bad.png ] && err "an unknown column still wrote a plot"

exit $fail
