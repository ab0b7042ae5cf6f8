#!/usr/bin/env bash
# test_sweep.sh: `mbcc sweep` (exit 0 = pass):
#   - bad input (no --vary, a malformed value list, a range in a full
#     design, an unknown design) is an "error:" with exit status 2;
#   - a full design over the run-time stiffness k and free length L0 of an
#     oscillator, compiled once and run by GNU parallel: the merged CSV has
#     one row per variant, and each row's largest speed is the closed form
#     (1 - L0) sqrt(k/m) and its shortest position L0 - (1 - L0);
#   - the merged values equal those of the same variants run one by one
#     with mbcc run --set (the same compiled code: bit for bit);
#   - a Latin hypercube puts exactly one sample in each of N strata of
#     every variable; one at a time varies one variable per run;
#   - a run that fails (an unknown parameter) is reported and marked, the
#     sweep exits 1;
#   - the Slurm job array, run task by task as Slurm would (the
#     SLURM_ARRAY_TASK_ID of each), gives the same merged CSV;
#   - GNU parallel over ssh to localhost, when an sshd can be started here.
# Runs in a scratch directory.  Environment: MBCC (default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
osc="$root/tests/models/sweep_oscillator.yaml"
command -v parallel >/dev/null || { echo "FAIL: GNU parallel is not installed (scripts/install-deps.sh)"; exit 1; }

# 1. bad input
bad() {
  "$MBCC" sweep "$osc" "$@" --quiet >out.txt 2>err.txt
  st=$?
  [ $st = 2 ] || err "mbcc sweep $* exited $st, expected 2"
  grep -q "error:" err.txt || err "mbcc sweep $*: no 'error:' message"
}
bad
bad --vary k=1,x
bad --vary k=10:1:3
bad --vary k=1:10
bad --vary k=1:10:3 --design nope
bad --vary k=1,2 --vary k=3
# a value that breaks the rule of the field the parameter sets (the spring's
# stiffness >= 0), though k has no min: refused before any run
bad --vary k=-5,100 --dir rule
grep -q "sweep_oscillator.yaml:19:16: error: run 1 of the sweep (--vary k=-5): 'stiffness' of force 'spring' would be -5, but it must be >= 0" err.txt ||
  err "sweep --vary k=-5,100: not the field's rule: $(cat err.txt)"
[ -e rule/jobs.txt ] && err "sweep --vary k=-5,100 wrote a job list"

# 2. a full design, run by GNU parallel; speeds against the closed form
"$MBCC" sweep "$osc" --vary k=100,400,900 --vary L0=0.9,0.8 --metric v:max --metric x:min \
  --dir sw --csv full.csv --jobs 2 --quiet 2>err.txt
st=$?
[ $st = 0 ] || err "the full sweep exited $st: $(cat err.txt)"
rows=$(($(wc -l <full.csv) - 1))
[ "$rows" = 6 ] || err "the full sweep merged $rows rows, expected 6"
head -1 full.csv | grep -qx 'run,k,L0,status,v.max,x.min' || err "merged header: $(head -1 full.csv)"
awk -F, 'NR > 1 {
  want = (1 - $3) * sqrt($2 / 1.0); xmin = $3 - (1 - $3)
  if ($4 != "ok" || ($5 - want) / want > 1e-3 || ($5 - want) / want < -1e-3) { print "run " $1 ": v.max " $5 " want " want; bad = 1 }
  if ($6 - xmin > 1e-4 || $6 - xmin < -1e-4) { print "run " $1 ": x.min " $6 " want " xmin; bad = 1 } }
  END { exit bad }' full.csv || err "merged speeds differ from (1 - L0) sqrt(k/m)"

