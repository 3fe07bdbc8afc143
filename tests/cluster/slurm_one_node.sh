#!/usr/bin/env bash
# A one-node SLURM cluster on loopback for testing workflow/profiles/slurm (issue 17).
#
#   tests/cluster/slurm_one_node.sh start   # munged + slurmctld + slurmd, waits for the node
#   eval "$(tests/cluster/slurm_one_node.sh env)"   # SLURM_CONF and PATH for sbatch/squeue
#   tests/cluster/slurm_one_node.sh status  # sinfo + squeue
#   tests/cluster/slurm_one_node.sh stop    # stops the three daemons it started (by pid file)
#
# Needs root and the Debian packages slurm-wlm (22.05) and munge:
#   apt-get install -y slurm-wlm munge
# Everything (slurm.conf, munge key and socket, state, spool, logs, pid files) lives in
# $GAITVAL_SLURM_DIR (default /tmp/gaitval-slurm); the system's /etc/slurm, /etc/munge and
# any running munged/slurmd are left alone.  Every finished job is written to
# $GAITVAL_SLURM_DIR/jobcomp.log (JobCompType=jobcomp/filetxt).
#
# Accounting: by default none (no slurmdbd), so `sacct` answers "Slurm accounting storage
# is disabled" and Snakemake must poll with squeue (--slurm-status-command squeue).  With
# GAITVAL_SLURM_DBD=1 the script also starts a MariaDB server and slurmdbd in the same
# folder (apt-get install -y slurmdbd mariadb-server), registers the cluster, an account
# `gaitval` and root in it: then sacct works as on a real cluster (job count, MaxRSS,
# Elapsed per job) and the executor can check `slurm_account`.
set -euo pipefail

DIR=${GAITVAL_SLURM_DIR:-/tmp/gaitval-slurm}
CTLD_PORT=${GAITVAL_SLURMCTLD_PORT:-16817}
SLURMD_PORT=${GAITVAL_SLURMD_PORT:-16818}
CPUS=${GAITVAL_SLURM_CPUS:-$(nproc)}
DBD=${GAITVAL_SLURM_DBD:-0}
DBD_PORT=${GAITVAL_SLURMDBD_PORT:-16819}
DB_PORT=${GAITVAL_SLURM_MARIADB_PORT:-16306}

write_conf() {
    mkdir -p "$DIR"/state "$DIR"/spool "$DIR"/munge "$DIR"/log
    chmod 700 "$DIR"/munge
    # RealMemory: what is available now minus a 2 GB margin for everything else.
    local avail_mb
    avail_mb=$(awk '/MemAvailable/ {print int($2/1024)}' /proc/meminfo)
    local real_mb=$((avail_mb - 2048))
    [ "$real_mb" -gt 1024 ] || real_mb=1024
    local ACCOUNTING="AccountingStorageType=accounting_storage/none"
    if [ "$DBD" = 1 ]; then
        ACCOUNTING="AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=localhost
AccountingStoragePort=$DBD_PORT
# the munge socket for talking to slurmdbd (AuthInfo covers slurmctld/slurmd only)
AccountingStoragePass=$DIR/munge/munge.socket"
    fi
    cat > "$DIR/slurm.conf" <<EOF
# Written by tests/cluster/slurm_one_node.sh -- a one-node test cluster on loopback.
ClusterName=gaitval-test
SlurmctldHost=localhost
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
AuthInfo=socket=$DIR/munge/munge.socket
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
ReturnToService=2
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
$ACCOUNTING
# a finished job stays visible to squeue for MinJobAge seconds -- long enough for
# Snakemake's status checks when there is no accounting database
JobAcctGatherType=jobacct_gather/linux
JobAcctGatherFrequency=5
# no cgroups here: jobacct_gather polls each step's memory and kills a step over its --mem,
# so a too small mem_mb in the profile fails the test as it would on a real cluster
JobAcctGatherParams=OverMemoryKill
JobCompType=jobcomp/filetxt
JobCompLoc=$DIR/jobcomp.log
MinJobAge=3600
# the node's own /tmp, as on most clusters
TmpFS=/tmp
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$real_mb State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
}

