#!/usr/bin/env bash
# A real Slurm in CI: Debian's slurm-wlm and munge on a one-node cluster on localhost (munged,
# slurmctld, slurmd; a minimal slurm.conf in a temporary folder), the scripts `scatterfit slurm`
# writes submitted as they are, and their results compared with the one-machine runs:
#   - a small Monte Carlo table at g = 0.9 as an 8-task job array + combine job: byte for byte;
#     then resubmitted with one partial file deleted: only that shard runs again;
#   - a small batch (three rig-twin samples) as a 2-task array + combine job: the same
#     summary.csv and summary.md.
# Bounded: the cluster must come up within 30 s and the jobs finish within 180 s. If the daemons
# cannot run here the test fails and says why; it never passes without having run. The daemons are
# stopped and the folder removed on exit (trap).
#
# Usage (as root, from the repository): .ci/slurm-test.sh   (called by .ci/run)
set -euo pipefail
cd "$(dirname "$0")/.."
REPO="$PWD"

fail() {
  echo "slurm-test: FAILED: $*" >&2
  exit 1
}

# --- Slurm and munge from Debian --------------------------------------------------------------
need=()
for b in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
  command -v "$b" >/dev/null 2>&1 || need+=("$b")
done
if [ "${#need[@]}" -gt 0 ]; then
  [ "$(id -u)" = 0 ] || fail "${need[*]} missing and this is not root: install Debian's slurm-wlm and munge"
  echo "== installing slurm-wlm and munge (apt)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
fi
[ "$(id -u)" = 0 ] || fail "the test cluster's daemons run as root here (SlurmUser=root); run as root"

# `.ci/run` hands over the binary `cargo test --workspace` built (SCATTERFIT_BIN): `cargo build -p
# scatterfit` alone unifies other features than the workspace's tests and recompiled half the
# workspace here (2.5 min of CI). Run on its own, the script builds it.
if [ -n "${SCATTERFIT_BIN:-}" ]; then
  SF="$SCATTERFIT_BIN"
else
  echo "== building scatterfit"
  cargo build -p scatterfit --quiet
  SF="$REPO/target/debug/scatterfit"
fi
[ -x "$SF" ] || fail "no binary at $SF"

