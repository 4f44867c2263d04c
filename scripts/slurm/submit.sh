#!/usr/bin/env bash
# Submits a scene as a Slurm job array of N shards and a merge job that runs when all
# shards have succeeded:  bash scripts/slurm/submit.sh SCENE N
set -euo pipefail
scene="$1" count="$2"
here="$(dirname "${BASH_SOURCE[0]}")"
jobid=$(sbatch --parsable --array=1-"$count" "$here/atlas.sbatch" "$scene")
echo "submitted shards: job array $jobid (1-$count)"
sbatch --dependency=afterok:"$jobid" --job-name=rubber-atlas-merge "$here/atlas.sbatch" --merge "$scene" "$count"
