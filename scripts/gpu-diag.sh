#!/usr/bin/env bash
# Short targeted GPU checks, each under its own time limit (used to chase a hang without losing the
# whole device call). Same setup as gpu-check.sh.
set -uo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-$PWD/gpu-out}; mkdir -p "$OUT"
if ! ldconfig -p | grep -q libvulkan.so.1; then for f in .vkrt/*.deb; do dpkg -x "$f" /; done; ldconfig; fi
pr=$PWD/.gpu/bin/pointrast
export XDG_RUNTIME_DIR=/tmp POINTRAST_VALIDATION=0
for spec in "$@"; do
  IFS=: read -r view method points <<< "$spec"
  timeout 40 $pr bench tls --points "$points" --views "$view" --methods "$method" --orders original --frames 5 -q --out /tmp/diag --name "d" 2>&1 | tail -2
  echo "== $view $method $points: rc=$?"
done