# 3. the same variants one by one with mbcc run --set: identical values
for r in 2 5; do
  line=$(sed -n "$((r + 1))p" full.csv)
  k=$(echo "$line" | cut -d, -f2); L0=$(echo "$line" | cut -d, -f3)
  "$MBCC" run "$osc" --set "k=$k" --set "L0=$L0" -o one.csv --plot none --quiet 2>err.txt ||
    err "mbcc run --set k=$k --set L0=$L0 failed: $(cat err.txt)"
  vmax=$(awk -F, 'NR == 1 { for (j = 1; j <= NF; j++) if ($j == "v") c = j; next }
                  NR == 2 || $c > v { v = $c } END { printf "%.17g", v }' one.csv)
  got=$(echo "$line" | cut -d, -f5)
  awk -v a="$vmax" -v b="$got" 'BEGIN { exit !(a == b) }' ||
    err "run $r: the sweep's v.max $got differs from mbcc run's $vmax"
done

# 4. Latin hypercube: one sample per stratum; one at a time
"$MBCC" sweep "$osc" --vary k=100:900 --vary L0=0.5:0.9 --design lhs --samples 8 --seed 7 \
  --dir lhs --csv lhs.csv --metric v:max --quiet 2>err.txt || err "the lhs sweep failed: $(cat err.txt)"
for col in 2 3; do
  lo=$([ $col = 2 ] && echo 100 || echo 0.5); hi=$([ $col = 2 ] && echo 900 || echo 0.9)
  strata=$(awk -F, -v c=$col -v lo=$lo -v hi=$hi 'NR > 1 { print int(($c - lo) / (hi - lo) * 8) }' lhs.csv | sort -n | tr '\n' ' ')
  [ "$strata" = "0 1 2 3 4 5 6 7 " ] || err "lhs column $col: strata $strata, expected one in each of 0..7"
done
"$MBCC" sweep "$osc" --vary k=100,400,900 --vary L0=0.7,0.8,0.9 --design oat --dir oat --csv oat.csv \
  --metric v:max --quiet 2>err.txt || err "the oat sweep failed: $(cat err.txt)"
# the baseline is the model's (k 100, L0 0.9), then k over 400 and 900, then L0 over 0.7 and 0.8
[ "$(cut -d, -f2,3 oat.csv | tail -n +2 | tr '\n' ' ')" = "100,0.9 400,0.9 900,0.9 100,0.7 100,0.8 " ] ||
  err "oat design: $(cut -d, -f2,3 oat.csv | tail -n +2 | tr '\n' ' ')"

# 5. a failing run: reported, marked failed, exit 1
"$MBCC" sweep "$osc" --vary k=100,400 --vary no_such_parameter=1 --dir failing --csv failing.csv \
  --quiet 2>err.txt
st=$?
[ $st = 1 ] || [ $st = 2 ] || err "a sweep whose runs fail exited $st, expected 1 or 2"
grep -q "no_such_parameter" err.txt || err "the failing runs' reason is not reported: $(cat err.txt)"

# 6. the Slurm job array, each task run as Slurm would
"$MBCC" sweep "$osc" --vary k=100,400,900 --vary L0=0.9,0.8 --metric v:max --metric x:min \
  --dir slurm --slurm array.sh --quiet 2>err.txt || err "writing the Slurm script failed: $(cat err.txt)"
grep -q '^#SBATCH --array=1-6$' array.sh || err "the Slurm script's array: $(grep array array.sh)"
bash -n array.sh || err "the Slurm script is not valid bash"
for id in 1 2 3 4 5 6; do SLURM_ARRAY_TASK_ID=$id bash array.sh || err "Slurm task $id failed"; done
"$MBCC" sweep --merge slurm --metric v:max --metric x:min --csv slurm.csv --quiet 2>err.txt ||
  err "merging the Slurm runs failed: $(cat err.txt)"
cmp -s slurm.csv full.csv || err "the Slurm array's merged CSV differs from GNU parallel's"
if command -v sbatch >/dev/null && sbatch --test-only array.sh >/dev/null 2>&1; then
  echo "note: sbatch --test-only accepts the script"
fi

# 7. GNU parallel over ssh to localhost, when an sshd can be started here
if command -v sshd >/dev/null || [ -x /usr/sbin/sshd ]; then
  sshd_bin=$(command -v sshd || echo /usr/sbin/sshd)
  mkdir -p ssh && chmod 700 ssh
  ssh-keygen -q -t ed25519 -N '' -f ssh/host >/dev/null && ssh-keygen -q -t ed25519 -N '' -f ssh/user >/dev/null
  cp ssh/user.pub ssh/authorized_keys
  port=$((20000 + RANDOM % 20000))
  cat >ssh/sshd_config <<EOC
Port $port
ListenAddress 127.0.0.1
HostKey $tmp/ssh/host
AuthorizedKeysFile $tmp/ssh/authorized_keys
PidFile $tmp/ssh/sshd.pid
StrictModes no
PasswordAuthentication no
UsePAM no
EOC
  [ -d /run/sshd ] || mkdir -p /run/sshd 2>/dev/null # sshd's privilege-separation directory
  if "$sshd_bin" -f ssh/sshd_config 2>ssh/sshd.err; then
    sleep 1
    login="ssh -p $port -i $tmp/ssh/user -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o LogLevel=ERROR $(whoami)@127.0.0.1"
    "$MBCC" sweep "$osc" --vary k=100,400,900 --vary L0=0.9,0.8 --metric v:max --metric x:min \
      --dir viassh --csv ssh.csv --sshlogin "$login" --quiet 2>err.txt || err "the sweep over ssh failed: $(cat err.txt)"
    cmp -s ssh.csv full.csv || err "the sweep over ssh differs from the local one"
    kill "$(cat ssh/sshd.pid)" 2>/dev/null
  else
    echo "note: sshd could not be started here ($(head -1 ssh/sshd.err)): the ssh mode is not tested"
  fi
else
  echo "note: no sshd: the ssh mode of GNU parallel is not tested"
fi
exit $fail
