#!/usr/bin/env bash
# Runs a small benchmark subset as a 4-task Slurm job array on a single-node Slurm started
# here (Debian's slurm-wlm and munge), merges the shards, and checks that the merged tables
# equal an unsharded local run of the same subset.
#
#   scripts/slurm-local.sh [NESY_BINARY] [SCENARIOS]
#
# NESY_BINARY defaults to target/release/nesy (built if missing); SCENARIOS to a dozen
# scenarios over every factor. Needs root (it starts munged, slurmctld and slurmd) and installs
# slurm-wlm and munge with apt-get when they are missing. Everything it writes stays under
# $WORK (default /tmp/nesy-slurm); the daemons are stopped on exit.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
nesy="${1:-$here/target/release/nesy}"
scenarios="${2:-obst_low_00_s0,obst_high_01_s1,affo_medium_00_s0,grip_low_02_s0,grip_medium_01_s1,comb_low_00_s0,obst_medium_03_s0,affo_low_04_s1,vacu_high_00_s1,vacu_low_03_s0,comb_medium_02_s1,affo_high_01_s0}"
methods="nesycr,imitation,replan"
work="${WORK:-/tmp/nesy-slurm}"
shards=4

say() { printf '[slurm-local] %s\n' "$*"; }

if [[ $(id -u) -ne 0 ]]; then
  echo "slurm-local.sh: needs root to start munged, slurmctld and slurmd" >&2
  exit 2
fi
if ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  say "installing slurm-wlm and munge"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q slurm-wlm munge >/dev/null
fi
if [[ ! -x "$nesy" ]]; then
  say "building $nesy"
  (cd "$here" && cargo build --release -p nesy-cli --locked)
fi
nesy="$(cd "$(dirname "$nesy")" && pwd)/$(basename "$nesy")"

rm -rf "$work"
mkdir -p "$work"/{state,spool,log}
conf="$work/slurm.conf"
node="$(hostname -s)"
cpus="$(nproc)"
mem_mb=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))

cleanup() {
  set +e
  [[ -n "${SLURM_CONF:-}" ]] && scancel --quiet --user=root 2>/dev/null
  for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid"; do
    [[ -f "$pidfile" ]] && kill "$(cat "$pidfile")" 2>/dev/null
  done
  [[ -f "$work/munge-run/munged.pid" ]] && kill "$(cat "$work/munge-run/munged.pid")" 2>/dev/null
}
trap cleanup EXIT

# munge: its own key, socket and seed under $work, owned by the munge user as munged insists
# (the key's folder private, the socket's folder searchable by every client).
mkdir -p "$work/munge-key" "$work/munge-run"
cp /etc/munge/munge.key "$work/munge-key/munge.key" 2>/dev/null \
  || dd if=/dev/urandom of="$work/munge-key/munge.key" bs=1 count=1024 status=none
touch "$work/log/munged.log"
chown -R munge:munge "$work/munge-key" "$work/munge-run" "$work/log/munged.log"
chmod 700 "$work/munge-key"
chmod 400 "$work/munge-key/munge.key"
chmod 755 "$work/munge-run"
runuser -u munge -- /usr/sbin/munged \
  --key-file="$work/munge-key/munge.key" \
  --socket="$work/munge-run/munge.socket" \
  --pid-file="$work/munge-run/munged.pid" \
  --log-file="$work/log/munged.log" \
  --seed-file="$work/munge-key/munge.seed"

# A single-node cluster: no cgroups (the container has none to give), linuxproc tracking.
cat >"$conf" <<EOF
ClusterName=nesy-local
SlurmctldHost=$node
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge-run/munge.socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
NodeName=$node CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$conf"

/usr/sbin/slurmctld -f "$conf"
/usr/sbin/slurmd -f "$conf"
for _ in $(seq 1 30); do
  if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then break; fi
  sleep 1
done
sinfo -h -o '%P %D %T %c' | sed 's/^/[slurm-local] sinfo: /'

demos="$work/demos"
run_args=(--methods "$methods" --scenarios "$scenarios" --vlm oracle --demos "$demos" --no-report)

# The demos first, so the array tasks do not all record the same ones at once.
say "recording the subset's demos"
"$nesy" bench demos --scenarios "$scenarios" --demos "$demos" >/dev/null

sharded="$work/run-sharded"
"$nesy" bench slurm "$sharded" --shards "$shards" --cpus 1 --mem 2G --time 00:30:00 \
  --nesy "$nesy" -- "${run_args[@]}"
say "submitting $sharded/slurm/run.sbatch as a $shards-task array"
sbatch --wait --parsable "$sharded/slurm/run.sbatch" >"$work/array.jobid"
say "array job $(cat "$work/array.jobid") finished"
for out in "$sharded"/slurm/*.out; do
  tail -n 1 "$out" | sed "s|^|[slurm-local] $(basename "$out"): |"
done

say "merging the shards"
"$nesy" bench merge "$sharded"

local_run="$work/run-local"
say "running the same subset unsharded"
"$nesy" bench run "$local_run" --methods "$methods" --scenarios "$scenarios" --vlm oracle \
  --demos "$demos" >/dev/null

# The result tables must be byte-identical; time.csv and the timing columns of units.csv
# (vlm_s, symbolic_s, sim_s, wall_s) are measurements of this machine and differ run to run.
status=0
for name in table1.csv status.csv domain_gap.csv; do
  if cmp -s "$local_run/tables/$name" "$sharded/tables/$name"; then
    say "tables/$name: identical"
  else
    say "tables/$name: DIFFERS"
    diff "$local_run/tables/$name" "$sharded/tables/$name" | head -20 || true
    status=1
  fi
done
if cmp -s <(cut -d, -f1-15,20- "$local_run/tables/units.csv") \
          <(cut -d, -f1-15,20- "$sharded/tables/units.csv"); then
  say "tables/units.csv without its timing columns: identical"
else
  say "tables/units.csv without its timing columns: DIFFERS"
  status=1
fi
if [[ $status -eq 0 ]]; then
  say "merged Slurm array = local run ($shards shards, $(tr ',' '\n' <<<"$scenarios" | wc -l) scenarios × 3 methods)"
fi
exit $status
