#!/bin/bash
# Runs one campaign's runs as a SLURM job array: task k makes the k-th run
# folder of `make campaign-list CAMPAIGN=<name>`, exactly as `make
# campaign-<name>` would (same folder, same command, skipped when done,
# resumed from its checkpoint when resubmitted).
#
#   make build                                  # once, on the login node
#   n=$(make -s campaign-list CAMPAIGN=inertial N=1000 STRAIN=5 | wc -l)
#   sbatch --array=1-$n configs/cluster/job-array.sh inertial N=1000 STRAIN=5
#
# The first argument is the campaign (inertial, cohesive, angularity); the
# others are make variables and must be the same in both commands. Samples
# (prep/ns_*) are shared by several runs: the first task to need one makes
# it while the others wait on a lock.
#SBATCH --job-name=cdlab
#SBATCH --cpus-per-task=2
#SBATCH --time=12:00:00
#SBATCH --output=outputs/campaigns/slurm-%A_%a.log
set -euo pipefail
campaign=${1:?usage: job-array.sh CAMPAIGN [VAR=value ...]}
shift
cd "${SLURM_SUBMIT_DIR:-.}"
run=$(make -s campaign-list CAMPAIGN="$campaign" "$@" | sed -n "${SLURM_ARRAY_TASK_ID:?not in a job array}p")
[ -n "$run" ] || { echo "job-array.sh: no run number $SLURM_ARRAY_TASK_ID in campaign $campaign" >&2; exit 2; }
export OMP_NUM_THREADS=${SLURM_CPUS_PER_TASK:-1}
mkdir -p outputs/campaigns
flock outputs/campaigns/.prep.lock make -s "$@" "$(make -s campaign-prep-of RUN="$run" "$@")"
make "$@" "$run/.done"
