#!/usr/bin/env bash
# A sweep through a real single-node Slurm: starts munge (if not running), slurmctld and slurmd on
# this machine with a private configuration under a scratch directory, submits the job array
# `monolith sweep --emit-slurm` writes, waits for it, collects the table and checks it equals the
# table of the same sweep run locally (same state hashes and check errors). Stops the daemons it
# started (by their pid files). Exit 77 (ctest: skipped) where Slurm or munge is not installed.
# usage: tests/support/slurm_round_trip.sh MONOLITH_BINARY SCENE_DIR [SCRATCH_DIR]
set -euo pipefail
monolith=$1
scenes=$2
scratch=${3:-}
own_scratch=""
if [ -z "$scratch" ]; then scratch=$(mktemp -d /tmp/monolith_slurm.XXXXXX); own_scratch=yes; fi
for tool in slurmctld slurmd sbatch munged; do
  command -v "$tool" >/dev/null || { echo "skipped: $tool not installed (apt-get install slurm-wlm munge)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "skipped: starting slurmd needs root"; exit 77; }
mkdir -p "$scratch/state" "$scratch/spool"
conf=$scratch/slurm.conf
host=$(hostname -s)
cpus=$(nproc)
cat > "$conf" <<CONF
ClusterName=monolith
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/slurmctld.log
SlurmdLogFile=$scratch/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=monolith Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$conf

started_munge=""
if ! { [ -f /run/munge/munged.pid ] && kill -0 "$(cat /run/munge/munged.pid)" 2>/dev/null; }; then
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
  runuser -u munge -- /usr/sbin/munged
  started_munge=yes
fi
stop() {
  for f in "$scratch/slurmd.pid" "$scratch/slurmctld.pid"; do
    [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null || true
  done
  if [ -n "$started_munge" ] && [ -f /run/munge/munged.pid ]; then kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true; fi
  if [ -n "$own_scratch" ]; then sleep 1; rm -rf "$scratch"; fi
}
trap stop EXIT
slurmctld -f "$conf"
slurmd -f "$conf"
up=""
for _ in $(seq 1 60); do
  if sinfo -h -o %T 2>/dev/null | grep -q idle; then up=yes; break; fi
  sleep 0.5
done
if [ -z "$up" ]; then  # the machine cannot run the daemons (e.g. a restricted container)
  echo "skipped: the single-node Slurm did not come up in 30 s"
  tail -5 "$scratch/slurmctld.log" "$scratch/slurmd.log" 2>/dev/null || true
  exit 77
fi
sinfo -h -o "%P %T %c" || true

sweep=("$scenes/spin_sliver.json" --vary time.dt=1/30,1/60 --vary solvers.rigid_rotation.order=1,2,3 --set time.end=1)
"$monolith" sweep "${sweep[@]}" --out "$scratch/local" 2>/dev/null
"$monolith" sweep "${sweep[@]}" --out "$scratch/cluster" --emit-slurm
start=$SECONDS
timeout 200 sbatch --wait --chdir="$scratch" "$scratch/cluster/sweep.slurm"
echo "array job done in $((SECONDS - start)) s"
"$monolith" sweep --collect "$scratch/cluster"
# Compare every column but the timings.
columns() { cut -d, -f1-7,10- "$1"; }
if diff <(columns "$scratch/local/sweep.csv") <(columns "$scratch/cluster/sweep.csv"); then
  echo "slurm round trip: the collected table equals the local one ($(($(wc -l < "$scratch/local/sweep.csv") - 1)) rows)"
else
  echo "slurm round trip: tables differ"; exit 1
fi
