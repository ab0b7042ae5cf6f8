#!/bin/sh
# peers.sh: mbcc's emitted evaluation against MuJoCo's mj_forward / mj_step on
# the same rigid mechanisms (bench/peers/README.md): the 4-revolute four-bar
# (bench/peers/four_bar_4r.yaml) and the 17-body car with its rigid chassis
# (bench/peers/sports_car_rigid.yaml).
# For each: `mbcc compile`, the MJCF from scripts/mjcf_from_yaml.py, the peer
# program bench/peers/mujoco_peer.c linked with the generated code, one
# interleaved timing run (exit 1 if the accelerations at rest disagree), and
# valgrind cachegrind's instructions and I1 misses per call (the difference
# between N2 and N1 calls, so that the set-up drops out).  Writes the
# Markdown section to $W/peers.md (make bench includes it in docs/benchmarks.md)
# and prints it.  Skips with a message when MuJoCo (libmujoco-dev) is missing.
# With PEER_DOC=FILE (make peers: docs/peers.md) it also writes that page:
# the section with a title, the machine and its load.
# Environment: MBCC (build/mbcc), CC, PEER_ROUNDS (31), PEER_MODELS (both),
# PEER_DIR (build/peers), PEER_CACHEGRIND (1; 0 skips it), PEER_DOC.
# shellcheck disable=SC2016
TOOL=peers
. "$(dirname "$0")/lib.sh"
RTLIB=$(dirname "$MBCC")/libmbrt.a
CC=${CC:-cc}
ROUNDS=${PEER_ROUNDS:-31}
MODELS=${PEER_MODELS:-"bench/peers/four_bar_4r.yaml bench/peers/sports_car_rigid.yaml"}
W=${PEER_DIR:-$ROOT/build/peers}
CG=${PEER_CACHEGRIND:-1}
fresh_dir "$W"
OUT=$W/peers.md

if [ ! -e /usr/include/mujoco/mujoco.h ]; then
  say "MuJoCo (Debian libmujoco-dev) is not installed: the MuJoCo peer is skipped (scripts/install-deps.sh installs it)"
  printf '## MuJoCo\n\nSkipped: MuJoCo (libmujoco-dev) was not installed when this page was made.\n' >"$OUT"
  exit 0
fi
need_mbcc
command -v python3 >/dev/null || die "python3 is needed (scripts/mjcf_from_yaml.py)"
if [ "$CG" = 1 ] && ! command -v valgrind >/dev/null; then
  say "valgrind is not installed: no instruction counts"
  CG=0
fi

LIBS="-lmujoco -lklu -lamd -lcolamd -lbtf -lsuitesparseconfig -llapack -lblas -lm"
# the flags mbcc builds generated code with (make passes them; the Makefile's CFLAGS less -g)
CFLAGS_GEN="${GEN_CFLAGS:--O2} -ffp-contract=off"

# valgrind 3.19 decodes no AVX-512: the instruction counts are of a copy of the
# peer built for this machine without it (-mno-avx512f after -march=native), on
# the portable runtime
CFLAGS_CG=$CFLAGS_GEN
case " $CFLAGS_GEN " in *" -march=native "*) CFLAGS_CG="$CFLAGS_GEN -mno-avx512f" ;; esac
RTLIB_CG=$(dirname "$MBCC")/libmbrt_portable.a

# cachegrind NAME SIDE N: "Ir I1mr" of N calls of SIDE (mbcc or forward)
cachegrind() {
  valgrind --tool=cachegrind --cache-sim=yes --I1=32768,8,64 --D1=32768,8,64 --LL=1048576,16,64 \
    --cachegrind-out-file="$W/$1.$2.$3.cg" "$W/$1_peer_cg" "$W/$1.xml" --only "$2" "$3" >"$W/$1.$2.$3.cglog" 2>&1 ||
    return 1
  awk '/^events:/ { for (i = 2; i <= NF; i++) e[$i] = i - 1 }
       /^summary:/ { print $(e["Ir"] + 1), $(e["I1mr"] + 1) }' "$W/$1.$2.$3.cg"
}

# per_call NAME SIDE: instructions per call and the I1 miss rate of the calls
# (stops the run when valgrind could not run them: no made-up numbers)
per_call() {
  a=$(cachegrind "$1" "$2" 200) && b=$(cachegrind "$1" "$2" 1200) && [ -n "$a" ] && [ -n "$b" ] ||
    die "cachegrind failed on $1 $2: $(tail -3 "$W/$1.$2.200.cglog" "$W/$1.$2.1200.cglog" 2>/dev/null)"
  echo "$a $b" | awk '{ di = $3 - $1; dm = $4 - $2; if (!(di > 0)) exit 1
                        printf "%.0f %.2f\n", di / 1000, 100 * dm / di }' ||
    die "cachegrind on $1 $2 counted no instructions for the calls"
}

