#!/usr/bin/env bash
# Submits a scene as a Slurm job array of N shards and a merge job that runs when all
# shards have succeeded:
#   bash scripts/slurm/submit.sh SCENE N [SBATCH OPTIONS...]
# Options after N go to both sbatch calls, e.g. --partition=short --account=myproject.
# Logs: atlas/logs/rubber-atlas-<job>_<task>.out and atlas/logs/rubber-atlas-merge-<job>.out.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bash scripts/slurm/submit.sh SCENE N [SBATCH OPTIONS...]" >&2
  exit 2
fi
scene="$1" count="$2"
shift 2
here="$(dirname "${BASH_SOURCE[0]}")"
# Nothing is queued for a scene the program refuses, or a shard count that does not tile its
# grid (shards are boxes of it): the program says why, in one line.
"${RUBBER_ATLAS_BIN:-target/release/rubber-atlas}" run "$scene" --shard "1/$count" --print-out >/dev/null
mkdir -p atlas/logs
jobid=$(sbatch --parsable --array=1-"$count" "$@" "$here/atlas.sbatch" "$scene")
echo "submitted shards: job array $jobid (1-$count)"
sbatch --dependency=afterok:"$jobid" --job-name=rubber-atlas-merge --output='atlas/logs/%x-%j.out' \
  "$@" "$here/atlas.sbatch" --merge "$scene" "$count"
