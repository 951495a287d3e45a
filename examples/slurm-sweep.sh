#!/usr/bin/env bash
# A coin-log sweep as a Slurm job array: each array task records its shard of the runs into DIR.
#
# Submit it from a login node, with coin-log on every node's PATH and DIR on a file system every node
# shares, then merge the shards' catalogue parts once every task has succeeded:
#
#     jid=$(sbatch --parsable --array=0-15 examples/slurm-sweep.sh SWEEP.toml DIR)
#     sbatch --dependency=afterok:"${jid%%;*}" --kill-on-invalid-dep=yes --job-name=coin-log-collect \
#         --output=collect-%j.out --wrap "coin-log sweep collect DIR"
#
# The array's size is the number of shards: coin-log sweep reads SLURM_ARRAY_TASK_ID and
# SLURM_ARRAY_TASK_COUNT (or MIN and MAX) when --shard is not given, and a run's parameters depend only on
# the sweep file and its index, so any array size gives the same catalogue. A task that fails (or a node
# lost) is redone by submitting the same array again (`sbatch --array=0-15 ...`, then collect as above):
# every task resumes, keeping the runs already on disk, and the tasks that were done find nothing to do. (An
# array of that index alone would be an array of one task, which makes the whole sweep and writes no part,
# unless it is given its shard: `sbatch --array=7 examples/slurm-sweep.sh SWEEP.toml DIR --shard 7/16`.)
# Arguments after DIR go to coin-log sweep as they are.
# With afterok, collect runs only if every task succeeded; --kill-on-invalid-dep cancels it otherwise,
# instead of leaving it pending forever. A task also fails (exit 1) when some of its runs failed for their
# values (`failure` scene, numerical or verify in its part): those recur, so run `coin-log sweep collect DIR`
# yourself then; it writes the catalogue with those rows (and exits 1 too).
#
# Adjust the #SBATCH lines to your cluster (partition, account, time limit); more CPUs per task make each
# task record that many runs at once.
#SBATCH --job-name=coin-log-sweep
#SBATCH --cpus-per-task=1
#SBATCH --mem-per-cpu=1G
#SBATCH --time=01:00:00
#SBATCH --output=coin-log-sweep-%A_%a.out
set -euo pipefail

[ $# -ge 2 ] || { echo "usage: sbatch --array=0-N examples/slurm-sweep.sh SWEEP.toml DIR [SWEEP OPTION]..." >&2; exit 2; }
[ -n "${SLURM_ARRAY_TASK_ID:-}" ] || { echo "not an array task: submit with sbatch --array=0-N" >&2; exit 2; }

# COIN_LOG: another coin-log binary (a build of your own, or a stand-in in a test).
# --jobs: the CPUs Slurm gave this task, not the node's cores (unless the cluster binds tasks to them,
# coin-log would see every core of the node).
exec "${COIN_LOG:-coin-log}" sweep "$1" -o "$2" --jobs "${SLURM_CPUS_PER_TASK:-1}" "${@:3}"
