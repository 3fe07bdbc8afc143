#!/usr/bin/env bash
# End-to-end test of workflow/profiles/slurm on a one-node SLURM cluster (issue 17):
# start munged + slurmctld + slurmd on loopback, run the tiny study locally (reference) and
# through the slurm profile, compare tables and results byte for byte, count the SLURM
# jobs, stop the daemons (also on failure or Ctrl-C).
#
#   apt-get install -y slurm-wlm munge            # Debian 12: Slurm 22.05
#   .venv/bin/pip install -e '.[cluster]'          # snakemake-executor-plugin-slurm
#   tests/cluster/run_tiny_on_slurm.sh [OUT]       # OUT default /tmp/gaitval-slurm-test
#
# Reuse an existing local reference run instead of running it again:
#   LOCAL_REF=/path/with/results_and_reports tests/cluster/run_tiny_on_slurm.sh
# Needs root (slurmd launches the jobs).  Takes ~5-10 min on 2 busy cores.
set -euo pipefail

REPO=$(cd "$(dirname "$0")/../.." && pwd)
OUT=${1:-/tmp/gaitval-slurm-test}
PY="$REPO/.venv/bin/python"
SM="$REPO/.venv/bin/snakemake"
export GAITVAL_SLURM_DIR="$OUT/cluster"
CLUSTER="$REPO/tests/cluster/slurm_one_node.sh"

mkdir -p "$OUT"
trap '"$CLUSTER" stop' EXIT
"$CLUSTER" start
eval "$("$CLUSTER" env)"

# --- local reference ------------------------------------------------------------------
LOCAL=${LOCAL_REF:-$OUT/local}
if [ -z "${LOCAL_REF:-}" ]; then
    rm -rf "$LOCAL"; mkdir -p "$LOCAL/work"
    echo "== local run (profile default, fork server on) -> $LOCAL"
    t0=$(date +%s)
    nice -n 10 "$SM" -s "$REPO/Snakefile" --directory "$LOCAL/work" \
        --profile "$REPO/workflow/profiles/default" \
        --config 'run=["tiny"]' "results_dir=$LOCAL/results" "reports_dir=$LOCAL/reports" \
        > "$OUT/local.log" 2>&1
    echo "local wall time: $(( $(date +%s) - t0 )) s"
fi

# --- SLURM run --------------------------------------------------------------------------
# A --config on the command line replaces the profile's `config:` list, so fork_server=False
# is given again here.  No slurmdbd on this test cluster: sacct answers "Slurm accounting
# storage is disabled", so job status comes from squeue (MinJobAge=3600 keeps finished jobs
# visible); a short first status check because the tiny study's jobs take seconds.
SL="$OUT/slurm"
rm -rf "$SL"; mkdir -p "$SL/work"
echo "== SLURM run (profile slurm) -> $SL"
t0=$(date +%s)
nice -n 10 "$SM" -s "$REPO/Snakefile" --directory "$SL/work" \
    --profile "$REPO/workflow/profiles/slurm" \
    --config 'run=["tiny"]' fork_server=False "results_dir=$SL/results" "reports_dir=$SL/reports" \
    --slurm-status-command squeue --slurm-init-seconds-before-status-checks 5 \
    --slurm-logdir "$SL/slurm-logs" --slurm-keep-successful-logs \
    --latency-wait 10 \
    > "$OUT/slurm.log" 2>&1 || { echo "SLURM run failed, tail of $OUT/slurm.log:"; tail -n 40 "$OUT/slurm.log"; exit 1; }
wall=$(( $(date +%s) - t0 ))
echo "SLURM wall time: $wall s"

# --- what ran where ---------------------------------------------------------------------
submitted=$(grep -c "with external jobid" "$OUT/slurm.log" || true)
local_jobs=$(grep -c "^localrule " "$OUT/slurm.log" || true)
completed=$(grep -c "JobState=COMPLETED" "$GAITVAL_SLURM_DIR/jobcomp.log" || true)
failed=$(grep -v -c "JobState=COMPLETED" "$GAITVAL_SLURM_DIR/jobcomp.log" || true)
echo "Snakemake jobs submitted to SLURM: $submitted; run locally (localrules): $local_jobs"
echo "slurmctld job completion log: $completed COMPLETED, $failed other"
echo "squeue --states=all (as sacct would list them):"
squeue --states=all --noheader -o '%i %j %T %M' | awk '{print $3}' | sort | uniq -c
echo "jobs per rule (from the SLURM logs):"
find "$SL/slurm-logs" -name '*.log' | sed -E 's|.*/rule_([^/]+)/.*|\1|' | sort | uniq -c
# every job on the node ran plain `python -m gaitval` (no fork server on the cluster)
if grep -rq "forkclient" "$SL/slurm-logs"; then
    echo "ERROR: a SLURM job used the fork client"; exit 1
fi
echo "plain 'python -m gaitval' in $(grep -rl -- "-m gaitval" "$SL/slurm-logs" | wc -l) job logs, forkclient in none"

# --- byte-for-byte comparison ----------------------------------------------------------
"$PY" "$REPO/tests/cluster/compare_runs.py" "$LOCAL" "$SL" --run tiny