for model in $MODELS; do
  name=$(basename "$model" .yaml)
  say "$name: mbcc compile, MJCF, peer program"
  "$MBCC" compile "$model" -o "$W/$name" --quiet >"$W/$name.compile.log" 2>&1 ||
    { cat "$W/$name.compile.log" >&2; die "mbcc compile $model failed"; }
  python3 scripts/mjcf_from_yaml.py "$model" "$W/$name.xml"
  printf '#include "%s.h"\nconst mb_model *const peer_model = &%s_model;\n' "$name" "$name" >"$W/$name/peer_model.c"
  # every file of the model (a large one is split: <name>.sources lists them)
  srcs=$W/$name/$name.c
  [ ! -e "$W/$name/$name.sources" ] || srcs=$(sed "s|^|$W/$name/|" "$W/$name/$name.sources" | tr '\n' ' ')
  # shellcheck disable=SC2086
  "$CC" -std=c11 $CFLAGS_GEN -Iruntime/core -Iruntime/hosted -I"$W/$name" bench/peers/mujoco_peer.c \
    $srcs "$W/$name/peer_model.c" "$RTLIB" $LIBS -o "$W/${name}_peer" 2>"$W/$name.cc.log" ||
    { cat "$W/$name.cc.log" >&2; die "building the peer of $name failed"; }
  # calls per round: about 2 ms of mj_forward each
  reps=200
  case $name in sports_car*) reps=100 ;; esac
  say "$name: $ROUNDS interleaved rounds of $reps calls"
  "$W/${name}_peer" "$W/$name.xml" --rounds "$ROUNDS" --reps "$reps" --csv "$W/$name.csv" >"$W/$name.txt" ||
    { cat "$W/$name.txt" >&2; die "$name: MuJoCo and mbcc disagree (or the peer failed)"; }
  cat "$W/$name.txt" >&2
  if [ "$CG" = 1 ]; then
    say "$name: cachegrind (200 and 1200 calls of each)"
    # shellcheck disable=SC2086
    "$CC" -std=c11 $CFLAGS_CG -Iruntime/core -Iruntime/hosted -I"$W/$name" bench/peers/mujoco_peer.c \
      $srcs "$W/$name/peer_model.c" "$RTLIB_CG" $LIBS -o "$W/${name}_peer_cg" 2>"$W/$name.cc_cg.log" ||
      { cat "$W/$name.cc_cg.log" >&2; die "building the cachegrind copy of the peer of $name failed"; }
    cg_mbcc=$(per_call "$name" mbcc) || exit 1
    cg_forward=$(per_call "$name" forward) || exit 1
    echo "$cg_mbcc $cg_forward" >"$W/$name.cg"
  else
    echo "- - - -" >"$W/$name.cg"
  fi
done

col() { awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; i++) k[$i] = i; next } { print $k[c] }' "$W/$1.csv"; }
{
  echo "## MuJoCo"
  echo
  echo "mbcc's per-evaluation work (the emitted eval, then the emitted LDLᵀ factor and solve: what"
  echo "the \`generated+ldl\` path does at every right-hand side) against MuJoCo $(dpkg-query -W -f '${Version}' libmujoco-dev 2>/dev/null || echo 2.2)'s"
  echo "\`mj_forward\` and \`mj_step\` on the same mechanism at the same state, measured interleaved in"
  echo "one process: $ROUNDS rounds, each timing a block of calls of the three in turn; medians of the"
  echo "per-call times and of the per-round ratios (with their range; \"fastest rounds\": mbcc's fastest"
  echo "block over MuJoCo's fastest, the least disturbed by the machine's other work). \`make peers\` (scripts/peers.sh)"
  echo "runs it alone. How the peer is modelled (bench/peers/README.md): the MJCF is written from the"
  echo "model's YAML by scripts/mjcf_from_yaml.py (the same bodies and joints; MuJoCo's tree"
  echo "of hinge, slide, ball and free joints with one equality \`connect\` per loop, solimp 0.9999,"
  echo "Newton solver at tolerance 1e-15); the state is mbcc's design configuration with random"
  echo "velocities projected onto the constraints; mbcc's force elements (springs, dampers, bump stops,"
  echo "tyre stand-ins), evaluated by mbcc, are MuJoCo's applied forces, so MuJoCo's timed calls"
  echo "evaluate no force element while mbcc's eval does."
  echo
  echo "| mechanism | mbcc n | MuJoCo nv (constraint rows) | accelerations at rest | in motion | mbcc [µs] | mj_forward [µs] | mj_step [µs] | mbcc / mj_forward | fastest rounds | mbcc / mj_step | instructions mbcc / mj_forward | I1 miss rate mbcc / mj_forward |"
  echo "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
  for model in $MODELS; do
    name=$(basename "$model" .yaml)
    read -r mi mm fi fm <"$W/$name.cg"
    irat=-
    [ "$mi" = - ] || irat=$(awk -v a="$mi" -v b="$fi" 'BEGIN { printf "%d / %d = %.2f", a, b, a / b }')
    printf '| %s | %s | %s (%s) | %s | %s | %s | %s | %s | %s (%s–%s) | %s | %s | %s | %s %% / %s %% |\n' "$name" \
      "$(col "$name" n)" "$(col "$name" mj_nv)" "$(col "$name" mj_nefc)" "$(col "$name" acc_rel_diff_rest)" \
      "$(col "$name" acc_rel_diff)" "$(col "$name" mbcc_us)" "$(col "$name" forward_us)" "$(col "$name" step_us)" \
      "$(col "$name" ratio_forward)" "$(col "$name" ratio_forward_lo)" "$(col "$name" ratio_forward_hi)" \
      "$(col "$name" ratio_fastest)" "$(col "$name" ratio_step)" "$irat" "$mm" "$fm"
  done
  echo
  echo "**Where the time goes** (the peer's second pass: mbcc's eval alone against eval + factor + solve,"
  echo "interleaved rounds; MuJoCo's own stage timers over as many \`mj_forward\` calls, so its stages"
  echo "include a clock read each and add up to more than the timed call):"
  echo
  echo "| mechanism | mbcc eval [µs] | mbcc LDLᵀ factor + solve [µs] | MuJoCo smooth dynamics [µs] | MuJoCo constraints (rows made, solved) [µs] |"
  echo "|---|--:|--:|--:|--:|"
  for model in $MODELS; do
    name=$(basename "$model" .yaml)
    printf '| %s | %s | %s | %s | %s |\n' "$name" "$(col "$name" mbcc_eval_us)" "$(col "$name" mbcc_factor_solve_us)" \
      "$(col "$name" mj_smooth_us)" "$(col "$name" mj_constraint_us)"
  done
  echo
  echo "The formulations differ: mbcc solves for every body's 6 velocities and every joint's"
  echo "constraint rows (the car: K of dimension 188, 17 bodies and 86 rows, 11 286 + 4 772 flops a"
  echo "factorization and solve), MuJoCo for the 26 joint velocities of a tree with 12 loop rows."
  echo "mbcc's straight-line code leaves out the generality (its eval against MuJoCo's smooth dynamics,"
  echo "the same kinematics and inertia in joint coordinates), but its factor and solve are bound by the"
  echo "size of the system, and they set what is left of the time."
  for model in $MODELS; do
    name=$(basename "$model" .yaml)
    awk -v n="$name" -v f="$(col "$name" forward_us)" -v l="$(col "$name" mbcc_factor_solve_us)" 'BEGIN {
      printf "%s: 0.3 of `mj_forward` is %.2f µs a call, against %.2f µs for mbcc'"'"'s LDLᵀ factor and solve alone.\n", n, 0.3 * f, l }'
  done
  echo "A joint-coordinate (recursive) formulation of the tree part would shrink the system to"
  echo "MuJoCo's size."
  echo
  echo "Accelerations: the largest difference of any body's linear or angular acceleration from"
  echo "mbcc's, relative to the largest; the peer program fails (and \`make bench\` with it) when the"
  echo "difference at rest exceeds 5e-3. At rest it is the constraints' softness: MuJoCo's impedance"
  echo "is at most 0.9999, and on the car the difference is 2.5e-1, 2.6e-2, 2.6e-3 at solimp 0.99, 0.999,"
  echo "0.9999 (it scales with 1 - impedance; solref does not change it). In motion MuJoCo's constraint rows also leave out the term (dJ/dt) q̇ of"
  echo "the exact acceleration constraint (its reference acceleration acts on the position and"
  echo "velocity errors only), a difference that grows with the square of the velocities (on the four-bar"
  echo "7.6e-4, 3.1e-3, 1.25e-2 at velocity scales 0.5, 1, 2) and does not change with solref or solimp."
  echo "Instructions: valgrind cachegrind (simulated 32 kB 8-way I1), (count at 1200 calls - count at"
  echo "200 calls) / 1000, of one side alone (\`--only mbcc|forward N\`), a deterministic second"
  echo "opinion on the time ratio; the I1 miss rate is over those calls. Valgrind decodes no AVX-512,"
  echo "so they are counted on a copy of the peer built with \`$CFLAGS_CG\` and the portable runtime"
  echo "(the timed one: \`$CFLAGS_GEN\`)."
  echo
  for model in $MODELS; do
    name=$(basename "$model" .yaml)
    echo '```'
    cat "$W/$name.txt"
    echo '```'
    echo
  done
} >"$OUT"
cat "$OUT"
if [ -n "${PEER_DOC:-}" ]; then
  {
    echo "# mbcc against MuJoCo"
    echo
    echo "Generated by \`make peers\` (scripts/peers.sh); do not edit by hand. \`make bench\` includes the"
    echo "same section in [benchmarks.md](benchmarks.md)."
    echo
    echo "- CPU: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -1), \`nproc\`: $(nproc)"
    echo "- compiler: $($CC --version 2>/dev/null | head -1), the generated code and the peer at $CFLAGS_GEN"
    echo "- load average when written: $(load_average)"
    [ -z "${BENCH_NOTE:-}" ] || echo "- note: $BENCH_NOTE"
    echo
    sed '1s/^## MuJoCo$/## Results/' "$OUT"
  } >"$PEER_DOC.part"
  mv "$PEER_DOC.part" "$PEER_DOC"
  say "wrote $PEER_DOC"
fi
