#!/usr/bin/env bash
# A real single-node Slurm cluster on this machine, and the tiny workflow run through it.
#
#   bash tests/slurm/run.sh            (as root; .ci/run calls it, bounded by `timeout -s INT`)
#
# Installs slurm-wlm and munge from Debian if missing, starts munged, slurmctld and slurmd for one
# localhost node under a temporary folder, runs config/tiny.yaml through `--workflow-profile
# profiles/slurm` up to $TARGETS (every per-shard stage, their gathers, one room type's training and
# generation: what scales out; the rest of the pipeline adds only more jobs of the same rules), runs the
# same targets locally, checks every output table is identical (as tables),
# writes the two wall times to $SLURM_TIMINGS (default bench/out/slurm.json), and stops the daemons it
# started, by PID, whatever happens. It fails, never skips, when Slurm cannot start.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BIN=${VENV_BIN:-$ROOT/.venv/bin}
TIMINGS=${SLURM_TIMINGS:-$ROOT/bench/out/slurm.json}
STATE=$(mktemp -d /tmp/planit-slurm.XXXXXX)
CONF=/etc/slurm/slurm.conf
PIDS=()
BACKUP=""

log() { echo "[slurm-test] $*" >&2; }

cleanup() {
  local rc=$?
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
  if [ -L "$CONF" ] && [ "$(readlink "$CONF")" = "$STATE/slurm.conf" ]; then rm -f "$CONF"; fi
  if [ -n "$BACKUP" ]; then mv "$BACKUP" "$CONF"; fi
  if [ $rc -ne 0 ]; then
    log "FAILED (exit $rc); daemon logs:"
    tail -n 20 "$STATE"/*.log >&2 2>/dev/null || true
  fi
  rm -rf "$STATE"
  exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT TERM

if [ "$(id -u)" -ne 0 ]; then log "must run as root (starts Slurm daemons)"; exit 1; fi
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  log "installing slurm-wlm and munge from Debian"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq slurm-wlm munge >/dev/null
fi
[ -f /etc/munge/munge.key ] || { log "no /etc/munge/munge.key"; exit 1; }

# munge: socket directory must be 755 and owned by munge
mkdir -p "$STATE/munge"
chown munge:munge "$STATE/munge"
chmod 755 "$STATE"
chmod 755 "$STATE/munge"
SOCKET="$STATE/munge/munge.socket.2"
runuser -u munge -- munged --foreground --socket="$SOCKET" --key-file=/etc/munge/munge.key \
  --pid-file="$STATE/munge/munged.pid" --log-file="$STATE/munge/munged.log" --seed-file="$STATE/munge/seed" \
  > "$STATE/munged.log" 2>&1 &
PIDS+=($!)
for _ in $(seq 50); do [ -S "$SOCKET" ] && break; sleep 0.1; done
[ -S "$SOCKET" ] || { log "munged did not start"; exit 1; }

MEM=$(( $(free -m | awk '/^Mem:/ {print $7}') * 8 / 10 ))
mkdir -p "$STATE/spool/ctld" "$STATE/spool/d"
cat > "$STATE/slurm.conf" <<CONF
ClusterName=ci
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCKET
MpiDefault=none
StateSaveLocation=$STATE/spool/ctld
SlurmdSpoolDir=$STATE/spool/d
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MinJobAge=300
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$MEM State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
mkdir -p /etc/slurm
if [ -e "$CONF" ] || [ -L "$CONF" ]; then BACKUP="$STATE/slurm.conf.orig"; mv "$CONF" "$BACKUP"; fi
ln -s "$STATE/slurm.conf" "$CONF"

slurmctld -D > "$STATE/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -N localhost > "$STATE/slurmd.out" 2>&1 &
PIDS+=($!)
for _ in $(seq 60); do
  state=$(sinfo -h -o %t 2>/dev/null | head -n 1 || true)
  [ "$state" = "idle" ] && break
  sleep 1
done
[ "$state" = "idle" ] || { log "Slurm node never became idle (state: '${state:-none}')"; exit 1; }
log "Slurm is up: $(sinfo -h -o '%P %D %t %c cpus %m MB')"

export PATH="$BIN:$PATH"
TARGETS=(results/graphs/ingested/report/table1.csv results/metrics/ingested/extraction.json
         results/metrics/ingested/superstructures.json results/filter/report.parquet results/ingest/drops.parquet
         results/graph_model/bedroom/planit/metrics.json results/generated/bedroom/planit/summary.json)
run() {  # run <name> <extra snakemake args...>
  local dir="$STATE/$1"; shift
  mkdir -p "$dir"
  local t0; t0=$(date +%s.%N)
  "$BIN/snakemake" "${TARGETS[@]}" --snakefile "$ROOT/Snakefile" --directory "$dir" --configfile "$ROOT/config/tiny.yaml" "$@" \
    > "$STATE/$(basename "$dir").snakemake.log" 2>&1 || { tail -n 40 "$STATE/$(basename "$dir").snakemake.log" >&2; return 1; }
  awk -v a="$(date +%s.%N)" -v b="$t0" 'BEGIN { printf "%.1f", a - b }'
}
log "tiny workflow through Slurm"
T_SLURM=$(run via-slurm --workflow-profile "$ROOT/profiles/slurm")
log "same workflow locally"
T_LOCAL=$(run local --cores 2)
log "wall time: slurm ${T_SLURM}s, local ${T_LOCAL}s"
"$BIN/python" "$ROOT/tests/slurm/compare_runs.py" "$STATE/local/results" "$STATE/via-slurm/results"
mkdir -p "$(dirname "$TIMINGS")"
printf '{"config": "config/tiny.yaml", "local_seconds": %.1f, "slurm_seconds": %.1f, "jobs": %s}\n' \
  "$T_LOCAL" "$T_SLURM" "$(grep -c '^rule \|^localrule ' "$STATE/via-slurm.snakemake.log" || echo null)" > "$TIMINGS"
log "identical outputs; timings in $TIMINGS"
echo "slurm: 1 passed, 0 failed"
