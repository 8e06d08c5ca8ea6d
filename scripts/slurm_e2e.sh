#!/usr/bin/env bash
# End-to-end check of docs/cluster.md's Slurm example on a one-node Slurm stood up on this machine.
# NOT run by CI: it needs root, installs Debian packages and starts daemons.
#
#   sudo scripts/slurm_e2e.sh            # SAMPLES=200 TIMEOUT=900 KEEP=0 by default
#
# What it does:
#  1. installs slurm-wlm and munge (apt-get) if slurmctld is missing;
#  2. builds pinfeed (cargo build --release) unless PINFEED names a binary, and puts it on PATH;
#  3. writes a private slurm.conf (in $STATE, default /tmp/pinfeed-slurm-e2e; /etc/slurm is not
#     touched) for this host with the cores and memory `slurmd -C` reports, and starts munged,
#     slurmctld and slurmd;
#  4. extracts the job script (mc.sh) and the submit commands from docs/cluster.md — the fenced blocks
#     after the markers `<!-- slurm_e2e: mc.sh -->` and `<!-- slurm_e2e: submit -->`, so what runs
#     here is what docs/cluster.md says — changing only the job's size: `--samples 100000` becomes
#     `--samples $SAMPLES` and `--cpus-per-task=4` becomes 1 (this node may have fewer than 4 cores);
#  5. in a scratch project root (a copy of studies/ and scenarios/, so results/ is not touched)
#     submits them as docs/cluster.md says, waits for the merge job with a bounded timeout, and compares the
#     merged report (report.md, report.json, sensitivity.svg) byte for byte with an unsharded
#     `pinfeed mc` run of the same study;
#  6. failure path: submits the same blocks in a scratch root without studies/, so every array task
#     fails, and checks that the merge job is cancelled (--kill-on-invalid-dep) instead of pending
#     forever;
#  7. stops the daemons it started (by their pid files) unless KEEP=1.
# Exit status 0 only if every step passed; the logs of a failed step are printed.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
SAMPLES=${SAMPLES:-200}
TIMEOUT=${TIMEOUT:-900}
STATE=${STATE:-/tmp/pinfeed-slurm-e2e}
KEEP=${KEEP:-0}
study=studies/quickstart_shape_tolerance.toml
report_dir=pinfeed-out/mc/quickstart-shape-tolerance

say() { printf '== %s\n' "$*"; }
die() {
    printf 'slurm_e2e: FAILED: %s\n' "$*" >&2
    exit 1
}

[ "$(id -u)" = 0 ] || die "run as root (installs packages, starts munged/slurmctld/slurmd)"

# 1. Packages.
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge"
    DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge
fi

# 2. pinfeed on PATH.
if [ -z "${PINFEED:-}" ]; then
    say "building pinfeed"
    (cd "$root" && cargo build --release --locked --bin pinfeed)
    PINFEED=$root/target/release/pinfeed
fi
[ -x "$PINFEED" ] || die "no pinfeed binary at $PINFEED"
bindir=$STATE/bin
mkdir -p "$bindir"
ln -sf "$PINFEED" "$bindir/pinfeed"
export PATH=$bindir:$PATH

# 3. A one-node cluster: this host, its cores and memory.
host=$(hostname -s)
node=$(slurmd -C | head -n1) # NodeName=HOST CPUs=.. Boards=.. ... RealMemory=..
cpus=$(sed -n 's/.*CPUs=\([0-9]*\).*/\1/p' <<<"$node")
mkdir -p "$STATE/ctld" "$STATE/d" "$STATE/log" "$STATE/run"
export SLURM_CONF=$STATE/slurm.conf
cat >"$SLURM_CONF" <<EOF
# Written by pinfeed's scripts/slurm_e2e.sh: a one-node cluster on $host.
ClusterName=pinfeed-e2e
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/d
SlurmctldPidFile=$STATE/run/slurmctld.pid
SlurmdPidFile=$STATE/run/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
$node State=UNKNOWN
PartitionName=e2e Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
# Older slurmd -C print an UpTime line too; the conf takes the first line only.

started=()
stop_daemons() {
    [ "$KEEP" = 1 ] && { say "KEEP=1: daemons left running (SLURM_CONF=$SLURM_CONF)"; return; }
    local pids=() pid
    for pidfile in "${started[@]}"; do
        if [ -s "$pidfile" ]; then
            pid=$(cat "$pidfile")
            kill "$pid" 2>/dev/null && pids+=("$pid")
        fi
    done
    # Wait (at most 30 s) until they have exited, so that a rerun can start its own.
    local alive
    for _ in $(seq 30); do
        alive=0
        for pid in "${pids[@]}"; do # an exited daemon not yet reaped shows as Z
            case "$(ps -o stat= -p "$pid" 2>/dev/null)" in "" | Z*) ;; *) alive=1 ;; esac
        done
        [ "$alive" = 0 ] && return 0
        sleep 1
    done
    echo "slurm_e2e: daemons ${pids[*]} still running after 30 s" >&2
}
trap stop_daemons EXIT

say "starting munged, slurmctld, slurmd (SLURM_CONF=$SLURM_CONF)"
if ! munge -n </dev/null >/dev/null 2>&1; then
    install -d -o munge -g munge -m 0755 /run/munge
    install -d -o munge -g munge -m 0700 /var/lib/munge /var/log/munge
    runuser -u munge -- /usr/sbin/munged
    started+=(/run/munge/munged.pid)
