#!/bin/bash
# Queues a sharded verification: an N-task job array (one shard each) and a merge job that
# runs after every task has ended. Prints the two job ids ("ARRAY_ID MERGE_ID").
#   deploy/slurm/submit.sh N OUT [SUITE [FILTER]]
# FLEXVERIFY (default: target/release/flexverify) and OUT must be on a shared filesystem.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=${1:?usage: submit.sh N OUT [SUITE [FILTER]]}
out=$(realpath -m "${2:?usage: submit.sh N OUT [SUITE [FILTER]]}")
suite=${3:-quick}
flexverify=$(realpath "${FLEXVERIFY:-target/release/flexverify}")
case $n in '' | *[!0-9]* | 0) echo "submit.sh: N must be a whole number >= 1" >&2; exit 2 ;; esac
mkdir -p "$out/shards" "$out/logs"
rm -rf "$out/shards/"* "$out/merged"
vars="ALL,FLEXVERIFY=$flexverify,SUITE=$suite,OUT=$out"
if [ $# -ge 4 ]; then vars="$vars,FILTER=$4"; fi
array=$(sbatch --parsable --chdir="$out/logs" --array="0-$((n - 1))" --export="$vars" \
    "$here/verify-shard.sbatch")
merge=$(sbatch --parsable --chdir="$out/logs" --dependency="afterany:$array" --export="$vars" \
    "$here/merge.sbatch")
echo "$array $merge"
