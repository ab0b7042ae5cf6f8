#!/bin/sh
# trade.sh: regenerates docs/trade.md and docs/img/trade_*.png: `mbcc trade`
# (the speed/accuracy study) on the flexible slider-crank and, when it
# exists, the vehicle model (models/*vehicle*.yaml), with the method, the
# reference's own error, the Pareto front, every run, and the cheapest
# settings for the error targets $TARGETS.
# Called by `make trade` after `make all` (POSIX sh and awk, gnuplot).
# Environment: MBCC (default build/mbcc), REPS (default 3), END (simulated
# time, default 0.05 s: one crank revolution), TARGETS (default
# 1e-2,1e-3,1e-4).  Work files (generated code, CSV, logs) go to build/trade/.
# shellcheck disable=SC2016  # awk programs in single quotes
TOOL=trade
. "$(dirname "$0")/lib.sh"
REPS=${REPS:-3}
END=${END:-0.05}
TARGETS=${TARGETS:-1e-2,1e-3,1e-4}
W=$ROOT/build/trade
OUT=docs/trade.md

need_mbcc
fresh_dir "$W"
mkdir -p docs/img

# study NAME MODEL [ARGS...]: `mbcc trade` into $W/NAME.{txt,csv,cmd,log}, docs/img/trade_NAME.png
study() {
  name=$1
  shift
  args="$* --end $END --reps $REPS --max-error $TARGETS"
  say "$(show "$MBCC trade $args") (a few minutes)"
  # shellcheck disable=SC2086  # args is a list of words
  if ! "$MBCC" trade $args --workdir "$W/$name" --csv "$W/$name.csv" --plot "$ROOT/docs/img/trade_$name.png" \
      >"$W/$name.txt" 2>"$W/$name.log"; then
    cat "$W/$name.txt" "$W/$name.log" >&2
    die "mbcc trade failed on $name"
  fi
  [ -s "$W/$name.csv" ] || die "no CSV from mbcc trade on $name"
  show "mbcc trade $args --csv $name.csv --plot docs/img/trade_$name.png" | sed 's|build/mbcc|mbcc|' >"$W/$name.cmd"
}

# every run as a Markdown table; with a second argument 1 only the Pareto front, by CPU time
md_runs() {
  awk -F, -v only_front="${2:-0}" '
    NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i
      print "| run | variant | modes | coupling | joints | real | integrator | step / rtol | solver | CPU [s] | max_err | rms_err | front |"
      print "|--:|---|--:|---|---|---|---|--:|---|--:|--:|--:|:-:|"
      next }
    only_front && $c["pareto"] != 1 { next }
    {
      sr = $c["step"] != "" ? $c["step"] : $c["rtol"]
      if ($c["failed"] == 1)
        printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | failed | %s | | |\n", $c["run"], $c["variant"], $c["modes"],
          $c["coupling"], $c["joints"], $c["real"], $c["integrator"], sr, $c["solver"], $c["note"]
      else
        printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %.3g | %.2e | %.2e | %s |\n", $c["run"], $c["variant"],
          $c["modes"], $c["coupling"], $c["joints"], $c["real"], $c["integrator"], sr, $c["solver"], $c["cpu_s"],
          $c["max_err"], $c["rms_err"], $c["pareto"] == 1 ? "*" : ""
    }' "$W/$1.csv" >"$W/$1.md"
  head -2 "$W/$1.md"
  if [ "${2:-0}" = 1 ]; then tail -n +3 "$W/$1.md" | sort -t'|' -k11,11g; else tail -n +3 "$W/$1.md"; fi
}

section() {
  name=$1
  title=$2
  echo "## $title"
  echo
  echo '```'
  cat "$W/$name.cmd"
  echo '```'
  echo
  echo "Reference and its own error (the reference against the stricter run):"
  echo
  echo '```'
  sed -n '/^model /,/^reference error/p' "$W/$name.txt"
  echo '```'
  echo
  echo "![max error against CPU time, $title](img/trade_$name.png)"
  echo
  echo "The cheapest settings for each error target:"
  echo
  echo '```'
  grep -E '^(max_err <=|warning:)' "$W/$name.txt" || true
  echo '```'
  echo
  echo "### The Pareto front, by CPU time"
  echo
  md_runs "$name" 1
  echo
  echo "### Every run"
  echo
  md_runs "$name"
  echo
}

