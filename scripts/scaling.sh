#!/usr/bin/env bash
# scaling.sh: regenerates docs/scaling.md: how building and running grow with
# the model, in two tables: pendulum chains of scripts/chain.sh (N links: n =
# 11 N) and fleets of scripts/fleet.sh (N rigid-chassis sports cars side by
# side, 17 N bodies: the vehicle repeated).  For each size: `mbcc compile`
# time and peak memory; the C compile of the benchmark executable (the
# generated model, its main program, linked against the runtime) time and
# peak memory, through a wrapper around $CC run by /usr/bin/time; the size of
# the generated C; and `mbcc bench`'s per-step times of generated+ldl and
# generic+klu (repetitions interleaved, set-up left out).  Called by `make
# scaling` after `make all`.
# Environment: MBCC (default build/mbcc), SIZES (links, default
# "5 10 20 50 100 200 500 1000"), FLEET_SIZES (cars, default "1 2 4 8 16 30";
# FLEET_SIZES="1 2" SIZES="5" for a quick run, FLEET_SIZES="" for none),
# REPS (default 5), END (simulated time, default 0.1 s: 20 to 50 steps of a
# chain, 100 of a fleet, whose steps are at most 1 ms), TIMEOUT (seconds
# allowed to one C compile, default 3600: a size that does not build within
# it is reported as such and the larger ones of its table are skipped), OUT
# (default docs/scaling.md), NOTE (a line about the machine).
# Work files go to build/scaling/ and are kept: a second run reuses each
# size's benchmark executable when its inputs are unchanged (mbcc's build
# stamp), and reports the C compile measured when it was built.
TOOL=scaling; . "$(dirname "$0")/lib.sh"
set -o pipefail
SIZES=${SIZES:-5 10 20 50 100 200 500 1000}
FLEET_SIZES=${FLEET_SIZES:-1 2 4 8 16 30}
REPS=${REPS:-5}
END=${END:-0.1}
TIMEOUT=${TIMEOUT:-3600}
OUT=${OUT:-docs/scaling.md}
W=$ROOT/build/scaling
need_mbcc
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

