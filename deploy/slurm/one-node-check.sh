#!/bin/bash
# Brings up a one-node Slurm on this machine (munged, slurmctld and slurmd on localhost, all
# state under $WORK), runs a sharded verification through it (submit.sh: job array + dependent
# merge), runs the same selection unsharded, and compares the two reports (JSON and CSV with
# the wall-time fields removed). Exit 0 only if they are identical and both runs agree on the
# exit status. Needs root and Debian's slurm-wlm (apt-get install -y slurm-wlm).
#   deploy/slurm/one-node-check.sh [N [FILTER [SUITE]]]     (defaults: 3 cantilever quick)
# Container-friendly configuration (no systemd, no cgroup hierarchy to delegate):
# ProctrackType=proctrack/linuxproc, TaskPlugin=task/none, JobAcctGatherType=jobacct_gather/none;
# the daemons run in the foreground-less "-D &" style under this script and are stopped at exit.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
n=${1:-3}
filter=${2-cantilever}
suite=${3:-quick}
WORK=${WORK:-/tmp/flexverify-slurm}
export FLEXVERIFY=${FLEXVERIFY:-$repo/target/release/flexverify}
[ -x "$FLEXVERIFY" ] || { echo "build first: cargo build --release -p verify" >&2; exit 2; }
command -v slurmctld >/dev/null || { echo "install slurm-wlm first" >&2; exit 2; }

node=$(hostname -s)
cpus=$(nproc)
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
rm -rf "$WORK"
mkdir -p "$WORK"/{state,spool,log,munge,run}
conf=$WORK/slurm.conf
cat > "$conf" <<CONF
ClusterName=flexverify-local
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/run/slurmctld.pid
SlurmdPidFile=$WORK/run/slurmd.pid
SlurmctldLogFile=$WORK/log/slurmctld.log
SlurmdLogFile=$WORK/log/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
NodeName=$node CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$conf

# munge: a fresh key, its own socket; root may run munged only with --force.
mungekey --create --keyfile "$WORK/munge/munge.key" --force
chmod 600 "$WORK/munge/munge.key"
munged --force --key-file "$WORK/munge/munge.key" --socket "$WORK/munge/munge.socket" \
    --pid-file "$WORK/munge/munged.pid" --log-file "$WORK/munge/munged.log" \
    --seed-file "$WORK/munge/munged.seed"
# Slurm's auth/munge plugin finds the socket through AuthInfo.
sed -i "s|^AuthType=auth/munge|AuthType=auth/munge\nAuthInfo=socket=$WORK/munge/munge.socket|" "$conf"

pids=()
stop() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    [ -f "$WORK/munge/munged.pid" ] && kill "$(cat "$WORK/munge/munged.pid")" 2>/dev/null || true
}
trap stop EXIT
slurmctld -D -f "$conf" >"$WORK/log/slurmctld.stdout" 2>&1 &
pids+=($!)
slurmd -D -f "$conf" >"$WORK/log/slurmd.stdout" 2>&1 &
pids+=($!)
for _ in $(seq 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then break; fi
    sleep 1
done
echo "== sinfo"
sinfo

out=$WORK/sharded
echo "== submit: $n shards of verify --suite $suite --filter '$filter'"
read -r array merge < <(cd "$repo" && "$here/submit.sh" "$n" "$out" "$suite" "$filter")
echo "array job $array, merge job $merge (afterany:$array)"
while squeue -h -j "$array,$merge" 2>/dev/null | grep -q .; do sleep 1; done
echo "== jobs (no accounting database: scontrol while they are remembered)"
for j in $(seq 0 $((n - 1))); do
    scontrol show job "${array}_$j" | grep -oE '(^| )(JobId|ArrayJobId|ArrayTaskId|JobState|ExitCode|NodeList)=[^ ]*' | tr '\n' ' '
    echo
done
scontrol show job "$merge" | grep -oE '(^| )(JobId|JobState|ExitCode|Dependency)=[^ ]*' | tr '\n' ' '
echo
ls "$out/logs"
merge_status=$(grep -o 'merged from [0-9]* shards' "$out/logs/fv-merge-$merge.out" || true)
echo "merge log: $merge_status"
tail -n 2 "$out/logs/fv-merge-$merge.out"

echo "== single run"
set +e
"$FLEXVERIFY" verify --suite "$suite" --filter "$filter" --format csv --out "$WORK/single" \
    >"$WORK/single.csv" 2>"$WORK/single.err"
single_code=$?
set -e
# Finished jobs stay visible to scontrol for MinJobAge (300 s): the merge job's exit status.
merged_code=$(scontrol show job "$merge" | grep -o ' ExitCode=[0-9]*' | cut -d= -f2)

strip_json() { grep -v '"wall_time_s"' "$1"; }
strip_csv() {
    python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1], newline="")))
w = rows[0].index("wall [s]")
for r in rows:
    print(r[:w] + r[w + 1:])
PY
}
status=0
if diff <(strip_json "$WORK/single/verification.json") <(strip_json "$out/merged/verification.json") >/dev/null; then
    echo "verification.json: identical apart from wall_time_s"
else
    echo "verification.json: DIFFERS"; status=1
fi
if diff <(strip_csv "$WORK/single/verification.csv") <(strip_csv "$out/merged/verification.csv") >/dev/null; then
    echo "verification.csv: identical apart from the wall column"
else
    echo "verification.csv: DIFFERS"; status=1
fi
# Full suite: the refinement ladders (ladders/converge-*.json and .csv) without their timings.
strip_study() {
    python3 - "$1" <<'PY'
import csv, json, sys
path = sys.argv[1]
if path.endswith(".json"):
    def strip(v):
        if isinstance(v, dict):
            return {k: strip(x) for k, x in v.items() if k not in ("wall_time_s", "timing")}
        if isinstance(v, list):
            return [strip(x) for x in v]
        return v
    print(json.dumps(strip(json.load(open(path))), sort_keys=True, indent=1))
else:
    timing = {"wall_s", "wall_median_s", "wall_max_s", "repeats", "spread"}
    rows = list(csv.reader(open(path, newline="")))
    keep = [i for i, h in enumerate(rows[0]) if h not in timing]
    for r in rows:
        print([r[i] for i in keep])
PY
}
single_ladders=$(cd "$WORK/single" && ls ladders/*.json ladders/*.csv 2>/dev/null || true)
merged_ladders=$(cd "$out/merged" && ls ladders/*.json ladders/*.csv 2>/dev/null || true)
if [ "$single_ladders" != "$merged_ladders" ]; then
    echo "ladders: the runs wrote different files"; status=1
elif [ -n "$single_ladders" ]; then
    same=0
    for f in $single_ladders; do
        if diff <(strip_study "$WORK/single/$f") <(strip_study "$out/merged/$f") >/dev/null; then
            same=$((same + 1))
        else
            echo "$f: DIFFERS"; status=1
        fi
    done
    echo "ladders: $same of $(echo "$single_ladders" | wc -w) files identical apart from timings"
fi
rows=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))))' "$out/merged/verification.json")
echo "rows: $rows; single run exit $single_code, merge job exit $merged_code"
[ "$single_code" = "$merged_code" ] || { echo "exit statuses differ"; status=1; }
exit $status
