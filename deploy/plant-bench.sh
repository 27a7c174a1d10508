#!/bin/bash
# The plant-integration figures of station/README.md: starts a throwaway mosquitto (persistent, as
# deploy/OPERATIONS.md asks of a plant's broker) and a throwaway PostgreSQL 15 cluster in a temporary
# directory, each on a free port of 127.0.0.1, runs `eol plant-bench` against them, and stops
# both by their own pids. As root the servers run as their packages' users (mosquitto drops
# to `mosquitto` by itself; PostgreSQL refuses root and runs as `postgres` via setpriv).
# Usage: deploy/plant-bench.sh [eol plant-bench options, e.g. --backlog 2000 --json]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
eol=${EOL:-$here/build/eol}
pgbin=/usr/lib/postgresql/15/bin
for f in "$eol" /usr/sbin/mosquitto "$pgbin/postgres"; do
  [[ -x $f ]] || { echo "plant-bench.sh: $f not found (build, or bash deploy/install-deps.sh --test)" >&2; exit 2; }
done
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
dir=$(mktemp -d /tmp/eol-plant-bench-XXXXXX)
chmod 711 "$dir"
mkdir "$dir/mq" "$dir/pg" "$dir/work"
as_pg=()
if [[ $(id -u) == 0 ]]; then
  chown mosquitto: "$dir/mq"
  chown postgres: "$dir/pg"
  as_pg=(setpriv --reuid=postgres --regid=postgres --clear-groups --)
fi
mq_pid=""; pg_pid=""
cleanup() {
  [[ -n $mq_pid ]] && kill -TERM "$mq_pid" 2>/dev/null && wait "$mq_pid" 2>/dev/null || true
  [[ -n $pg_pid ]] && kill -INT "$pg_pid" 2>/dev/null && wait "$pg_pid" 2>/dev/null || true
  rm -rf "$dir"
}
trap cleanup EXIT
mq_port=$(free_port)
printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence true\npersistence_location %s/\nmax_queued_messages 1000000\n' \
  "$mq_port" "$dir/mq" > "$dir/mq/mosquitto.conf"
/usr/sbin/mosquitto -c "$dir/mq/mosquitto.conf" > "$dir/mq.log" 2>&1 &
mq_pid=$!
"${as_pg[@]}" "$pgbin/initdb" -D "$dir/pg/data" -U eol -A trust -E UTF8 --locale=C > "$dir/initdb.log" 2>&1
pg_port=$(free_port)
"${as_pg[@]}" "$pgbin/postgres" -D "$dir/pg/data" -p "$pg_port" -h 127.0.0.1 -k "$dir/pg" > "$dir/pg.log" 2>&1 &
pg_pid=$!
for _ in $(seq 200); do
  grep -q 'ready to accept connections' "$dir/pg.log" && grep -q ' running' "$dir/mq.log" && break
  sleep 0.1
done
echo "plant-bench.sh: mosquitto $(/usr/sbin/mosquitto -h 2>/dev/null | head -1 | awk '{print $3}') on $mq_port, PostgreSQL $("$pgbin/postgres" --version | awk '{print $3}') on $pg_port (fsync on, defaults)" >&2
"$eol" plant-bench --mqtt "mqtt://127.0.0.1:$mq_port" \
  --central "postgresql://eol@127.0.0.1:$pg_port/postgres" --work-dir "$dir/work" "$@"
