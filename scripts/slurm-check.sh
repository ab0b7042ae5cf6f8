#!/usr/bin/env bash
# slurm-check.sh (make slurm-check): the job-array script of `mbcc sweep
# --slurm` on a real, single-node Slurm.  In a scratch directory it starts
# munged with a fresh key, slurmctld and slurmd on this machine from a
# minimal generated slurm.conf (its own ports, spool and state directories;
# no cgroups, no accounting), submits the array of a 2 x 2 sweep of
# tests/models/sweep_oscillator.yaml with sbatch (--test-only first, then for
# real, waiting), merges it and compares the merged CSV with the same sweep
# run by GNU parallel: they must be identical.  Everything it started is
# stopped at the end.  Needs Debian slurm-wlm and munge (not part of
# `make test`: scripts/install-deps.sh does not install them).
# Environment: MBCC (default build/mbcc).  Exit 0 = pass.
set -u
cd "$(dirname "$0")/.." || exit 1
root=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC="$root/$MBCC" ;; esac
[ -x "$MBCC" ] || { echo "slurm-check: no mbcc at $MBCC (make first)"; exit 1; }
for tool in munged slurmctld slurmd sbatch squeue parallel; do
  command -v "$tool" > /dev/null || PATH=$PATH:/usr/sbin
  command -v "$tool" > /dev/null || { echo "slurm-check: '$tool' is missing: apt-get install slurm-wlm munge parallel"; exit 1; }
done
tmp=$(mktemp -d /tmp/mbcc-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
stop() {
  for p in "${pids[@]}"; do kill "$p" 2> /dev/null; done
  sleep 1
  for p in "${pids[@]}"; do kill -9 "$p" 2> /dev/null; done
  [ -n "${KEEP:-}" ] || rm -rf "$tmp"
}
trap stop EXIT
fail() { echo "slurm-check: FAIL: $*"; for f in "$tmp"/*.log; do [ -f "$f" ] && { echo "--- $f"; tail -15 "$f"; }; done; exit 1; }

# munge: a key of our own, a socket in the scratch directory
dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 status=none
chmod 600 "$tmp/munge.key"
munged --foreground --force --key-file="$tmp/munge.key" --socket="$tmp/munge.sock" \
  --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" > "$tmp/munged.out.log" 2>&1 &
pids+=($!)

# slurm.conf: this host, ports away from a system Slurm's
host=$(hostname -s)
port=$((17000 + RANDOM % 2000))
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" <<CONF
ClusterName=mbcccheck
SlurmctldHost=$host
SlurmUser=$(id -un)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$tmp/munge.sock
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf
for i in $(seq 50); do [ -S "$tmp/munge.sock" ] && break; sleep 0.1; done
[ -S "$tmp/munge.sock" ] || fail "munged did not start"
slurmctld -D -i -f "$SLURM_CONF" > "$tmp/slurmctld.out.log" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" > "$tmp/slurmd.out.log" 2>&1 &
pids+=($!)
up=
for i in $(seq 60); do
  if sinfo -h -o '%T' 2> /dev/null | grep -Eq '^(idle|mixed)'; then up=1; break; fi
  sleep 0.5
done
[ -n "$up" ] || fail "the node did not come up: $(sinfo 2>&1 | tail -3)"
echo "slurm-check: slurmctld and slurmd up on $host (port $port)"

# the same sweep: GNU parallel, then the Slurm array
osc=$root/tests/models/sweep_oscillator.yaml
cd "$tmp" || exit 1
"$MBCC" sweep "$osc" --vary k=100,400 --vary L0=0.9,0.8 --metric v:max --metric x:min \
  --dir par --csv parallel.csv --quiet 2> par.log || fail "the GNU parallel sweep: $(cat par.log)"
"$MBCC" sweep "$osc" --vary k=100,400 --vary L0=0.9,0.8 --metric v:max --metric x:min \
  --dir arr --slurm array.sh --quiet 2> arr.log || fail "writing the job array: $(cat arr.log)"
sbatch --test-only array.sh > test-only.log 2>&1 || fail "sbatch --test-only: $(cat test-only.log)"
echo "slurm-check: sbatch --test-only: $(grep -o 'to start.*' test-only.log | head -1)"
timeout 300 sbatch --wait array.sh > sbatch.log 2>&1 || fail "sbatch --wait: $(cat sbatch.log)"
"$MBCC" sweep --merge arr --metric v:max --metric x:min --csv slurm.csv --quiet 2> merge.log ||
  fail "merging the Slurm runs: $(cat merge.log)"
rows=$(($(wc -l < slurm.csv) - 1))
[ "$rows" = 4 ] || fail "the Slurm sweep merged $rows rows, expected 4"
cmp -s parallel.csv slurm.csv || fail "the Slurm array's merged CSV differs from GNU parallel's: $(diff parallel.csv slurm.csv)"
echo "slurm-check: the job array ran its 4 tasks on Slurm; the merged CSV equals GNU parallel's"