# measure SIZE WHAT NAME: appends to rows the table row of the model
# $W/NAME/NAME.yaml (already written), SIZE its first column, WHAT its name in
# messages; once a model does not build (stop set), the larger ones of the
# same table are skipped
rows=()
stop=
measure() {
  local size=$1 what=$2 name=$3 d=$W/$3
  local n mu ms mk csize nfiles ldl cw cu ck gen gnc
  n=$("$MBCC" check "$d/$name.yaml" 2> /dev/null | sed -n 's/^  system dimension *//p' | cut -d' ' -f1) || true
  [ -n "$n" ] || die "mbcc check of the $what failed: $("$MBCC" check "$d/$name.yaml" 2>&1 | tail -3)"
  if [ -n "$stop" ]; then
    rows+=("| $size | $n | | | | | | | | | skipped: a smaller model did not build |")
    return 0
  fi
  say "$what: mbcc compile"
  /usr/bin/time -o "$d/mbcc.time" -f "%e %U %S %M" "$MBCC" compile "$d/$name.yaml" -o "$d/gen" > "$d/compile.log" 2>&1 ||
    die "mbcc compile of the $what failed: $(tail -3 "$d/compile.log")"
  read -r _ mu ms mk < "$d/mbcc.time"
  # the model's C files: NAME.c, or all that NAME.sources lists
  if [ -f "$d/gen/$name.sources" ]; then
    csize=$(cd "$d/gen" && cat $(cat "$name.sources") | wc -c)
    nfiles=$(wc -l < "$d/gen/$name.sources")
  else
    csize=$(wc -c < "$d/gen/$name.c")
    nfiles=1
  fi
  ldl=$("$MBCC" check "$d/$name.yaml" 2> /dev/null | sed -n 's/^  LDL^T code *//p' | cut -d' ' -f1)
  say "$what: mbcc bench (C compile of up to $TIMEOUT s, then $REPS interleaved rounds)"
  touch "$d/cc.time" # the last build's compiles: kept, for an executable reused unchanged
  rm -f "$d/cc.new"
  if ! (cd "$d" && SCALING_CC_LOG="$d/cc.new" CC="$W/timed-cc" "$MBCC" bench "$name.yaml" \
        --paths generated+ldl,generic+klu --reps "$REPS" --end "$END" --csv bench.csv --quiet) \
        > "$d/bench.txt" 2> "$d/bench.log"; then
    if grep -q "the C compiler failed" "$d/bench.log"; then
      rows+=("| $size | $n | $(awk -v u="$mu" -v s="$ms" 'BEGIN { printf "%.2f", u + s }') | $((mk / 1024)) | $((csize / 1024)) ($nfiles) | | | | | $ldl | did not build within $TIMEOUT s (or failed) |")
      stop=1
      return 0
    fi
    die "mbcc bench of the $what failed: $(tail -3 "$d/bench.log")"
  fi
  [ -s "$d/cc.new" ] && mv "$d/cc.new" "$d/cc.time"
  [ -s "$d/cc.time" ] || die "no C compile recorded for the $what (remove $d and run again)"
  # the build: wall from the first compiler's start to the last one's end, CPU
  # summed over the calls, memory of the largest
  read -r cw cu ck < <(awk '{ u += $2 + $3; if ($4 > k) k = $4; if (s == "" || $5 < s) s = $5; if ($6 > e) e = $6 }
    END { printf "%.1f %.2f %d\n", e - s, u, k }' "$d/cc.time")
  read -r gen gnc < <(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    $c["path"] == "generated+ldl" { g = $c["step_median_s"] } $c["path"] == "generic+klu" { k = $c["step_median_s"] }
    END { print g, k }' "$d/bench.csv")
  rows+=("$(awk -v size="$size" -v n="$n" -v mu="$mu" -v ms="$ms" -v mk="$mk" -v cs="$csize" -v nf="$nfiles" -v cw="$cw" -v cu="$cu" -v ck="$ck" \
      -v g="$gen" -v k="$gnc" -v ldl="$ldl" 'BEGIN {
    printf "| %d | %d | %.2f | %d | %d (%d) | %.1f | %.1f | %d | %.3g / %.3g | %s | %.1f |", size, n, mu + ms, mk / 1024,
      cs / 1024, nf, cw, cu, ck / 1024, g, k, ldl, k / g }')")
  say "${rows[-1]}"
}

for links in $SIZES; do
  mkdir -p "$W/chain$links"
  bash scripts/chain.sh "$links" > "$W/chain$links/chain$links.yaml"
  measure "$links" "chain of $links links" "chain$links"
done
chain_rows=("${rows[@]}")

rows=()
stop=
for cars in $FLEET_SIZES; do
  mkdir -p "$W/fleet$cars"
  bash scripts/fleet.sh "$cars" > "$W/fleet$cars/fleet$cars.yaml" || die "scripts/fleet.sh $cars failed"
  measure "$cars" "fleet of $cars cars" "fleet$cars"
done
fleet_rows=("${rows[@]}")

{
  echo "# Scaling with the model's size"
  echo
  echo "Written by \`make scaling\` (scripts/scaling.sh) on $(date -u +%Y-%m-%d), $(uname -m), $(nproc) cores,"
  echo "$(${CC:-cc} --version | head -n 1)."
  [ -n "${NOTE:-}" ] && echo "$NOTE"
  echo "Load average when the table was written: $(cut -d' ' -f1-3 /proc/loadavg) (the machine is shared)."
  echo
  echo "Two families of models: pendulum chains and fleets of cars. mbcc compile: the whole of"
  echo "\`mbcc compile\` (read, lower, assembly analysis, ordering, emission), user+system CPU and"
  echo "peak resident memory. C compile:"
  echo "the C compiler building the benchmark executable (the generated model, its main program,"
  echo "linked against the runtime): wall time from the first compiler's start to the link's end"
  echo "(a large model's files are compiled $(nproc) at a time), CPU summed over the compiler"
  echo "processes, peak memory of the largest. C files: the generated model's size and, in"
  echo "parentheses, its number of C files (docs/pipeline.md, \"A large model in several files\"). Per step: \`mbcc bench"
  echo "--paths generated+ldl,generic+klu --reps $REPS --end $END\`, medians of the repetitions"
  echo "(interleaved round after round, set-up left out) of the time per Dormand–Prince step; the"
  echo "ratio is generic+klu / generated+ldl. LDLᵀ: the emitted factorization's form (straight-line"
  echo "code, or loops over the factor's pattern when above the flop budget). n: the system"
  echo "dimension (velocities and constraint rows, \`mbcc check\`)."
  echo
  echo "## Pendulum chains"
  echo
  echo "Chains of N uniform rods hinged about z (scripts/chain.sh N; n = 11 N: 6 velocities"
  echo "and 5 constraint rows a link)."
  echo
  echo "| links | n | mbcc compile [s] | mbcc memory [MB] | C files [kB] | C compile wall [s] | C compile CPU [s] | C memory [MB] | per step generated+ldl / generic+klu [s] | LDLᵀ | ratio |"
  echo "|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|"
  printf '%s\n' "${chain_rows[@]}"
  if [ ${#fleet_rows[@]} -gt 0 ]; then
    echo
    echo "## The vehicle repeated"
    echo
    echo "Fleets of N sports cars with rigid chassis (scripts/fleet.sh N: N instances of the subsystem"
    echo "models/sports_car/rigid_car.yaml, the \`rigid\` scene's car of models/sports_car.yaml, 17 bodies,"
    echo "4 Gim–Nikravesh tyres, 86 constraint rows, n = 188 a car) side by side in lanes 3.5 m apart, at"
    echo "60 km/h on a flat road; steps of at most 1 ms (the car's \`max_step\`). The cars do not interact:"
    echo "the sparse system is N copies of one car's."
    echo
    echo "| cars | n | mbcc compile [s] | mbcc memory [MB] | C files [kB] | C compile wall [s] | C compile CPU [s] | C memory [MB] | per step generated+ldl / generic+klu [s] | LDLᵀ | ratio |"
    echo "|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|"
    printf '%s\n' "${fleet_rows[@]}"
  fi
} > "$OUT.part"
mv "$OUT.part" "$OUT"
say "wrote $OUT"
