#!/usr/bin/env bash
# scaling.sh: regenerates docs/scaling.md: how building and running grow with
# the model, on pendulum chains of scripts/chain.sh (N links: n = 11 N).  For
# each size: `mbcc compile` time and peak memory; the C compile of the
# benchmark executable (the generated model, its main program, linked against
# the runtime) time and peak memory, through a wrapper around $CC run by
# /usr/bin/time; the size of the generated C; and `mbcc bench`'s
# per-step times of generated+ldl and generic+klu (repetitions interleaved,
# set-up left out).  Called by `make scaling` after `make all`.
# Environment: MBCC (default build/mbcc), SIZES (links, default
# "5 10 20 50 100 200 500 1000"), REPS (default 5), END (simulated time,
# default 0.1 s: 20 to 50 steps), TIMEOUT (seconds allowed to one C compile, default 3600: a
# size that does not build within it is reported as such and larger ones are
# skipped), OUT (default docs/scaling.md), NOTE (a line about the machine).
# Work files go to build/scaling/ and are kept: a second run reuses each
# size's benchmark executable when its inputs are unchanged (mbcc's build
# stamp), and reports the C compile measured when it was built.
set -euo pipefail
export LC_ALL=C
cd "$(dirname "$0")/.."
ROOT=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC=$ROOT/$MBCC ;; esac
SIZES=${SIZES:-5 10 20 50 100 200 500 1000}
REPS=${REPS:-5}
END=${END:-0.1}
TIMEOUT=${TIMEOUT:-3600}
OUT=${OUT:-docs/scaling.md}
W=$ROOT/build/scaling
die() { echo "scaling: error: $*" >&2; exit 1; }
say() { echo "scaling: $*" >&2; }
[ -x "$MBCC" ] || die "$MBCC not found: run 'make all' first"
[ -x /usr/bin/time ] || die "/usr/bin/time not found (Debian package 'time': scripts/install-deps.sh)"
mkdir -p "$W"

# the C compiler mbcc runs, timed: one line "wall user sys maxrss_kB start end" per
# call (a large model's files are compiled by several calls at once, then linked)
cat > "$W/timed-cc" <<EOS
#!/bin/sh
start=\$(date +%s.%N)
timeout $TIMEOUT /usr/bin/time -o "\$SCALING_CC_LOG.\$\$" -f "%e %U %S %M" ${CC:-cc} "\$@"
rc=\$?
echo "\$(cat "\$SCALING_CC_LOG.\$\$") \$start \$(date +%s.%N)" >> "\$SCALING_CC_LOG"
rm -f "\$SCALING_CC_LOG.\$\$"
exit \$rc
EOS
chmod +x "$W/timed-cc"