start_dbd() {  # MariaDB + slurmdbd in $DIR; the cluster, account `gaitval`, root in it
    command -v slurmdbd >/dev/null && command -v mariadbd >/dev/null \
        || { echo "GAITVAL_SLURM_DBD=1 needs: apt-get install -y slurmdbd mariadb-server" >&2; exit 2; }
    local db="$DIR/mysql"
    mkdir -p "$db"
    if [ ! -d "$db/data/mysql" ]; then
        mariadb-install-db --no-defaults --datadir="$db/data" --user=root \
            --auth-root-authentication-method=normal --skip-test-db > "$DIR/log/mariadb-install.log" 2>&1
    fi
    setsid mariadbd --no-defaults --datadir="$db/data" --socket="$db/mysqld.sock" \
        --port="$DB_PORT" --bind-address=127.0.0.1 --user=root --pid-file="$db/mariadbd.pid" \
        --log-error="$DIR/log/mariadbd.log" --innodb-buffer-pool-size=64M \
        < /dev/null > /dev/null 2>&1 &
    for _ in $(seq 1 60); do
        mariadb-admin --no-defaults --socket="$db/mysqld.sock" -u root ping >/dev/null 2>&1 && break
        sleep 1
    done
    mariadb --no-defaults --socket="$db/mysqld.sock" -u root -e "
        CREATE USER IF NOT EXISTS 'slurm'@'localhost' IDENTIFIED BY 'slurm';
        CREATE USER IF NOT EXISTS 'slurm'@'127.0.0.1' IDENTIFIED BY 'slurm';
        GRANT ALL ON slurm_acct_db.* TO 'slurm'@'localhost';
        GRANT ALL ON slurm_acct_db.* TO 'slurm'@'127.0.0.1';"
    # slurmdbd reads slurmdbd.conf beside $SLURM_CONF (mode 600, owned by SlurmUser)
    printf '%s\n' "AuthType=auth/munge" "AuthInfo=socket=$DIR/munge/munge.socket" \
        "DbdHost=localhost" "DbdPort=$DBD_PORT" "SlurmUser=root" \
        "LogFile=$DIR/log/slurmdbd.log" "PidFile=$DIR/slurmdbd.pid" \
        "StorageType=accounting_storage/mysql" "StorageHost=127.0.0.1" \
        "StoragePort=$DB_PORT" "StorageUser=slurm" "StoragePass=slurm" \
        "StorageLoc=slurm_acct_db" > "$DIR/slurmdbd.conf"
    chmod 600 "$DIR/slurmdbd.conf"
    slurmdbd
    for _ in $(seq 1 60); do
        sacctmgr -n list cluster >/dev/null 2>&1 && break
        sleep 1
    done
    sacctmgr -i add cluster gaitval-test >/dev/null
    sacctmgr -i add account gaitval Description=gaitval-test Organization=gaitval >/dev/null
    sacctmgr -i add user root Account=gaitval >/dev/null
    echo "slurmdbd up (MariaDB on 127.0.0.1:$DB_PORT): account gaitval, user root"
}

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

start() {
    command -v slurmctld >/dev/null || { echo "slurmctld not found: apt-get install -y slurm-wlm munge" >&2; exit 2; }
    if pid_alive "$DIR/slurmctld.pid"; then
        echo "already running in $DIR (stop first)" >&2; exit 1
    fi
    write_conf
    # snakemake-executor-plugin-slurm-jobstep (0.6.1) drops every SLURM_* variable, SLURM_CONF
    # too, before it calls `srun` inside the job, so srun would look for /etc/slurm/slurm.conf.
    # A real cluster has its slurm.conf there (or configless); this test cluster keeps it in
    # $DIR, so $DIR/bin (put first on PATH by `env` and the run script) has srun/sbatch/...
    # shims that set SLURM_CONF.
    mkdir -p "$DIR/bin"
    for tool in srun sbatch squeue sacct scancel scontrol sinfo; do
        printf '#!/bin/sh\nSLURM_CONF=%s exec /usr/bin/%s "$@"\n' "$DIR/slurm.conf" "$tool" > "$DIR/bin/$tool"
        chmod +x "$DIR/bin/$tool"
    done
    [ -s "$DIR/munge/munge.key" ] || dd if=/dev/urandom of="$DIR/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$DIR/munge/munge.key"
    munged --force --key-file="$DIR/munge/munge.key" --socket="$DIR/munge/munge.socket" \
        --pid-file="$DIR/munge/munged.pid" --log-file="$DIR/log/munged.log" \
        --seed-file="$DIR/munge/munged.seed"
    export SLURM_CONF="$DIR/slurm.conf"
    if [ "$DBD" = 1 ]; then start_dbd; fi
    # -c: a clean start (no jobs/state carried over from an earlier test)
    slurmctld -c -f "$DIR/slurm.conf"
    slurmd -f "$DIR/slurm.conf" -N localhost
    for _ in $(seq 1 60); do
        if sinfo -h -N -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then
            echo "SLURM up: SLURM_CONF=$DIR/slurm.conf"
            sinfo -N -o '%N %T %c %m'
            return 0
        fi
        sleep 1
    done
    echo "the node did not come up; logs in $DIR/log:" >&2
    tail -n 20 "$DIR"/log/*.log >&2
    exit 1
}

stop_one() {  # pid file, name
    if pid_alive "$1"; then
        local pid; pid=$(cat "$1")
        kill "$pid"
        for _ in $(seq 1 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.5; done
        kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
        echo "stopped $2 ($pid)"
    fi
    rm -f "$1"
}

stop() {
    stop_one "$DIR/slurmd.pid" slurmd
    stop_one "$DIR/slurmctld.pid" slurmctld
    stop_one "$DIR/slurmdbd.pid" slurmdbd
    stop_one "$DIR/mysql/mariadbd.pid" mariadbd
    stop_one "$DIR/munge/munged.pid" munged
}

case "${1:-}" in
    start) start ;;
    stop) stop ;;
    env) echo "export SLURM_CONF=$DIR/slurm.conf PATH=$DIR/bin:\$PATH" ;;
    status) SLURM_CONF="$DIR/slurm.conf" sinfo -N; SLURM_CONF="$DIR/slurm.conf" squeue ;;
    *) sed -n '2,16p' "$0"; exit 2 ;;
esac
