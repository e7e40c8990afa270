#!/usr/bin/env bash
# tools/slurm/sweep.sh on a one-node Slurm cluster started here on localhost: munged, slurmctld and slurmd run by
# hand (no systemd) from a generated slurm.conf in a scratch directory, and are stopped on every exit. A small sweep
# runs as 3 array tasks and a dependent merge; its sweep.csv must equal the unsharded run's byte for byte once the
# timing columns (the only run-specific ones) are cut from both, and so must report.json without its timings. A
# sweep whose shards fail must not merge, and sweep.sh --wait must say so.
#
# Usage: slurm_sweep_test.sh TRM REPO. Exit 77 (ctest SKIP_RETURN_CODE) only when the daemons cannot start here,
# printing why; any other failure is a failure.
set -euo pipefail
trm=$(realpath "${1:?usage: slurm_sweep_test.sh TRM REPO}")
repo=$(realpath "${2:?usage: slurm_sweep_test.sh TRM REPO}")
skip=77

for tool in munged munge slurmctld slurmd sbatch sinfo python3; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is missing (tools/setup.sh installs slurm-wlm and munge)"; exit 1; }
done

scratch=$(mktemp -d "${TMPDIR:-/tmp}/trm-slurm-test.XXXXXX")
daemons=()
cleanup() {
  local pid
  for pid in "${daemons[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${daemons[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$scratch"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

cannot_start() {
  echo "SKIP: $1; the Slurm test needs munged, slurmctld and slurmd running on localhost. Last log lines:"
  tail -n 15 "$scratch"/log/* 2>/dev/null || true
  exit "$skip"
}

mkdir -p "$scratch"/{log,state,spool}
chmod 700 "$scratch"

# munge: a fresh key and a socket of its own, so that a munged of the machine (if any) is not touched.
head -c 1024 /dev/urandom >"$scratch/munge.key"
chmod 400 "$scratch/munge.key"
socket="$scratch/munge.socket"
# --force: the key, socket and seed live in this scratch directory instead of munge's own /etc and /run paths,
# whose ownership checks munged would otherwise apply.
munged --foreground --force --key-file="$scratch/munge.key" --socket="$socket" --pid-file="$scratch/munged.pid" \
  --seed-file="$scratch/munged.seed" --log-file="$scratch/log/munged.log" >"$scratch/log/munged.out" 2>&1 &
daemons+=($!)
for _ in $(seq 50); do [[ -S "$socket" ]] && break; kill -0 "${daemons[0]}" 2>/dev/null || break; sleep 0.2; done
[[ -S "$socket" ]] || cannot_start "munged did not create its socket"
munge --socket="$socket" --no-input | unmunge --socket="$socket" >/dev/null 2>&1 ||
  cannot_start "munged does not answer on its socket"

# Two free TCP ports on localhost (a connection that fails means nobody listens there).
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
ports=()
while ((${#ports[@]} < 2)); do
  candidate=$((20000 + RANDOM % 20000))
  if port_free "$candidate" && [[ " ${ports[*]} " != *" $candidate "* ]]; then ports+=("$candidate"); fi
done

user=$(id -un)
host=$(hostname -s)
export SLURM_CONF="$scratch/slurm.conf"
cat >"$SLURM_CONF" <<CONF
ClusterName=trmtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=${ports[0]}
SlurmdPort=${ports[1]}
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/slurmctld.pid
SlurmdPidFile=$scratch/slurmd.pid
SlurmctldLogFile=$scratch/log/slurmctld.log
SlurmdLogFile=$scratch/log/slurmd.log
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
NodeName=trmnode NodeHostname=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=trm Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -D -i -f "$SLURM_CONF" >"$scratch/log/slurmctld.out" 2>&1 &
daemons+=($!)
slurmd -D -N trmnode -f "$SLURM_CONF" >"$scratch/log/slurmd.out" 2>&1 &
daemons+=($!)
state=""
for _ in $(seq 60); do
  state=$(sinfo -h -n trmnode -o %t 2>/dev/null || true)
  [[ "$state" == idle ]] && break
  kill -0 "${daemons[1]}" 2>/dev/null || cannot_start "slurmctld exited"
  kill -0 "${daemons[2]}" 2>/dev/null || cannot_start "slurmd exited"
  sleep 0.5
done
[[ "$state" == idle ]] || cannot_start "the node did not come up idle (sinfo says '${state:-nothing}')"

# The sweep: three knobs at a tiny size, rejected values among them (linear_frac_bits 16), 31 rows.
options=(--quick --size 24x16 --hw-size 24x16 --knob linear_frac_bits --knob residual_bits --knob exp_entries)
work="$scratch/work"
"$trm" sweep "${options[@]}" -o "$work/sweep" >"$scratch/log/single.out" 2>&1 ||
  { cat "$scratch/log/single.out"; echo "FAIL: the unsharded sweep failed"; exit 1; }
mv "$work/sweep" "$scratch/single"  # the merge then writes where the single run did, so their commands match

if ! "$repo/tools/slurm/sweep.sh" --shards 3 --trm "$trm" --wait "$work" "${options[@]}"; then
  tail -n 30 "$work"/logs/* || true
  echo "FAIL: the Slurm array sweep did not complete"
  exit 1
fi
for k in 1 2 3; do
  [[ -f "$work/parts/part-$k/sweep-part.json" ]] || { echo "FAIL: array task $k wrote no part"; exit 1; }
done

# sweep.csv without its timing columns, and report.json without its timings, byte for byte.
python3 - "$scratch/single" "$work/sweep" "$scratch" <<'PY'
import csv, json, sys
single, merged, scratch = sys.argv[1:4]
timing_columns = {"seconds_per_frame", "min_seconds_per_frame", "reference_seconds_per_frame", "setup_seconds",
                  "eye_seconds_per_frame"}
def without_timing_columns(directory, name):
    with open(f"{directory}/sweep.csv", newline="") as f:
        rows = list(csv.reader(f))
    keep = [i for i, column in enumerate(rows[0]) if column not in timing_columns]
    assert len(keep) == len(rows[0]) - len(timing_columns), rows[0]
    with open(f"{scratch}/{name}.csv", "w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows([[row[i] for i in keep] for row in rows])
    return len(rows) - 1
def without_timings(value):
    if isinstance(value, dict):
        # The Pareto fronts against time are as run-specific as the times.
        timed_front = "time" in str(value.get("chart", ""))
        return {k: without_timings(v) for k, v in value.items()
                if k not in ("time", "reference_seconds_per_frame", "wall_seconds") and not (timed_front and k == "front")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value
rows = without_timing_columns(single, "single")
assert without_timing_columns(merged, "merged") == rows
assert rows == 31, rows
for name in ("single", "merged"):
    with open(f"{scratch}/{name}.json", "w") as out:
        directory = single if name == "single" else merged
        json.dump(without_timings(json.load(open(f"{directory}/report.json"))), out, indent=1)
PY
cmp "$scratch/single.csv" "$scratch/merged.csv" || { echo "FAIL: merged sweep.csv differs from the unsharded run's"; exit 1; }
cmp "$scratch/single.json" "$scratch/merged.json" || { echo "FAIL: merged report.json differs from the unsharded run's"; exit 1; }
# A shard that fails (here every one: an unknown scene) cancels the merge, and --wait says so.
if "$repo/tools/slurm/sweep.sh" --shards 2 --trm "$trm" --wait "$scratch/failing" --quick --scene nosuchscene \
     >"$scratch/log/failing.out" 2>&1; then
  cat "$scratch/log/failing.out"
  echo "FAIL: sweep.sh --wait succeeded although its shards failed"
  exit 1
fi
grep -q "did not complete" "$scratch/log/failing.out" || { cat "$scratch/log/failing.out"; echo "FAIL: no error message"; exit 1; }
grep -q "unknown scene 'nosuchscene'" "$scratch/failing/logs/shard-1.out" ||
  { cat "$scratch/failing/logs/shard-1.out"; echo "FAIL: the shard's log lacks trm's error"; exit 1; }
[[ ! -e "$scratch/failing/sweep" ]] || { echo "FAIL: a merge ran after failed shards"; exit 1; }
echo "PASS: 3 Slurm array tasks and their merge reproduce the unsharded sweep (31 rows); failed shards cancel the merge"