fi
munge -n </dev/null | unmunge >/dev/null || die "munge does not work"
if [ -s "$STATE/run/slurmctld.pid" ] && kill -0 "$(cat "$STATE/run/slurmctld.pid")" 2>/dev/null; then
    die "a slurmctld from an earlier run is still running (pid $(cat "$STATE/run/slurmctld.pid"))"
fi
slurmctld -i # -i: ignore state left by an earlier run
started+=("$STATE/run/slurmctld.pid")
slurmd
started+=("$STATE/run/slurmd.pid")
for _ in $(seq 60); do
    sinfo -h -n "$host" -o '%T' 2>/dev/null | grep -qE '^idle' && break
    sleep 1
done
sinfo -h -n "$host" -o '%T' | grep -qE '^idle' || {
    sinfo || true
    tail -n 30 "$STATE/log/slurmctld.log" "$STATE/log/slurmd.log" || true
    die "node $host did not come up idle"
}
say "node $host up: $cpus CPUs"

# 4. The blocks of docs/cluster.md.
block() { # the fenced block after the marker line `<!-- slurm_e2e: $1 -->`
    awk -v m="<!-- slurm_e2e: $1 -->" '
        $0 == m { armed = 1; next }
        armed == 1 && /^```/ { armed = 2; next }
        armed == 2 && /^```/ { exit }
        armed == 2 { print }' "$root/docs/cluster.md"
}
job=$(block mc.sh)
submit=$(block submit)
[ -n "$job" ] && [ -n "$submit" ] || die "docs/cluster.md has no slurm_e2e blocks"
grep -q -- '--samples 100000' <<<"$job" || die "the job in docs/cluster.md has no '--samples 100000' to shrink"
grep -q -- '--cpus-per-task=4' <<<"$job" || die "the job in docs/cluster.md has no '--cpus-per-task=4' to shrink"
job=$(sed -e "s/--samples 100000/--samples $SAMPLES/" -e 's/--cpus-per-task=4/--cpus-per-task=1/' <<<"$job")

# Wait until job $1 has left the queue (or TIMEOUT); print its final state.
wait_job() {
    local id=$1 deadline=$((SECONDS + TIMEOUT)) st
    while [ $SECONDS -lt $deadline ]; do
        st=$(scontrol show job -o "$id" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -n1)
        st=${st#JobState=}
        case "$st" in
        PENDING | RUNNING | CONFIGURING | COMPLETING | SUSPENDED | "") sleep 2 ;;
        *)
            echo "$st"
            return 0
            ;;
        esac
    done
    echo TIMEOUT
}

# Submit the blocks of docs/cluster.md from a scratch project root $1; print the merge job's final state.
run_readme_job() {
    local dir=$1
    printf '%s\n' "$job" >"$dir/mc.sh"
    # The submit block prints "Submitted batch job ID" for the merge job; then the array job's id.
    local out merge_id array_id
    out=$(cd "$dir" && bash -c "set -euo pipefail"$'\n'"$submit"$'\necho "$jobid"') ||
        die "the submit commands of docs/cluster.md failed in $dir"
    merge_id=$(head -n1 <<<"$out" | grep -oE '[0-9]+$') || die "no merge job id in: $out"
    array_id=$(tail -n1 <<<"$out")
    say "submitted array job $array_id and merge job $merge_id in $dir" >&2
    wait_job "$merge_id"
}

show_logs() {
    squeue || true
    for f in "$1"/logs/*; do
        [ -f "$f" ] && { echo "--- $f"; cat "$f"; }
    done
    tail -n 20 "$STATE/log/slurmctld.log" || true
}

# 5. Success path.
work=$(mktemp -d /tmp/pinfeed-slurm-e2e-work.XXXXXX)
cp -r "$root/studies" "$root/scenarios" "$work/"
say "docs/cluster.md job, --samples $SAMPLES, in $work"
t0=$SECONDS
state=$(run_readme_job "$work")
[ "$state" = COMPLETED ] || {
    show_logs "$work"
    die "merge job ended $state"
}
say "merge job COMPLETED after $((SECONDS - t0)) s"
nshards=$(ls "$work"/shards/shard-*-of-0008.json | wc -l)
[ "$nshards" = 8 ] || die "expected 8 shard files, found $nshards"

say "unsharded run"
# Into the same default folder (a report's command names its folder), the merged one moved aside.
mv "$work/$report_dir" "$work/merged"
(cd "$work" && pinfeed mc "$study" --samples "$SAMPLES" --quiet)
for f in report.md report.json sensitivity.svg; do
    cmp "$work/merged/$f" "$work/$report_dir/$f" ||
        die "$f: the merged report differs from the unsharded run ($work)"
done
say "merged report == unsharded report, byte for byte (report.md, report.json, sensitivity.svg)"

# 6. Failure path: every array task fails (no studies/ in this root); the merge job must end.
bad=$(mktemp -d /tmp/pinfeed-slurm-e2e-fail.XXXXXX)
cp -r "$root/scenarios" "$bad/"
say "failure path: array tasks fail, in $bad"
state=$(run_readme_job "$bad")
[ "$state" = CANCELLED ] || {
    show_logs "$bad"
    die "with failed array tasks the merge job ended '$state', not CANCELLED"
}
[ ! -e "$bad/$report_dir" ] || die "a merge ran although the array tasks failed"
grep -qs 'error' "$bad"/logs/mc-*.out || die "the failed tasks' logs do not say why"
say "merge job CANCELLED when the array tasks failed (it does not wait forever)"

rm -rf "$work" "$bad"
say "PASS"