rows=()
stop=
for n in $SIZES; do
  d=$W/chain$n
  mkdir -p "$d"
  if [ -n "$stop" ]; then
    rows+=("| $n | $((11 * n)) | | | | | | | | | skipped: a smaller chain did not build |")
    continue
  fi
  bash scripts/chain.sh "$n" > "$d/chain$n.yaml"
  say "chain of $n links: mbcc compile"
  /usr/bin/time -o "$d/mbcc.time" -f "%e %U %S %M" "$MBCC" compile "$d/chain$n.yaml" -o "$d/gen" > "$d/compile.log" 2>&1 ||
    die "mbcc compile of the $n-link chain failed: $(tail -3 "$d/compile.log")"
  read -r _ mu ms mk < "$d/mbcc.time"
  # the model's C files: chain$n.c, or all that chain$n.sources lists
  if [ -f "$d/gen/chain$n.sources" ]; then
    csize=$(cd "$d/gen" && cat $(cat "chain$n.sources") | wc -c)
    nfiles=$(wc -l < "$d/gen/chain$n.sources")
  else
    csize=$(wc -c < "$d/gen/chain$n.c")
    nfiles=1
  fi
  ldl=$("$MBCC" check "$d/chain$n.yaml" | sed -n 's/^  LDL^T code *//p' | cut -d' ' -f1)
  say "chain of $n links: mbcc bench (C compile of up to $TIMEOUT s, then $REPS interleaved rounds)"
  touch "$d/cc.time" # the last build's compiles: kept, for an executable reused unchanged
  rm -f "$d/cc.new"
  if ! (cd "$d" && SCALING_CC_LOG="$d/cc.new" CC="$W/timed-cc" "$MBCC" bench "chain$n.yaml" \
        --paths generated+ldl,generic+klu --reps "$REPS" --end "$END" --csv bench.csv --quiet) \
        > "$d/bench.txt" 2> "$d/bench.log"; then
    if grep -q "the C compiler failed" "$d/bench.log"; then
      rows+=("| $n | $((11 * n)) | $(awk -v u="$mu" -v s="$ms" 'BEGIN { printf "%.2f", u + s }') | $((mk / 1024)) | $((csize / 1024)) ($nfiles) | | | | | $ldl | did not build within $TIMEOUT s (or failed) |")
      stop=1
      continue
    fi
    die "mbcc bench of the $n-link chain failed: $(tail -3 "$d/bench.log")"
  fi
  [ -s "$d/cc.new" ] && mv "$d/cc.new" "$d/cc.time"
  [ -s "$d/cc.time" ] || die "no C compile recorded for the $n-link chain (remove $d and run again)"
  # the build: wall from the first compiler's start to the last one's end, CPU
  # summed over the calls, memory of the largest
  read -r cw cu ck < <(awk '{ u += $2 + $3; if ($4 > k) k = $4; if (s == "" || $5 < s) s = $5; if ($6 > e) e = $6 }
    END { printf "%.1f %.2f %d\n", e - s, u, k }' "$d/cc.time")
  read -r gen gnc < <(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    $c["path"] == "generated+ldl" { g = $c["step_median_s"] } $c["path"] == "generic+klu" { k = $c["step_median_s"] }
    END { print g, k }' "$d/bench.csv")
  rows+=("$(awk -v n="$n" -v mu="$mu" -v ms="$ms" -v mk="$mk" -v cs="$csize" -v nf="$nfiles" -v cw="$cw" -v cu="$cu" -v ck="$ck" \
      -v g="$gen" -v k="$gnc" -v ldl="$ldl" 'BEGIN {
    printf "| %d | %d | %.2f | %d | %d (%d) | %.1f | %.1f | %d | %.3g / %.3g | %s | %.1f |", n, 11 * n, mu + ms, mk / 1024,
      cs / 1024, nf, cw, cu, ck / 1024, g, k, ldl, k / g }')")
  say "${rows[-1]}"
done

{
  echo "# Scaling with the model's size"
  echo
  echo "Written by \`make scaling\` (scripts/scaling.sh) on $(date -u +%Y-%m-%d), $(uname -m), $(nproc) cores,"
  echo "$(${CC:-cc} --version | head -n 1)."
  [ -n "${NOTE:-}" ] && echo "$NOTE"
  echo "Load average when the table was written: $(cut -d' ' -f1-3 /proc/loadavg) (the machine is shared)."
  echo
  echo "Pendulum chains of N uniform rods hinged about z (scripts/chain.sh N; n = 11 N: 6 velocities"
  echo "and 5 constraint rows a link). mbcc compile: the whole of \`mbcc compile\` (read, lower,"
  echo "assembly analysis, ordering, emission), user+system CPU and peak resident memory. C compile:"
  echo "the C compiler building the benchmark executable (the generated model, its main program,"
  echo "linked against the runtime): wall time from the first compiler's start to the link's end"
  echo "(a large model's files are compiled $(nproc) at a time), CPU summed over the compiler"
  echo "processes, peak memory of the largest. C files: the generated model's size and, in"
  echo "parentheses, its number of C files (docs/pipeline.md, \"A large model in several files\"). Per step: \`mbcc bench"
  echo "--paths generated+ldl,generic+klu --reps $REPS --end $END\`, medians of the repetitions"
  echo "(interleaved round after round, set-up left out) of the time per Dormand–Prince step; the"
  echo "ratio is generic+klu / generated+ldl. LDLᵀ: the emitted factorization's form (straight-line"
  echo "code, or loops over the factor's pattern when above the flop budget)."
  echo
  echo "| links | n | mbcc compile [s] | mbcc memory [MB] | C files [kB] | C compile wall [s] | C compile CPU [s] | C memory [MB] | per step generated+ldl / generic+klu [s] | LDLᵀ | ratio |"
  echo "|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|"
  printf '%s\n' "${rows[@]}"
} > "$OUT.part"
mv "$OUT.part" "$OUT"
say "wrote $OUT"