# --- the cluster -----------------------------------------------------------------------------
T="$(mktemp -d /tmp/scatterfit-slurm.XXXXXX)"
chmod 755 "$T"
stop() {
  local rc=$?
  for d in slurmd slurmctld munged; do
    if [ -f "$T/$d.pid" ]; then
      kill "$(cat "$T/$d.pid")" 2>/dev/null || true
    fi
  done
  sleep 1
  if [ "$rc" != 0 ]; then
    for log in munged slurmctld slurmd; do
      [ -f "$T/$log.log" ] && { echo "--- $log.log (last lines)" >&2; tail -n 15 "$T/$log.log" >&2; }
    done
    for f in "$T"/work/parts*/logs/*.out; do
      [ -f "$f" ] && { echo "--- $f" >&2; tail -n 15 "$f" >&2; }
    done
  fi
  rm -rf "$T"
  exit "$rc"
}
trap stop EXIT INT TERM

NODE="$(hostname -s)"
CPUS="$(nproc)"
MEM_MB="$(awk '/MemTotal/ {print int($2 / 1024 / 2)}' /proc/meminfo)"
# Ports away from a real installation's 6817/6818.
PORT_CTLD=16817
PORT_D=16818
mkdir -p "$T/state" "$T/spool" "$T/work"

echo "== munged"
mungekey --create --keyfile="$T/munge.key" >/dev/null 2>&1 || dd if=/dev/urandom of="$T/munge.key" bs=128 count=1 status=none
chmod 600 "$T/munge.key"
munged --force --socket="$T/munge.sock" --key-file="$T/munge.key" --log-file="$T/munged.log" \
  --pid-file="$T/munged.pid" --seed-file="$T/munged.seed" ||
  fail "munged does not start (see munged.log below)"
munge -n --socket="$T/munge.sock" | unmunge --socket="$T/munge.sock" >/dev/null ||
  fail "munge cannot encode and decode a credential"

cat >"$T/slurm.conf" <<EOF
ClusterName=scatterfitci
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$PORT_CTLD
SlurmdPort=$PORT_D
AuthType=auth/munge
AuthInfo=socket=$T/munge.sock
CredType=cred/munge
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/slurmctld.log
SlurmdLogFile=$T/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
ReturnToService=2
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=ci Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$T/slurm.conf"

echo "== slurmctld, slurmd"
slurmctld -f "$SLURM_CONF" || fail "slurmctld does not start (see slurmctld.log below)"
slurmd -f "$SLURM_CONF" -N "$NODE" || fail "slurmd does not start (see slurmd.log below)"
up=""
for _ in $(seq 30); do
  state="$(sinfo -h -N -o %T 2>/dev/null || true)"
  if [ "$state" = idle ]; then
    up=1
    break
  fi
  sleep 1
done
[ -n "$up" ] || fail "the node is not idle after 30 s (sinfo says: ${state:-nothing})"
sinfo

W="$T/work"
cd "$W"

# --- a small table at g = 0.9, 8 shards ------------------------------------------------------
# 16 albedos, 2·10⁵ full-length photons (the fewest at which the lowest albedos at g = 0.9 still
# smooth): a few seconds on two cores.
TABLE=(--eta 1.3 --g 0.9 --albedos 16 --photons 2e5)
echo "== table on one machine"
"$SF" table "${TABLE[@]}" --cache-dir "$W/cache-one" -o "$W/table-one.json" --quiet >/dev/null
echo "== table as a Slurm job array"
"$SF" slurm table "${TABLE[@]}" --cache-dir "$W/cache-slurm" -o "$W/table-slurm.json" \
  --partial-dir "$W/parts-table" --array 8 --script "$W/table.sh" >/dev/null
bash "$W/table.sh"

# --- a small batch, 2 shards -----------------------------------------------------------------
echo "== batch samples (rig twin, quick)"
for m in pink-plastic marble sulfur; do
  "$SF" synth --material "$m" --quick -o "$W/one/$m" --seed 3 --quiet >/dev/null 2>&1 ||
    "$SF" synth --material "$m" --quick -o "$W/one/$m" --seed 3 >/dev/null
done
cp -r "$W/one" "$W/sharded"
"$SF" batch "$W"/one/* -o "$W/batch-one" --quiet >/dev/null || true
"$SF" slurm batch "$W"/sharded/* -o "$W/batch-slurm" --partial-dir "$W/parts-batch" --array 2 \
  --script "$W/batch.sh" >/dev/null
bash "$W/batch.sh"

# --- wait, bounded ---------------------------------------------------------------------------
echo "== waiting for the jobs (at most 180 s)"
done=""
for _ in $(seq 180); do
  if [ -z "$(squeue -h 2>/dev/null)" ]; then
    done=1
    break
  fi
  sleep 1
done
[ -n "$done" ] || {
  squeue >&2
  fail "the jobs did not finish within 180 s"
}

# --- compare ---------------------------------------------------------------------------------
[ -f "$W/table-slurm.json" ] || fail "the combine job wrote no table (its log is below)"
cmp "$W/table-one.json" "$W/table-slurm.json" ||
  fail "the table combined from 8 Slurm shards differs from the one-machine table"
n_parts="$(ls "$W"/parts-table/table-*-of-0008.json | wc -l)"
[ "$n_parts" = 8 ] || fail "expected 8 partial files, found $n_parts"
echo "table: 8 shards under Slurm = one machine, byte for byte ($(stat -c %s "$W/table-one.json") bytes)"

# --- resubmitted after a lost shard: only that shard runs again ------------------------------
touch -d '2000-01-01' "$W"/parts-table/*.json
lost="$(ls "$W"/parts-table/table-*-0005-of-0008.json)"
rm "$lost" "$W/table-slurm.json"
echo "== table script resubmitted without shard 5/8"
bash "$W/table.sh"
done=""
for _ in $(seq 120); do
  if [ -z "$(squeue -h 2>/dev/null)" ]; then
    done=1
    break
  fi
  sleep 1
done
[ -n "$done" ] || fail "the resubmitted jobs did not finish within 120 s"
[ -f "$lost" ] || fail "the resubmitted array did not redo shard 5/8"
redone="$(find "$W/parts-table" -name 'table-*.json' -newermt '2001-01-01' | wc -l)"
[ "$redone" = 1 ] || fail "the resubmitted array redid $redone shards, not 1"
skipped="$(grep -l 'matches; nothing to do' "$W"/parts-table/logs/table-*-*.out | wc -l)"
[ "$skipped" = 7 ] || fail "$skipped array tasks said their shard was done, not 7"
cmp "$W/table-one.json" "$W/table-slurm.json" ||
  fail "the table combined after the resubmission differs from the one-machine table"
echo "table: resubmitted, 1 shard redone, 7 skipped, the same table again"

# Table 1 without its fitting-time column (wall-clock, different on every run): fit_time_s in the
# CSV, "Fitting time" (the 7th cell) in the Markdown; the samples' folders one/ and sharded/ named
# alike.
untimed() {
  case "$1" in
    *.csv) awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "fit_time_s") c = i }
                             { if (c) $c = ""; print }' "$1" ;;
    *.md) awk -F'|' -v OFS='|' 'NF > 9 { $8 = "" } { print }' "$1" ;;
  esac | sed -e "s#$W/one#SAMPLES#g" -e "s#$W/sharded#SAMPLES#g" -e 's#one/#SAMPLES/#g' -e 's#sharded/#SAMPLES/#g'
}
for f in summary.csv summary.md; do
  [ -f "$W/batch-slurm/$f" ] || fail "the batch's combine job wrote no $f (its log is below)"
  diff <(untimed "$W/batch-one/$f") <(untimed "$W/batch-slurm/$f") ||
    fail "the batch's $f from 2 Slurm shards differs from the one-machine batch's"
done
echo "batch: 2 shards under Slurm = one machine (summary.csv, summary.md)"
echo "slurm-test: ok"