# the method, after the results
method() {
  cat <<'EOF_METHOD'
## Method

`mbcc trade M.yaml [--scene S]` answers, for one model, what each unit of speed costs
in accuracy (compiler/tools/trade.c; the pure parts in compiler/tools/trade_metric.c).

**Reference.** The most accurate settings the study knows: the largest number of modes
swept (`--modes`; `all` if listed), full inertia coupling, joints directly on the
flexible nodes, double precision, KLU, Dormand–Prince 5(4) at `--ref-rtol` (default
1e-10, atol = rtol / 100). It is checked against a second, stricter run of the same
code: rtol 100 times tighter and the largest step halved (half the output step). The
**reference error** printed is the error metric below between the two, the stricter
run taken as the truth: the part of the reference's error that comes from
integration. It says nothing about modes beyond those the reference has: the default
reference keeps the largest count swept (for the slider-crank 8 fixed-interface normal
modes plus the 6 interface modes: 14) rather than all 48 of its rod's FE model, whose
highest modes (tens of kHz) hold an explicit integrator to steps of about 1 µs (about 30
times the CPU time per simulated second). What that leaves out was measured once with
`mbcc trade models/slider_crank_flexible.yaml --modes all --end 0.02 --integrators
rk4@5e-5,dopri5@1e-4,dopri5@1e-6 --couplings full --joints direct --reals double
--solvers ldl --reps 1` (6 minutes): the 14-mode reference differs from the 48-mode one by
1.8e-2 in total energy (the output slowest to converge in the number of modes), 1.8e-3 in
the midspan deflection, 4e-5 in the slider position and nothing in the (driven) crank
angle, relative to each output's range over 0.02 s. Error targets below those are
targets against the 14-mode model; add `all` to `--modes` to measure against every mode.
`tests/test_trade.c` checks the reported reference error
against a closed form (below).

**Sweep.** Every setting that trades speed for accuracy:

- structural settings (the `modes` column counts every modal coordinate, interface modes
  included; the variant `modes-N` has N fixed-interface normal modes), each with its own
  generated code, compiled once into
  `generated/<model>_trade/<variant>/` (or `--workdir`): the number of modes per
  flexible body (`--modes`: counts, `all`, or cutoffs such as `1000Hz`; default twice,
  half and none of the model's count of normal modes, on top of its interface modes),
  the inertia coupling (`--couplings full,partial,constant,rigid`), the joints on
  flexible nodes (`--joints direct,virtual`) and the precision (`--reals double,float`).
  One setting is changed at a time from the model as written (the variant `base`):
  a full cross product would be hundreds of builds. A variant with the reference's
  structure runs the reference's code;
- for each variant, every integrator setting (`--integrators`, `NAME@VALUE`: the value is
  the step for `rk4` and rtol for the adaptive ones, atol = rtol / 100). Default: RK4
  at a quarter and a sixteenth of the output step, Dormand–Prince and the
  generalized-α (`genalpha`) at rtol 1e-4, 1e-6, 1e-8;
- the solvers (`--solvers ldl,klu,dense`): the variants run with the first listed, the
  base with every one; single precision runs with ldl only.

A run whose simulator cannot be built (no single-precision runtime, an integrator the
simulator does not know yet) or fails (nonzero exit, no or short CSV, a non-finite
output, other output times) is reported `failed` with its reason, has no error and is
never on the front; the study goes on.

**CPU time.** The simulator process's user + system CPU time (`wait4`), the median of
`--reps` runs (default 3): the whole simulation (set-up, integration, writing the CSV;
process start is about a millisecond), not the code generation or the C compiler.

**Error.** For the chosen outputs (`--outputs a,b`; default every output column that varies) at the
reference's output times: for column c and output time k,
e_ck = |y_ck − ref_ck| / s_c, where s_c is the range (max − min) of column c over the
reference run; the columns of one vector output (`p.x`, `p.y`, `p.z`) share the
largest range among them, so that a component that stays at round-off (a planar
mechanism's z) is measured against the vector's scale; a column (or vector) that does
not move is measured against its largest |value|, or in absolute terms if that is 0.
`max_err` = max over c and k of e_ck; `rms_err` = sqrt(mean over all k and all c of
e_ck²). Without `--outputs`, a column that does not vary is left out and listed with
the reason: constant; a range below 1e-12 of the largest |value| of its vector
(round-off); or a range within 10 times the reference's own error against the
stricter run (a conserved output: the pendulum's total energy, whose range is only
integration error). `--outputs` compares exactly what it names.

**Pareto front.** Among the runs that did not fail, those that no other run matches or
beats in both CPU time and `max_err` while beating it in one (marked `*`, `pareto` = 1).
Two runs with the same time and error are both on it.

**Error targets.** `--max-error E[,E2,...]`: for each target, the successful run with
`max_err` ≤ E and the least CPU time, as the IFToMM multibody benchmark ranks methods
(a precision target first, then CPU time), or "no run meets it". A target below the
reference's own error is flagged: tighten `--ref-rtol`.

**Reading the results.** An error that does not fall when the tolerance is tightened is
the model's, not the integrator's: modes left out, a simpler coupling, or the
reference's extra modes. RK4 near its stability limit, and the generalized-α at a
loose tolerance (its numerical dissipation), damp the highest modes, which can bring a
truncated model closer to the reference (slider-crank: `base` with RK4 at 5e-5 against
1.25e-5; `base` with generalized-α at rtol 1e-4, 9.6e-3, against 1.8e-2 at 1e-8, the
truncation error of its 10 modes); such a point on the front is luck of this model, not
a method.
Times below about 0.05 s are within the noise of a shared machine.

**Output.** The table on stdout, `--csv FILE` (one row per run: `run, variant, modes,
coupling, joints, real, integrator, step, rtol, solver, cpu_s, max_err, rms_err, failed,
pareto, note`; written through a temporary file), and `--plot FILE.png` (default next to
the CSV; `none` for no plot): log-log `max_err` against CPU time with the front and the
reference error (dashed).

**The closed-form check** (`tests/test_trade.c`). The pendulum (models/pendulum.yaml)
released at rest 90° from the bottom has θ(t) = 2 asin(k sn(K − ω₀t, k)), k = sin(θ₀/2),
ω₀² = mgL / (mL² + I); sn and K by the descending Landen (AGM) method. With a loose
reference (rtol 1e-6, output step 0.1 s: its error far above the 12 printed digits) the
reference's true error against the closed form, on the same metric, must be within a
factor 2 of the error `mbcc trade` reports for it (measured: 2.81e-6 true, 2.78e-6
reported); with the default reference (rtol 1e-10) the true error must be at most twice
the reported one plus the CSV's print rounding, 1e-11 (measured: 2.8e-12 true,
3.2e-12 reported).
EOF_METHOD
}

study slider_crank_flexible "$ROOT/models/slider_crank_flexible.yaml"
vehicles=$(ls models/*vehicle*.yaml 2>/dev/null || true)
for v in $vehicles; do study "$(basename "$v" .yaml)" "$ROOT/$v"; done

cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo 2>/dev/null | head -1)
[ -n "$cpu" ] || cpu=unknown
tmp=$OUT.part
{
  echo "# Speed against accuracy: \`mbcc trade\`"
  echo
  echo "Generated by \`make trade\` (scripts/trade.sh); do not edit by hand. The method is"
  echo "described in [the last section](#method)."
  echo
  echo "## Machine"
  echo
  echo "- CPU: $cpu"
  echo "- \`nproc\`: $(nproc 2>/dev/null || echo unknown), \`uname -m\`: $(uname -m)"
  echo "- compiler: $(${CC:-cc} --version 2>/dev/null | head -1)"
  echo "- the machine may have been running other work: CPU times are medians of $REPS repetitions;"
  echo "  compare them within one table."
  echo
  section slider_crank_flexible "Flexible slider-crank (models/slider_crank_flexible.yaml, $END s)"
  for v in $vehicles; do
    n=$(basename "$v" .yaml)
    section "$n" "Vehicle ($v, $END s)"
  done
  [ -n "$vehicles" ] || { echo "## Vehicle"; echo; echo "Not yet: there is no vehicle model in models/; \`make trade\` adds it when there is."; echo; }
  method
} >"$tmp"
mv "$tmp" "$OUT"
say "wrote $OUT"
