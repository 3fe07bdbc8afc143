#!/usr/bin/env bash
# End-to-end test of workflow/profiles/slurm on a one-node SLURM cluster (issue 17):
# start munged + slurmctld + slurmd on loopback (tests/cluster/slurm_one_node.sh), run the
# tiny study locally (reference) and through the slurm profile, compare tables and results
# byte for byte, list the SLURM jobs per rule, stop the daemons (also on failure or Ctrl-C).
#
#   apt-get install -y slurm-wlm munge             # Debian 12: Slurm 22.05
#   .venv/bin/pip install -e '.[cluster]'           # snakemake-executor-plugin-slurm
#   tests/cluster/run_tiny_on_slurm.sh [OUT]        # OUT default /tmp/gaitval-slurm-test
#
# With accounting, as on a real cluster (sacct for job status, account checked by sacctmgr):
#   apt-get install -y slurmdbd mariadb-server
#   GAITVAL_SLURM_DBD=1 tests/cluster/run_tiny_on_slurm.sh [OUT]
# Reuse an existing local reference run (folder with results/ and reports/):
#   LOCAL_REF=/path tests/cluster/run_tiny_on_slurm.sh [OUT]
# Needs root (slurmd launches the jobs).  Takes ~35 min on 2 busy cores (docs/cluster.md).
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
    echo "== local run (profile default) -> $LOCAL"
    t0=$(date +%s)
    nice -n 10 "$SM" -s "$REPO/Snakefile" --directory "$LOCAL/work" \
        --profile "$REPO/workflow/profiles/default" \
        --config 'run=["tiny"]' "results_dir=$LOCAL/results" "reports_dir=$LOCAL/reports" \
        > "$OUT/local.log" 2>&1
    echo "local wall time: $(( $(date +%s) - t0 )) s"
fi

# --- the site's profile: the repository's, account and partition filled in -------------
PROFILE="$OUT/site-profile"
mkdir -p "$PROFILE"
EXTRA=()
if [ "${GAITVAL_SLURM_DBD:-0}" = 1 ]; then
    # what a user does: copy the profile, fill in the placeholders
    sed -e "s|# slurm_account: \"'YOUR_ACCOUNT'\"|slurm_account: \"'gaitval'\"|" \
        -e "s|# slurm_partition: \"'YOUR_PARTITION'\"|slurm_partition: \"'debug'\"|" \
        "$REPO/workflow/profiles/slurm/config.yaml" > "$PROFILE/config.yaml"
    grep -q "^  slurm_account: \"'gaitval'\"" "$PROFILE/config.yaml" \
        || { echo "placeholders not found in workflow/profiles/slurm/config.yaml" >&2; exit 1; }
else
    cp "$REPO/workflow/profiles/slurm/config.yaml" "$PROFILE/config.yaml"
    # no slurmdbd: sacct answers "Slurm accounting storage is disabled"; poll with squeue
    # (MinJobAge=3600 keeps finished jobs visible to it)
    EXTRA=(--slurm-status-command squeue)
fi

# --- SLURM run --------------------------------------------------------------------------
# A short first status check: the tiny study's jobs take seconds.
SL="$OUT/slurm"
rm -rf "$SL"; mkdir -p "$SL/work"
echo "== SLURM run (profile slurm) -> $SL"
t0=$(date +%s)
nice -n 10 "$SM" -s "$REPO/Snakefile" --directory "$SL/work" --profile "$PROFILE" \
    --config 'run=["tiny"]' "results_dir=$SL/results" "reports_dir=$SL/reports" \
    --slurm-init-seconds-before-status-checks 5 "${EXTRA[@]}" \
    --slurm-logdir "$SL/slurm-logs" --slurm-keep-successful-logs \
    > "$OUT/slurm.log" 2>&1 || { echo "SLURM run failed, tail of $OUT/slurm.log:"; tail -n 40 "$OUT/slurm.log"; exit 1; }
wall=$(( $(date +%s) - t0 ))
echo "SLURM wall time: $wall s"

# --- what ran where ---------------------------------------------------------------------
echo "Snakemake jobs run locally by the main Snakemake (localrules): $(grep -c "^localrule " "$OUT/slurm.log" || true)"
echo "slurmctld job completion log: $(grep -c "JobState=COMPLETED" "$GAITVAL_SLURM_DIR/jobcomp.log" || true) COMPLETED, $(grep -v -c "JobState=COMPLETED" "$GAITVAL_SLURM_DIR/jobcomp.log" || true) other"
"$PY" "$REPO/tests/cluster/slurm_job_report.py" "$OUT/slurm.log"
# Every batch job ran its trials in its own process pool on the node: each batch job's log
# (logs/<rule>/...) starts with "N task(s) in P process(es)".
batches=$(grep -rl "task(s) in [0-9]* process(es)" "$SL/work/logs" | wc -l)
echo "batch job logs: $batches"
[ "$batches" -gt 0 ] || { echo "ERROR: no batch job log in $SL/work/logs"; exit 1; }
# sacct (with GAITVAL_SLURM_DBD=1): every job of the run, its state and elapsed time
if [ "${GAITVAL_SLURM_DBD:-0}" = 1 ]; then
    sacct --allusers --format=JobID,JobName%40,State,Elapsed,MaxRSS,AllocCPUS -X | tee "$OUT/sacct.txt"
fi

# --- byte-for-byte comparison ----------------------------------------------------------
"$PY" "$REPO/tests/cluster/compare_runs.py" "$LOCAL" "$SL" --run tiny
