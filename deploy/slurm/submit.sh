#!/bin/bash
# Submits one photonflow run as a Slurm job array of N shards and a merge job that starts
# when every shard succeeded (--dependency=afterok). Prints the two job ids.
#
#   deploy/slurm/submit.sh N SHARD_DIR RESULT -- COMMAND...
#
# COMMAND is a photonflow command without --shard and --out, e.g.
#   render scenes/cornell-spheres/analytic.toml --method path --spp 4096
#   trace scenes/cornell-spheres/analytic.toml --photons 100000000
# Shard I of N goes to SHARD_DIR/shard-I-of-N; the merge writes RESULT (a run directory for
# images, a cache directory for photon sets). SHARD_DIR must be on a file system every node
# sees. PHOTONFLOW names the binary (default: photonflow on PATH); extra sbatch options (a
# partition, a time limit) go in SBATCH_* variables, which sbatch reads itself.
set -euo pipefail
if [ $# -lt 5 ] || [ "$4" != "--" ]; then
    echo "usage: $0 N SHARD_DIR RESULT -- COMMAND..." >&2
    exit 2
fi
n=$1 dir=$2 result=$3
shift 4
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$dir"
# Every job reads its settings from the environment it is submitted with (sbatch exports it).
export PF_SHARDS=$n PF_SHARD_DIR=$dir PF_RESULT=$result PF_COMMAND="$*"
array=$(sbatch --parsable --array="0-$((n - 1))" --output="$dir/slurm-%A_%a.out" \
    "$here/shard.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable --dependency="afterok:$array" --output="$dir/slurm-merge-%j.out" \
    "$here/merge.sbatch")
echo "$array ${merge%%;*}"
