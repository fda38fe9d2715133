#!/usr/bin/env bash
# The desktop viewer flying over an octree with level of detail, measured from its own statistics: the
# flight `serve_load --flight` flies against `serve` (scripts/bench-serve-lod.sh), played by the viewer
# itself (`view --flight`) on a private Xvfb. A generated terrain is written as LAS and built into an octree
# by `pointrast lod`; the viewer opens it with a node cache of 1/8 of the octree, so nodes stream while it
# flies: six wheel steps down low, pan strokes across the cloud for FLIGHT_SECONDS at FLIGHT_RATE inputs a
# second, then eight jumps (standard views and zooms), each followed until a frame converged. Writes
# $OUT/view-flight.json (`view --stats`, with frames/s, input to frame p50/p95 and the frames each jump took
# under "flight") and $OUT/view-flight.md; fails when a jump did not converge within 30 s.
#   POINTRAST_BIN=... OUT=... [WORK=/tmp/viewflight] [VIEW_SIZE=960x540] [FLIGHT_SECONDS=15]
#   [FLIGHT_RATE=120] [MACHINE="..."] scripts/view-flight.sh [POINTS]
# 960x540 are the pixels of serve's frames while moving at 1920x1080 (half resolution). Needs Xvfb
# (scripts/install-deps.sh) and python3 for the Markdown.
set -euo pipefail
points=${1:-2M}
pr=${POINTRAST_BIN:?the pointrast binary}
out=${OUT:?the result folder}
work=${WORK:-/tmp/viewflight}
size=${VIEW_SIZE:-960x540}
seconds=${FLIGHT_SECONDS:-15}
rate=${FLIGHT_RATE:-120}
mkdir -p "$out" "$work"
octree="$work/terrain-$points"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"

if [ ! -f "$octree/metadata.json" ]; then
  "$pr" generate terrain --points "$points" --point-format 2 -o "$work/terrain.las" -q
  "$pr" lod "$work/terrain.las" -o "$octree" -q
  rm -f "$work/terrain.las"
fi
bytes=$(du -sb "$octree" | cut -f1)
budget=$((bytes / 8))
echo "view-flight: octree $bytes bytes, node cache $budget bytes (1/8)"

display_file=$(mktemp)
xvfb=""
cleanup() {
  if [ -n "$xvfb" ]; then kill "$xvfb" 2>/dev/null || true; fi
  rm -f "$display_file"
}
trap cleanup EXIT
exec 3>"$display_file"
Xvfb -displayfd 3 -screen 0 1920x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
exec 3>&-
for _ in $(seq 100); do [ -s "$display_file" ] && break; sleep 0.1; done
[ -s "$display_file" ] || { echo "view-flight: Xvfb did not start" >&2; exit 1; }
DISPLAY=":$(head -n1 "$display_file")"
export DISPLAY

status=0
"$pr" view "$octree" --gpu-memory "$budget" --width "${size%x*}" --height "${size#*x}" --no-panel --no-vsync \
  --flight "$seconds" --flight-rate "$rate" --stats "$out/view-flight.json" --path "$work/path.json" -q \
  2>"$work/view.log" || status=$?
cat "$work/view.log"
[ "$status" -eq 0 ] || { echo "view-flight: the viewer exited with $status" >&2; exit 1; }

python3 - "$out/view-flight.json" "$out/view-flight.md" "$points" "$budget" "${MACHINE:-}" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
f, s = j["flight"], j["flight"]["strokes"]
ms = s["input_to_frame_ms"]
machine = sys.argv[5]
md = f"# pointrast view: a flight with level of detail, {j['sizes'][0] if j['sizes'] else '?'}\n\n"
md += (f"Device {j['device']['name']}{', ' + machine if machine else ''}; a {sys.argv[3]}-point generated terrain "
       f"built by `pointrast lod`, node cache {int(sys.argv[4]):,} bytes (1/8 of the octree), method "
       f"{', '.join(j['methods'])}, no vsync, no panel; `view --flight`: the inputs of `serve_load --flight`, "
       f"low over the cloud, pan strokes across it at {s['input_rate_hz']:.0f} inputs/s for "
       f"{s['seconds']:.1f} s, then jumps.\n\n")
md += "| phase | frames/s | input to frame p50 (ms) | p95 (ms) | inputs |\n| --- | ---: | ---: | ---: | ---: |\n"
md += f"| flight | {s['frames_per_second']:.1f} | {ms['p50']:.1f} | {ms['p95']:.1f} | {ms['inputs']} |\n\n"
md += "| jump | converged | frames to converge | ms |\n| --- | --- | ---: | ---: |\n"
for x in f["jumps"]:
    md += f"| {x['jump']} | {'yes' if x['converged'] else 'no'} | {x['frames_to_converge']} | {x.get('ms_to_converge', 0):.0f} |\n"
st = f.get("streaming")
if "points_drawn" in s:
    d = s["points_drawn"]
    md += (f"\nPoints drawn a frame while the strokes flew: median {d['median']:,.0f}, min {d['min']:,.0f}, "
           f"max {d['max']:,.0f}.\n")
    if d["median"] == 0:
        md += ("Most stroke frames draw nothing: a pan drag from the bottom of the viewport to the top moves the "
               "camera down along its up vector (the ground follows the cursor), so the strokes carry the camera, "
               "which looks down at the ground, back and down through it within the first stroke. "
               "`serve_load --flight` sends the same strokes.\n")
if st:
    md += (f"\nNodes streamed through the node cache ({st['cache_bytes']:,} bytes): while the strokes flew "
           f"{st['strokes']['nodes_loaded']} loaded, {st['strokes']['nodes_evicted']} evicted, "
           f"{st['strokes']['bytes_streamed'] / 1e6:.1f} MB read; over the session {st['session']['nodes_loaded']} "
           f"loaded, {st['session']['nodes_evicted']} evicted, {st['session']['bytes_streamed'] / 1e6:.1f} MB read.\n")
gpu = j["frame"]["gpu"]
md += (f"\nEvery frame of the session ({j['frames']}): GPU {gpu['median_ms']:.1f} ms median, {gpu['p95_ms']:.1f} ms p95 "
       f"(render and present passes, timestamp queries); host {j['frame']['host']['median_ms']:.1f} ms median.\n")
open(sys.argv[2], "w").write(md)
print(md)
sys.exit(0 if f["jumps_all_converged"] and f["complete"] else 1)
PY
