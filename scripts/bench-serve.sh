#!/usr/bin/env bash
# The browser viewer measured on a GPU machine (scripts/gpu-check.sh serve): `pointrast serve` on a
# generated cloud, and the loopback load client `serve_load` as one browser tab of the given size that
# drags the camera without pause. Writes $OUT/serve.json and $OUT/serve.md (frames/s streamed, input to
# frame latency, bytes per frame moving and at rest), the server's event lines and its log.
#   POINTRAST_BIN=... SERVE_LOAD=... OUT=... scripts/bench-serve.sh [POINTS] [METHOD]
set -euo pipefail
points=${1:-1G}
method=${2:-batch-prefetch}
pr=${POINTRAST_BIN:?the pointrast binary}
load=${SERVE_LOAD:?the serve_load binary}
out=${OUT:?the result folder}
size=${SERVE_SIZE:-1920x1080}
# Generating, ordering and uploading 1 G points takes minutes before the server listens.
wait_s=${SERVE_WAIT_S:-420}
mkdir -p "$out"

events="$out/serve-events.jsonl"
"$pr" serve terrain --points "$points" --order morton --method "$method" --port 0 --events -q \
  >"$events" 2>"$out/serve-server.log" &
server=$!
stop_server() { kill -TERM "$server" 2>/dev/null || true; }
trap stop_server EXIT
trap 'stop_server; exit 1' TERM INT

port=""
for ((i = 0; i < wait_s * 2; ++i)); do
  port=$(sed -n 's/.*"event":"listening".*"port":\([0-9]*\).*/\1/p' "$events" | head -1)
  [ -n "$port" ] && break
  kill -0 "$server" 2>/dev/null || break
  sleep 0.5
done
if [ -z "$port" ]; then
  echo "bench-serve: the server did not listen within ${wait_s} s" >&2
  cat "$out/serve-server.log" >&2
  exit 1
fi
echo "bench-serve: serve ($points points, $method) listens on port $port"

status=0
"$load" --port "$port" --width "${size%x*}" --height "${size#*x}" --seconds "${SERVE_SECONDS:-10}" \
  -o "$out/serve.json" --markdown "$out/serve.md" || status=1

trap - EXIT
kill -TERM "$server"
wait "$server" || { echo "bench-serve: the server exited with $?" >&2; status=1; }
cat "$out/serve-server.log"
[ -f "$out/serve.md" ] && cat "$out/serve.md"
exit $status
