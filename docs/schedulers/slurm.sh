#!/usr/bin/env bash
# Precompute the mode banks of an asset library as a Slurm job array.
#
#   sbatch docs/schedulers/slurm.sh library.toml /shared/banks
#
# Every array task runs one shard: modal reads SLURM_ARRAY_TASK_ID,
# SLURM_ARRAY_TASK_MIN, SLURM_ARRAY_TASK_STEP and SLURM_ARRAY_TASK_COUNT itself
# (shard = (TASK_ID - TASK_MIN) / TASK_STEP, of TASK_COUNT), so the --array
# range may start at 0 or 1 and have a step (0-14:2); a list (3,5,7) is refused.
# The job's --mem is not what modal sees as free memory: set
# MODAL_MEMORY_LIMIT_GB below it, so an asset too large fails alone.
# All tasks write into one output directory (each its own
# catalogue-shard-I-of-N.json) and share one cache on the shared file system:
# a re-submitted or requeued task skips what is already finished.
#
#SBATCH --job-name=modal-banks
#SBATCH --array=0-7
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=04:00:00
#SBATCH --requeue
#SBATCH --output=modal-banks-%A_%a.log

set -euo pipefail

MANIFEST=${1:?usage: sbatch slurm.sh MANIFEST OUT_DIR}
OUT=${2:?usage: sbatch slurm.sh MANIFEST OUT_DIR}
# One cache for all tasks, on the shared file system (atomic renames, no locks).
export MODAL_CACHE_DIR=${MODAL_CACHE_DIR:-$OUT/.cache}
# The memory guard: 3 of the job's 4 GB (--mem above).
export MODAL_MEMORY_LIMIT_GB=${MODAL_MEMORY_LIMIT_GB:-3}

# One asset at a time per task, two solver threads (the --cpus-per-task above).
# Exit code 1 means some assets failed: the task is marked FAILED, the good
# banks and the catalogue with every error message are written regardless.
modal precompute-batch "$MANIFEST" --out "$OUT" --jobs 1 --threads "${SLURM_CPUS_PER_TASK:-1}"

# After the whole array finished (e.g. a dependent job:
#   sbatch --dependency=afterany:$SLURM_ARRAY_JOB_ID --wrap "modal catalogue merge $OUT -o $OUT/catalogue.json"
# ), join the shards' catalogues:
#   modal catalogue merge "$OUT" -o "$OUT/catalogue.json"
