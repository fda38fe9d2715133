#!/usr/bin/env bash
# GPU time of each pass of the resolve stage (point size, dilation, compose with eye-dome lighting), from
# the timestamps `render --json` reports, on a generated terrain at a desktop and a VR-eye resolution.
# The passes work on pixels, so the point count only has to fill the image.
#   scripts/time-post.sh BIN OUT.jsonl [POINTS] [FRAMES]   e.g. scripts/time-post.sh build-rel/pointrast post.jsonl
# Writes one JSON object per configuration (render's --json with "post": {splat_ms, dilate_ms, compose_ms})
# and prints a table of the medians.
set -euo pipefail
bin=${1:?usage: time-post.sh BIN OUT.jsonl [POINTS] [FRAMES]}
out=${2:?usage: time-post.sh BIN OUT.jsonl [POINTS] [FRAMES]}
points=${3:-20M}
frames=${4:-50}
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
png=$(mktemp --suffix=.png)
trap 'rm -f "$png"' EXIT
: >"$out"
configs=(
  ""
  "--point-size 3"
  "--point-size 8"
  "--point-size 16"
  "--point-size 5 --point-shape disc"
  "--point-size 4 --point-size-mode attenuated --point-size-max 16"
  "--dilate 1"
  "--dilate 3"
  "--edl"
  "--point-size 2 --dilate 2 --edl"
)
printf '%-10s %-66s %9s %9s %9s %9s\n' size options frame_ms splat dilate compose
for size in "--width 1920 --height 1080" "--width 2478 --height 2740"; do
  for options in "${configs[@]}"; do
    # shellcheck disable=SC2086 # options are words
    line=$("$bin" render terrain --points "$points" --order morton --method batch-prefetch $size $options \
      --frames "$frames" --json -q -o "$png")
    echo "$line" >>"$out"
    command -v python3 >/dev/null || { echo "$line"; continue; }
    echo "$line" | python3 -c '
import json, sys
j = json.loads(sys.stdin.read())
p = j.get("post", {})
print("%-10s %-66s %9.3f %9.3f %9.3f %9.3f" % ("%dx%d" % (j["width"], j["height"]), sys.argv[1] or "(none)",
      j["median_ms"], p.get("splat_ms", 0), p.get("dilate_ms", 0), p.get("compose_ms", 0)))' "$options"
  done
done
