#!/bin/sh
# A picture of the browser viewer for docs/ (pointrast serve, chromium through tests/web/browser.mjs):
# the panel shown, an octree drawn with the LOD method and eye-dome lighting on, once it converged.
#
#   scripts/viewer-shots.sh [BUILD_DIR] [OCTREE]
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
octree=${2:-/work/shared/data/potree/autzen_trim_default}
bin=$build/pointrast
camera="--eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1"
tmp=$(mktemp -d)
serve_pid=
trap 'kill $serve_pid 2>/dev/null || true; rm -rf "$tmp"' EXIT

# The browser page.
"$bin" serve "$octree" $camera --edl --port 0 --events -q > "$tmp/serve.jsonl" &
serve_pid=$!
while ! grep -q '"listening"' "$tmp/serve.jsonl" 2>/dev/null; do sleep 0.2; done
url=$(grep '"listening"' "$tmp/serve.jsonl" | sed 's/.*"url":"\([^"]*\)".*/\1/')
(cd "$root/tests/web" && node browser.mjs pageshot "$url" "$root/docs" \
  '{"file":"serve-lod.png","viewportWidth":1100,"viewportHeight":760,"converged":true}')
echo "wrote docs/serve-lod.png"
