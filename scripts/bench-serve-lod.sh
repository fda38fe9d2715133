#!/usr/bin/env bash
# The browser viewer with level of detail, measured on a GPU machine (scripts/gpu-check.sh servelod):
# the 1,000 M stand-in (generated terrain, as the lod suite's) written as LAS, built into an octree by
# `pointrast lod`, then `pointrast serve OCTREE` with a node cache of 1/8 of the octree, and the loopback
# client `serve_load --flight` as one browser tab: low over the cloud and across it, then jumps. Writes
# $OUT/serve-lod.{json,md}, the server's events and log. The LAS is removed once the octree is built (the
# two together are about 50 GB).
#   POINTRAST_BIN=... SERVE_LOAD=... OUT=... WORK=/tmp/servelod [SERVE_RATE=120] scripts/bench-serve-lod.sh [POINTS]
set -euo pipefail
points=${1:-1G}
pr=${POINTRAST_BIN:?the pointrast binary}
load=${SERVE_LOAD:?the serve_load binary}
out=${OUT:?the result folder}
work=${WORK:-/tmp/servelod}
size=${SERVE_SIZE:-1920x1080}
mkdir -p "$out" "$work"
octree="$work/terrain-$points"

if [ ! -f "$octree/metadata.json" ]; then
  start=$(date +%s)
  "$pr" generate terrain --points "$points" --point-format 2 -o "$work/terrain.las" -q
  "$pr" lod "$work/terrain.las" -o "$octree" --json -q > "$out/serve-lod-build.json"
  rm -f "$work/terrain.las"
  echo "bench-serve-lod: generated and built $points points in $(( $(date +%s) - start )) s"
fi
bytes=$(du -sb "$octree" | cut -f1)
budget=$(( bytes / 8 ))
echo "bench-serve-lod: octree $bytes bytes, node cache $budget bytes (1/8)"
# Cold start: the octree's files leave the page cache, as on a first open.
sync; echo 1 > /proc/sys/vm/drop_caches 2>/dev/null || echo "bench-serve-lod: the page cache could not be dropped"

events="$out/serve-lod-events.jsonl"
"$pr" serve "$octree" --gpu-memory "$budget" --port 0 --events -q >"$events" 2>"$out/serve-lod-server.log" &
server=$!
stop_server() { kill -TERM "$server" 2>/dev/null || true; }
trap stop_server EXIT
# The port a server started with --events says it listens on, within TRIES half-seconds; empty if it
# exits or never says.
listening_port() { # EVENTS TRIES
  local i found=""
  for ((i = 0; i < $2; ++i)); do
    found=$(sed -n 's/.*"event":"listening".*"port":\([0-9]*\).*/\1/p' "$1" | head -1)
    [ -n "$found" ] && break
    kill -0 "$server" 2>/dev/null || break
    sleep 0.5
  done
  echo "$found"
}
# serve_load's flight against PORT, its reports at $out/NAME.{json,md}.
fly() { # PORT NAME
  "$load" --port "$1" --width "${size%x*}" --height "${size#*x}" --seconds "${SERVE_SECONDS:-15}" \
    --rate "${SERVE_RATE:-120}" --flight -o "$out/$2.json" --markdown "$out/$2.md"
}
port=$(listening_port "$events" 240)
if [ -z "$port" ]; then
  echo "bench-serve-lod: the server did not listen" >&2
  cat "$out/serve-lod-server.log" >&2
  exit 1
fi
status=0
# SERVE_RATE: pointer moves a second, the page's display refresh rate (one move per animation frame).
fly "$port" serve-lod || status=1
trap - EXIT
kill -TERM "$server"
wait "$server" || { echo "bench-serve-lod: the server exited with $?" >&2; status=1; }
cat "$out/serve-lod-server.log"

# Beside it, the same flight over the same points drawn by brute force (the generated terrain of the same
# seed, uploaded whole, the device's default method): serve-lod-brute.{json,md}, appended to serve-lod.md.
if [ "${SERVE_BRUTE:-1}" = 1 ]; then
  brute_events="$out/serve-lod-brute-events.jsonl"
  "$pr" serve terrain --points "$points" --port 0 --events -q >"$brute_events" 2>"$out/serve-lod-brute-server.log" &
  server=$!
  trap stop_server EXIT
  port=$(listening_port "$brute_events" 600)
  if [ -z "$port" ]; then
    echo "bench-serve-lod: the brute-force server did not listen" >&2
    cat "$out/serve-lod-brute-server.log" >&2
    status=1
  else
    fly "$port" serve-lod-brute || status=1
  fi
  trap - EXIT
  kill -TERM "$server" 2>/dev/null || true
  wait "$server" || { echo "bench-serve-lod: the brute-force server exited with $?" >&2; status=1; }
  if [ -f "$out/serve-lod-brute.md" ] && [ -f "$out/serve-lod.md" ]; then
    { echo; echo "## Beside it: the same flight over the same $points points drawn by brute force"; echo
      sed '1s/^# /### /' "$out/serve-lod-brute.md"; } >> "$out/serve-lod.md"
  fi
fi
[ -f "$out/serve-lod.md" ] && cat "$out/serve-lod.md"
exit $status
