#!/usr/bin/env bash
# The viewer's render loop, measured from its own statistics: opens `pointrast view` on a private Xvfb
# (lavapipe draws; no screen needed), orbits the camera with xdotool, one drag step per frame (each step
# waits for the frame it causes), closes the window with Escape and keeps the --stats JSON: median and
# 95th percentile GPU ms of each pass (render, present) and of the frame, over every frame rendered.
#   scripts/view-stats.sh BIN OUT.json STEPS INPUT [view options...]
#   e.g. scripts/view-stats.sh build-rel/pointrast view.json 100 terrain --points 10M --width 1280 --height 720
# Needs Xvfb and xdotool (scripts/install-deps.sh). The viewer runs with --no-vsync, so that the host's frame
# time is the loop's own work, not the display's rate; the panel is shown unless the options say --no-panel.
set -euo pipefail
usage="usage: view-stats.sh BIN OUT.json STEPS INPUT [view options...]"
bin=${1:?$usage}
out=${2:?$usage}
steps=${3:?$usage}
shift 3
[ $# -ge 1 ] || { echo "$usage" >&2; exit 1; }
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
work=$(mktemp -d)
xvfb=""
viewer=""
cleanup() {
  if [ -n "$viewer" ]; then kill "$viewer" 2>/dev/null || true; fi
  if [ -n "$xvfb" ]; then kill "$xvfb" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

exec 3>"$work/display"
Xvfb -displayfd 3 -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
exec 3>&-
for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { echo "view-stats: Xvfb did not start" >&2; exit 1; }
DISPLAY=":$(head -n1 "$work/display")"
export DISPLAY

"$bin" view "$@" --no-vsync --events -q --stats "$out" --path "$work/path.json" \
  >"$work/events" 2>"$work/errors" &
viewer=$!

frames() {
  local n
  n=$(grep -c '"event":"frame"' "$work/events" 2>/dev/null || true)
  echo "${n:-0}"
}
# Waits up to $2 seconds for more than $1 frames; fails when the viewer exited.
wait_frames() {
  local deadline=$((SECONDS + $2))
  while [ "$(frames)" -le "$1" ]; do
    kill -0 "$viewer" 2>/dev/null || { echo "view-stats: the viewer exited:" >&2; cat "$work/errors" >&2; exit 1; }
    [ $SECONDS -lt $deadline ] || { echo "view-stats: no frame in $2 s" >&2; exit 1; }
    sleep 0.02
  done
}
wait_frames 0 600 # loading and the upload come first
window=$(xdotool search --sync --name '^pointrast' | head -n1)
# A slow orbit from right of the panel: 2 px a step, 100 steps to the right, 100 back, and again.
eval "$(xdotool getwindowgeometry --shell "$window")"
x=$((WIDTH * 2 / 3))
y=$((HEIGHT / 2))
xdotool mousemove --window "$window" "$x" "$y" mousedown 1
for i in $(seq "$steps"); do
  n=$(frames)
  if [ $(((i - 1) / 100 % 2)) -eq 0 ]; then x=$((x + 2)); else x=$((x - 2)); fi
  xdotool mousemove --window "$window" "$x" "$y"
  wait_frames "$n" 60
done
xdotool mouseup 1 mousemove --window "$window" 5 5 key Escape
status=0
wait "$viewer" || status=$?
viewer=""
[ "$status" -eq 0 ] || { echo "view-stats: the viewer exited with $status" >&2; cat "$work/errors" >&2; exit 1; }
echo "view-stats: $(frames) frames; wrote $out"
